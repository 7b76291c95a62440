"""Tests of wgcad.export.formats.dxf: exact round trip, one closed LWPOLYLINE per outline, mm header, clean audit."""

import os
import shutil
import subprocess
import time

import ezdxf
import numpy as np
import pytest

from wgcad.atomic import atomic_batch
from wgcad.errors import InputFileError, OutputError
from wgcad.export.formats.dxf import DxfLayer, audit_dxf, build_dxf, clean_outline, read_dxf, write_dxf

# DXF stores coordinates as decimal text; ezdxf writes Python's shortest
# round-trip repr of each float64, so read-back is expected to be exact. The
# bound allows a writer that prints 16 significant digits (relative error
# <= 5e-16 * a few) and still fails one that prints 6 decimals (5e-7 mm) or
# goes through float32 (4 um at 80 mm).
ROUND_TRIP_TOL = 1e-12 * 100  # mm, relative 1e-12 of the ~100 mm drawing size


def star(n, lobes=200, r0=80.0, amp=0.8, phase=0.0):
    """(n, 2) CCW polar curve r = r0 + amp sin(lobes theta): a gear-like outline."""
    t = np.linspace(0.0, 2 * np.pi, n, endpoint=False) + phase
    r = r0 + amp * np.sin(lobes * t)
    return np.column_stack([r * np.cos(t), r * np.sin(t)])


def max_error(a, b):
    assert a.shape == b.shape
    return float(np.max(np.abs(a - b)))


@pytest.fixture(scope="module")
def gear_layers():
    return [
        DxfLayer("flexspline", outlines=(star(20_000),), circles=((0.0, 0.0, 30.0),), color=1),
        # 40k points: add_lwpolyline(points) would take seconds here
        DxfLayer("circular_spline", outlines=(star(40_000, lobes=202, r0=82.0, phase=1e-3),), color=5),
        DxfLayer("marks", circles=((1.5, -2.25, 0.125), (-10.0, 3.0, 2.0))),
    ]


@pytest.fixture(scope="module")
def gear_file(gear_layers, tmp_path_factory):
    path = tmp_path_factory.mktemp("dxf") / "gear.dxf"
    t0 = time.perf_counter()
    write_dxf(path, gear_layers)
    print(f"write_dxf of 60k vertices: {time.perf_counter() - t0:.3f} s")
    return path


def test_round_trip_equals_input(gear_layers, gear_file):
    back = read_dxf(gear_file)
    assert list(back) == [layer.name for layer in gear_layers]
    for layer in gear_layers:
        got = back[layer.name]
        assert len(got["outlines"]) == len(layer.outlines)
        for a, b in zip(layer.outlines, got["outlines"]):
            assert max_error(a, b) <= ROUND_TRIP_TOL
        assert len(got["circles"]) == len(layer.circles)
        for c, d in zip(layer.circles, got["circles"]):
            assert np.max(np.abs(np.subtract(c, d))) <= ROUND_TRIP_TOL


def test_file_structure(gear_layers, gear_file):
    doc = ezdxf.readfile(gear_file)  # ezdxf directly, not through read_dxf
    assert doc.dxfversion >= "AC1024"  # R2010
    assert doc.header["$INSUNITS"] == 4  # mm
    assert doc.header["$MEASUREMENT"] == 1  # metric
    msp = doc.modelspace()
    assert len(msp.query("SPLINE")) == 0
    assert {e.dxftype() for e in msp} == {"LWPOLYLINE", "CIRCLE"}
    for layer in gear_layers:
        polylines = msp.query(f'LWPOLYLINE[layer=="{layer.name}"]')
        assert len(polylines) == len(layer.outlines)  # one entity per outline
        for e, outline in zip(polylines, layer.outlines):
            assert e.closed
            assert len(e) == len(outline)
            pts = e.lwpoints.values
            assert np.all(pts[:, 2:] == 0)  # no widths, no bulges
            steps = np.hypot(*np.diff(np.vstack([pts[:, :2], pts[:1, :2]]), axis=0).T)
            assert steps.min() > 1e-9  # no duplicates, closing vertex not repeated
        assert doc.layers.get(layer.name).color == layer.color
    # extents are the bounding box of everything, so viewers can zoom to it
    xy = np.vstack([o for layer in gear_layers for o in layer.outlines])
    assert tuple(doc.header["$EXTMAX"])[:2] == tuple(xy.max(axis=0))
    assert tuple(doc.header["$EXTMIN"])[:2] == tuple(xy.min(axis=0))
    # nothing for the auditor to repair silently either
    auditor = doc.audit()
    assert not auditor.fixes and not auditor.errors


def test_audit_is_clean(gear_file):
    assert audit_dxf(gear_file) == 0


def test_duplicates_and_closing_vertex_are_removed(tmp_path):
    square = np.array([[0, 0], [10, 0], [10, 10], [0, 10]], dtype=float)
    dirty = np.array(
        [[0, 0], [10, 0], [10, 0], [10 + 1e-12, 1e-12], [10, 10], [0, 10], [0, 10], [0, 0]],
        dtype=float,
    )
    write_dxf(tmp_path / "sq.dxf", [DxfLayer("sq", outlines=(dirty,))])
    got = read_dxf(tmp_path / "sq.dxf")["sq"]["outlines"]
    assert len(got) == 1
    assert np.array_equal(got[0], square)


def test_clean_outline_keeps_close_but_distinct_vertices():
    # 1 nm apart is a real vertex (outlines are sampled to 1 um, not to 1 nm)
    pts = np.array([[0, 0], [1, 0], [1 + 1e-6, 0], [0, 1]], dtype=float)
    assert len(clean_outline(pts)) == 4
    with pytest.raises(ValueError, match="at least 3"):
        clean_outline([[0, 0], [1, 1], [1, 1], [0, 0]])


def test_layer_validation():
    with pytest.raises(ValueError, match="not valid"):
        DxfLayer("a/b")
    with pytest.raises(ValueError, match=r"\(N, 2\)"):
        DxfLayer("a", outlines=(np.zeros((4, 3)),))
    with pytest.raises(ValueError, match="r > 0"):
        DxfLayer("a", circles=((0, 0, 0),))
    with pytest.raises(ValueError, match="used twice"):
        build_dxf([DxfLayer("A"), DxfLayer("a")])
    outline = np.array([[0, 0], [1, 0], [0, 1]], dtype=float)
    layer = DxfLayer("a", outlines=(outline,))
    outline[0, 0] = 5.0  # the layer keeps its own read-only copy
    assert layer.outlines[0][0, 0] == 0.0
    with pytest.raises(ValueError):
        layer.outlines[0][0, 0] = 1.0


def test_empty_layer_round_trips(tmp_path):
    write_dxf(tmp_path / "e.dxf", [DxfLayer("empty"), DxfLayer("0", circles=((0, 0, 1),))])
    back = read_dxf(tmp_path / "e.dxf")
    empty = {"outlines": [], "circles": [], "paths": [], "texts": []}
    assert back == {"empty": empty, "0": {**empty, "circles": [(0.0, 0.0, 1.0)]}}


def test_read_rejects_what_the_writer_never_writes(tmp_path):
    doc = ezdxf.new("R2010")
    doc.modelspace().add_spline([(0, 0), (1, 1), (2, 0), (3, 1)])
    doc.saveas(tmp_path / "spline.dxf")
    with pytest.raises(InputFileError, match="SPLINE .* is not supported"):
        read_dxf(tmp_path / "spline.dxf")
    doc = ezdxf.new("R2010")
    doc.modelspace().add_lwpolyline([(0, 0), (1, 0), (0, 1)], close=False)
    doc.saveas(tmp_path / "open.dxf")
    with pytest.raises(InputFileError, match="is not closed"):
        read_dxf(tmp_path / "open.dxf")
    (tmp_path / "junk.dxf").write_text("not a dxf\n")
    with pytest.raises(InputFileError, match="junk.dxf"):
        read_dxf(tmp_path / "junk.dxf")
    with pytest.raises(InputFileError, match="missing.dxf"):
        audit_dxf(tmp_path / "missing.dxf")


def test_write_is_atomic(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    with pytest.raises(OutputError):
        write_dxf(blocker / "a.dxf", [DxfLayer("a", circles=((0, 0, 1),))])
    # a bad outline fails before anything is written
    with pytest.raises(ValueError, match="outline 0"):
        write_dxf(tmp_path / "bad.dxf", [DxfLayer("a", outlines=(np.zeros((5, 2)),))])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file"]


def test_batch_writes_both_files(tmp_path):
    layers = [DxfLayer("a", outlines=(star(1000),))]
    with atomic_batch() as batch:
        write_dxf(batch.temp_path(tmp_path / "one.dxf"), layers)
        write_dxf(batch.temp_path(tmp_path / "two.dxf"), layers)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["one.dxf", "two.dxf"]
    assert max_error(read_dxf(tmp_path / "two.dxf")["a"]["outlines"][0], layers[0].outlines[0]) == 0.0


@pytest.mark.skipif(shutil.which("librecad") is None, reason="LibreCAD not installed")
def test_librecad_reads_the_file(tmp_path):
    """A real CAD program opens the file and draws something (optional)."""
    path = tmp_path / "gear.dxf"
    write_dxf(path, [DxfLayer("a", outlines=(star(4000, lobes=40),), circles=((0, 0, 30),))])
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen")
    subprocess.run(
        ["librecad", "dxf2pdf", "-a", "-m", str(path)],
        cwd=tmp_path,
        env=env,
        check=True,
        capture_output=True,
        timeout=120,
    )
    pdf = tmp_path / "gear.pdf"
    assert pdf.exists() and pdf.stat().st_size > 1000


def test_layer_names_follow_the_dxf_rule():
    # ezdxf's table-name rule, plus what wgcad adds: 1-255 printable characters, no AutoCAD-special "*" layer
    from wgcad.export.formats.dxf import is_valid_layer_name

    for name in ["FLEXSPLINE", "GEAR_DATA", "RIGID OUTER", "xref|y", "Zähne 1", "x" * 255]:
        assert is_valid_layer_name(name), name
    for name in ["", "a<b", "q=1", 'say "hi"', "back`tick", "a/b", "*ACTIVE", "tab\there", "x" * 256]:
        assert not is_valid_layer_name(name), name
