"""Design input (issue 13): bounds on every number, one-line errors naming the field and rule, only regular files read."""

import os
import threading
import tomllib
from dataclasses import fields

import pytest
from conftest import TEMPLATES, edit_toml

from wgcad.cli import main
from wgcad.design import TABLES, load_design, parse_design
from wgcad.design.files import MAX_DESIGN_BYTES
from wgcad.design.rules import Rel, context, key_meta
from wgcad.drive import build_drive
from wgcad.errors import DesignError, InputFileError

NAMES = ["d1_involute", "d1_cycloidal", "d2", "d3_external", "d4_discrete"]


def data(name):
    return tomllib.loads((TEMPLATES / f"{name}.toml").read_text())


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def one_line(err: str) -> str:
    assert err.count("\n") == 1 and err.startswith("wgcad: error: ") and "Traceback" not in err, err
    return err


# ----------------------------------------------------------------------------- declared bounds
def bounded_keys():
    for table, cls in TABLES.items():
        for f in fields(cls):
            meta = key_meta(f)
            if meta.get("lo") is not None or meta.get("hi") is not None:
                yield table, f.name, meta


@pytest.mark.parametrize("table,key,meta", list(bounded_keys()), ids=lambda x: x if isinstance(x, str) else "")
@pytest.mark.parametrize("side", ["lo", "hi"])
def test_every_bound_refuses_just_outside(table, key, meta, side):
    """Each declared bound of each key, on D1 (D1 cycloidal for involute-only keys is not needed: bounds are per key)."""
    base = data("d4_sectored" if table == "sectors" else "d1_involute")  # a [sectors] key needs a sector layout
    if table == "generator" and key == "offset":
        base["generator"] = {"law": "ellipse", "w0_coef": 1.1}  # the offset belongs to the ellipse law
    if table == "generator" and key == "beta_deg":
        base["generator"]["beta_deg"] = 35.0
    b = meta[side]
    if b is None:
        pytest.skip("no bound on this side")
    design = parse_design(base)
    ctx = context(design)
    ctx = {**ctx, "d": ctx["d_flex"] if table != "rigid" else ctx["d_rigid"]}
    ctx["r"] = ctx["d"] / 2
    v = b(ctx) if isinstance(b, Rel) else float(b)
    open_ = meta[f"{side}_open"]
    eps = 1e-6 * max(1.0, abs(v))
    outside = v - eps if side == "lo" else v + eps
    if open_:
        outside = v
    ints = key in ("z_flex", "z_rigid", "waves", "balls")
    if ints:
        outside = int(v) - 1 if side == "lo" else int(v) + 1
    bad = {**base, table: {**base.get(table, {}), key: outside}}
    with pytest.raises(DesignError) as e:
        parse_design(bad)
    assert e.value.field == f"{table}.{key}", str(e.value)
    assert "\n" not in str(e.value)


HUGE = [
    ("drive", "module", "1e12"),
    ("drive", "module", "1e6"),
    ("drive", "module", "1e-9"),
    ("drive", "z_flex", "1000000000"),
    ("drive", "z_rigid", "1000000"),
    ("drive", "z_flex", "99999999999999"),
    ("drive", "face_width", "1e300"),
    ("drive", "waves", "1000000"),
    ("tooth", "addendum_coef", "1e39"),
    ("tooth", "clearance_coef", "1e39"),
    ("flexspline", "shift", "1e39"),
    ("flexspline", "rim_thickness", "1e39"),
    ("rigid", "rim_thickness", "1e9"),
    ("flexspline", "tip_radius", "1e39"),
    ("rigid", "root_radius", "1e-300"),
    ("flexspline", "fillet_coef", "1e9"),
    ("generator", "w0_coef", "1e39"),
    ("generator", "cone_length", "1e39"),
    ("generator", "generator_z", "1e39"),
]


@pytest.mark.parametrize("table,key,value", HUGE)
def test_absurd_numbers_are_one_line_errors_naming_the_field(table, key, value, tmp_path, capsys):
    text = edit_toml((TEMPLATES / "d1_involute.toml").read_text(), table, key, value)
    p = tmp_path / "bad.toml"
    p.write_text(text)
    for cmd in (
        ["generate", p, "--out", tmp_path / "o", "--no-stl"],
        ["audit", p, "--json", tmp_path / "o" / "a.json"],
    ):
        code, out, err = run(cmd, capsys)
        assert code == 2
        one_line(err)
        # the field itself is named: absolute bounds are checked before any rule combining fields
        assert err.startswith(f"wgcad: error: {table}.{key}: "), err
        assert not (tmp_path / "o").exists() or not any((tmp_path / "o").iterdir())


def test_z_rigid_million_on_d1_is_refused_not_reported_as_no_interference(tmp_path, capsys):
    # issue 13: z_rigid = 1,000,000 ran and printed "minimum clearance 399917488 um ... no interference"
    text = edit_toml((TEMPLATES / "d1_involute.toml").read_text(), "drive", "z_rigid", "1000000")
    p = tmp_path / "bad.toml"
    p.write_text(text)
    code, out, err = run(["audit", p], capsys)
    assert code == 2 and out == ""
    assert "drive.z_rigid: must be in [8, 3000]" in one_line(err)


@pytest.mark.parametrize(
    "z_rigid,w0,field",
    [(2000, None, "drive.z_rigid"), (208, "1.1", "generator.w0_coef"), (206, "1.1", None), (202, "0.05", None)],
)
def test_teeth_that_never_meet_are_refused_in_one_line(z_rigid, w0, field, tmp_path, capsys):
    # D1 with textbook teeth (docs/models.md 2.1): flexspline tip r_a = 80 + 0.8 (1 + 3.1) = 83.28 mm, rigid tip
    # 0.4 z_rigid + 0.8 (3.2 - 1); the largest W0 over the coned face is at the open end, W0 * 160/142 (docs/models.md
    # 3.1). 206 teeth still mesh, 208 leave the tips 0.69 mm short (a larger W0 would close it), 2000 teeth 717 mm
    text = edit_toml((TEMPLATES / "d1_involute_nominal.toml").read_text(), "drive", "z_rigid", str(z_rigid))
    if w0:
        text = edit_toml(text, "generator", "w0_coef", w0)
    p = tmp_path / "d.toml"
    p.write_text(text)
    w0_open = float(w0 or 1.1) * 0.8 * 160 / 142
    gap = (0.4 * z_rigid + 0.8 * 2.2) - (83.28 + w0_open)
    code, out, err = run(["audit", p], capsys)
    if gap < 0:
        assert field is None and code in (0, 1), err
        return
    assert code == 2 and out == ""
    one_line(err)
    assert f"{field}: the teeth never meet" in err
    assert f"{gap:.4f} mm short" in err


# ----------------------------------------------------------------------------- what is read as a design
def test_a_directory_is_refused(tmp_path, capsys):
    code, out, err = run(["audit", tmp_path], capsys)
    assert code == 2 and "is a directory, not a regular file" in one_line(err)


def test_dev_zero_is_refused_without_reading_it(capsys):
    code, out, err = run(["audit", "/dev/zero"], capsys)
    assert code == 2 and "is a character device, not a regular file" in one_line(err)


def test_a_fifo_is_refused_without_waiting_for_a_writer(tmp_path, capsys):
    fifo = tmp_path / "design.toml"
    os.mkfifo(fifo)
    result = {}

    def go():
        result["r"] = run(["generate", fifo, "--out", tmp_path / "o"], capsys)

    t = threading.Thread(target=go, daemon=True)
    t.start()
    t.join(20.0)  # a hang would block forever on open(); the run itself takes milliseconds
    assert not t.is_alive(), "reading a FIFO as the design blocked"
    code, out, err = result["r"]
    assert code == 2 and "is a FIFO (named pipe), not a regular file" in one_line(err)
    assert not (tmp_path / "o").exists()


def test_a_symlink_to_a_regular_file_is_read(tmp_path):
    link = tmp_path / "link.toml"
    link.symlink_to(TEMPLATES / "d4_discrete.toml")
    assert load_design(link).drive.z_flex == 86


def test_design_files_over_the_size_limit_are_refused(tmp_path):
    p = tmp_path / "big.toml"
    text = (TEMPLATES / "d4_discrete.toml").read_text()
    p.write_text(text + "#" * (MAX_DESIGN_BYTES - len(text.encode()) + 1) + "\n")
    with pytest.raises(InputFileError, match="larger than the limit of 1048576 bytes"):
        load_design(p)
    # at the limit it is read
    p.write_text(text + "#" * (MAX_DESIGN_BYTES - len(text.encode()) - 1) + "\n")
    assert p.stat().st_size == MAX_DESIGN_BYTES
    assert load_design(p).drive.z_flex == 86


@pytest.mark.parametrize("nest", ["array", "table"])
def test_deeply_nested_toml_is_a_one_line_error(nest, tmp_path, capsys):
    # issue 13: a 5000-deep nested array gave a RecursionError traceback
    depth = 5000
    value = "[" * depth + "1" + "]" * depth if nest == "array" else "{a = " * depth + "1" + "}" * depth
    p = tmp_path / "deep.toml"
    p.write_text((TEMPLATES / "d4_discrete.toml").read_text() + f"\n[extra]\nx = {value}\n")
    code, out, err = run(["audit", p], capsys)
    assert code == 2
    assert "nested too deeply" in one_line(err)


def test_nested_values_in_a_known_key_are_named_briefly(tmp_path, capsys):
    # 50 levels parse; the message shows the value abbreviated, not 50 levels of brackets
    text = edit_toml((TEMPLATES / "d4_discrete.toml").read_text(), "drive", "module", "[" * 50 + "1" + "]" * 50)
    p = tmp_path / "n.toml"
    p.write_text(text)
    code, out, err = run(["audit", p], capsys)
    assert code == 2 and "drive.module: must be a number, got list" in one_line(err)
    assert len(err) < 200


def test_not_utf8_is_a_one_line_error(tmp_path, capsys):
    p = tmp_path / "latin1.toml"
    p.write_bytes((TEMPLATES / "d4_discrete.toml").read_bytes().replace(b"D4", b"D\xe94"))
    code, out, err = run(["audit", p], capsys)
    assert code == 2 and "not UTF-8" in one_line(err)


def test_names_are_one_line(tmp_path, capsys):
    d = data("d4_discrete")
    d["drive"]["name"] = "two\nlines"
    with pytest.raises(DesignError, match="drive.name: must be 1 to 200 characters on one line"):
        parse_design(d)


@pytest.mark.parametrize("name", NAMES)
def test_every_template_is_within_every_bound(name):
    build_drive(load_design(TEMPLATES / f"{name}.toml"))


@pytest.mark.parametrize(
    "table,key,value,says",
    [
        ("imperfections", "flex_runout_um", float("nan"), "must be finite"),
        ("imperfections", "cam_offset_fixed_um", -1.0, "must be in [0, m/4 (in um)"),
        ("imperfections", "rigid_install_angle_deg", 400.0, "must be in [-360, 360]"),
        ("material", "poisson", 0.5, "must be in [0, 0.5)"),
        ("bearing", "groove_conformity", 1.0, "must be in (0.5, 1)"),
        ("bearing", "balls", 2, "must be in [3, 1000]"),
        ("load", "cam_offset_um", float("inf"), "must be finite"),
    ],
)
def test_table_bounds_come_from_the_key_declarations(table, key, value, says):
    # issue 20: [imperfections] and the load tables were checked twice, by their keys' bounds and by hand;
    # the keys' bounds are the one rule now, also for a design changed in code (where NaN can reach them)
    from wgcad.design import load_design
    from wgcad.design.schema import with_changes
    from wgcad.errors import DesignError

    d = load_design(TEMPLATES / "d1_involute.toml")
    with pytest.raises(DesignError) as e:
        with_changes(d, **{table: {key: value}})
    assert e.value.field == f"{table}.{key}" and says in e.value.rule, str(e.value)
