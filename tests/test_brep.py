"""STEP solids written as B-rep text without a CAD kernel (wgcad.export.brep, wgcad.export.parts.breps), read back
by OpenCASCADE and FreeCAD: on every template every part, the face-modified cup's ruled ring too, is one valid solid
with the volume its 2D areas give and the solid OpenCASCADE's booleans and loft build (same volume, bounds and kinds of
faces)."""

import shutil
import subprocess

import numpy as np
import pytest
from conftest import TEMPLATES

from wgcad.design import load_design
from wgcad.design.parts import load_parts, part_sizes
from wgcad.drive import build_drive
from wgcad.errors import GeometryError
from wgcad.export import brep as B
from wgcad.export.parts import build_parts
from wgcad.export.step import read_step, solid_props

ALL = sorted(p.stem for p in TEMPLATES.glob("*.toml"))

# exact lines, arcs and circles: the solid's volume is the 2D areas x heights to rounding (OCCT integrates planes and
# cylinders exactly; measured <= 3e-14 relative)
EXACT_REL = 1e-9
# a B-spline side face (plug, generator ring): OCCT integrates a surface of extrusion numerically, and not closely.
# On D3's generator ring it reads 6.2e-5 relative below the solid's exact volume (the spline's area by dense
# sampling), for our file and for its own solid of the same curve alike (they differ by 3.5e-7); the spline's area
# itself departs from the 2D polygon's by 4.1e-5. The 2D check of a B-spline part is therefore 2e-4 (a lost face or
# bore is > 1e-2), and OCCT's own solid is the close reference (1e-6)
SPLINE_2D_REL = 2e-4
SPLINE_REL = 1e-6
# our bounds against OCCT's solid's: the same vertices and curves; measured <= 8e-13 mm
BOUNDS_MM = 1e-9
# OpenCASCADE reads a STEP file in time that grows fast with the edges of a face's loop (D1 involute's 1,800-face
# flexspline 4.6 s, its own file of it 9.1 s; D1 cycloidal's 7,800 faces 232 s, its own 617 s): the parts are read
# back on these templates (a cup on arcs, a face-modified drive's ruled cup, plug and rigid gear, the external drive, small
# discrete teeth; of the external drive its generator ring, whose toothed rings are prisms like D1's and take 25 s);
# on every template every part's shell is checked closed and oriented as it is written
READ = {"d1_involute": None, "d1_conjugate_modified": None, "d3_external": ("generator_ring",), "d4_discrete": None}
# and built by OpenCASCADE's booleans for comparison (~1-15 s a part): a cup, a plug and a flanged rigid gear on arcs,
# the face-modified cup (OCCT's ruled loft),
# the external drive's generator ring (its B-spline as a hole; its toothed rings are D1's prisms again, 30 s), small
# discrete teeth
COMPARED = {
    "d1_involute": None,
    "d1_conjugate_modified": ("flexspline",),
    "d3_external": ("generator_ring",),
    "d4_discrete": None,
}


def _read(text: str, tmp_path, name: str):
    path = tmp_path / f"{name}.step"
    path.write_text(text, encoding="ascii")
    solids = read_step(path)
    assert len(solids) == 1, name
    return path, solid_props(solids[0])


def _parts(name):
    path = TEMPLATES / f"{name}.toml"
    drive = build_drive(load_design(path))
    return [p for p in build_parts(drive, part_sizes(load_parts(path), drive)) if not p.name.startswith("assembly")]


@pytest.mark.parametrize("name", ALL)
def test_every_template_part_is_a_closed_shell(name):
    for p in _parts(name):
        b = p.brep()  # every part of every template has its B-rep (none goes to OpenCASCADE)
        text = b.text(p.name)  # raises unless every edge is in two faces, run opposite ways
        assert text.count("ADVANCED_FACE(") == len(b.faces) and text.count("MANIFOLD_SOLID_BREP(") == 1


@pytest.mark.parametrize("name", READ)
def test_parts_read_back_as_one_valid_solid_of_their_volume(name, tmp_path):
    for p in _parts(name):
        b = p.brep()
        if b is None or (READ[name] is not None and p.name not in READ[name]):
            continue
        _, pr = _read(b.text(p.name), tmp_path, p.name)
        assert pr["valid"], p.name
        rel = SPLINE_2D_REL if "plug_outline" in p.info else EXACT_REL
        assert pr["volume"] == pytest.approx(p.volume_mm3, rel=rel), p.name


def test_straight_segments_and_holes_read_back(tmp_path):
    """Plane side faces (a sectored rigid gear's polygon teeth) and circular holes: a star with a bore and a hole."""
    import shapely

    t = np.linspace(0.0, 2 * np.pi, 60, endpoint=False)
    star = np.c_[np.cos(t), np.sin(t)] * np.where(np.arange(60) % 2, 10.0, 12.0)[:, None]
    b = B.prism(B.polygon_loop(star[::-1]), [B.circle_loop(0, 0, 3, False), B.circle_loop(6, 0, 1, False)], 1.0, 3.5)
    _, pr = _read(b.text("star"), tmp_path, "star")
    area = shapely.Polygon(star).area - np.pi * (9 + 1)
    assert pr["valid"] and pr["volume"] == pytest.approx(area * 2.5, rel=EXACT_REL)
    assert pr["faces"] == {"GeomAbs_Plane": 62, "GeomAbs_Cylinder": 2}
    np.testing.assert_allclose(pr["bounds"], [[-12, star[:, 1].min(), 1.0], [12, star[:, 1].max(), 3.5]], atol=1e-9)


@pytest.mark.parametrize("name", COMPARED)
def test_parts_equal_opencascade_booleans(name, tmp_path):
    for p in _parts(name):
        if COMPARED[name] is not None and p.name not in COMPARED[name]:
            continue
        _, ours = _read(p.brep().text(p.name), tmp_path, p.name)
        ref = solid_props(p.solid())
        rel = SPLINE_REL if "plug_outline" in p.info else EXACT_REL
        assert ours["volume"] == pytest.approx(ref["volume"], rel=rel), p.name
        if "face_modification" in p.info:
            # OCCT's loft carries its 1e-7 mm tolerance, which its bounding box adds; it makes every ruled face a
            # B-spline surface, ours are extrusions where they can be
            np.testing.assert_allclose(ours["bounds"], ref["bounds"], rtol=0, atol=1e-7 + BOUNDS_MM)
            continue
        np.testing.assert_allclose(ours["bounds"], ref["bounds"], rtol=0, atol=BOUNDS_MM)
        faces = dict(ref["faces"])
        if p.info.get("kind") == "cup flexspline":
            faces["GeomAbs_Cylinder"] -= 1  # OCCT's glued cup keeps the bore in two faces; ours is one
        assert ours["faces"] == faces, p.name


@pytest.mark.skipif(shutil.which("freecadcmd") is None, reason="FreeCAD (freecadcmd) not installed")
def test_freecad_reads_the_template_parts(tmp_path):
    files = []
    parts = _parts("d1_involute") + [p for p in _parts("d1_double_arc") if p.name == "flexspline"]  # + a ruled ring
    for k, p in enumerate(parts):
        path, pr = _read(p.brep().text(p.name), tmp_path, f"{k}_{p.name}")
        files.append((path, pr["volume"]))
    script = tmp_path / "read.py"
    script.write_text(
        "import Part\n"
        + "".join(
            f"s = Part.read({str(f)!r}); print('PART', s.isValid(), len(s.Solids), repr(s.Volume))\n" for f, _ in files
        )
    )
    res = subprocess.run(["freecadcmd", str(script)], capture_output=True, text=True, timeout=600)
    rows = [line.split()[1:] for line in res.stdout.splitlines() if line.startswith("PART ")]
    assert len(rows) == len(files), res.stdout + res.stderr
    for (f, ocp), (valid, n, volume) in zip(files, rows):
        assert valid == "True" and n == "1", f.name
        assert float(volume) == pytest.approx(ocp, rel=1e-9), f.name


def test_an_open_shell_is_refused():
    """The edge check: a prism without its top face has edges used once; a cap put on the wrong side (the hole's
    loop taken as the region) runs an edge the same way in two faces."""
    b = B.Brep()
    outer = b.wall(B.circle_loop(0.0, 0.0, 10.0), 0.0, 1.0)
    hole = b.wall(B.circle_loop(0.0, 0.0, 5.0, material_left=False), 0.0, 1.0)
    b.cap(0.0, False, [(outer, True), (hole, True)])
    with pytest.raises(GeometryError, match="not shared by two faces"):
        b.text("open")
    b.cap(1.0, True, [(outer, True), (hole, False)])
    with pytest.raises(GeometryError, match="not shared by two faces"):
        b.text("wrong")


def test_loops_orient_themselves():
    """path_loop makes an outer boundary counter-clockwise and a hole clockwise whichever way the path ran, with the
    arcs' centres on the side their bulge says."""
    sq = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 3.0], [0.0, 3.0]])
    bulges = np.array([0.0, 0.3, 0.0, 0.0])  # the right edge bulges out (counter-clockwise arc)
    for v, b in ((sq, bulges), (sq[::-1], -np.roll(bulges[::-1], -1))):
        outer = B.path_loop(v, b)
        arc = next(s for s in outer if isinstance(s, B.Arc))
        assert arc.ccw and arc.center[0] < 4.0  # centre inside the square: the arc bulges out to the right
        hole = B.path_loop(v, b, material_left=False)
        arc = next(s for s in hole if isinstance(s, B.Arc))
        assert not arc.ccw and arc.center[0] < 4.0


def test_step_reals():
    assert [B.real(x) for x in (1.0, -0.5, 0.0, 1.5e-7, 2e20, 71.521)] == [
        "1.",
        "-0.5",
        "0.",
        "1.5E-07",
        "2.E+20",
        "71.521",
    ]
