"""The [sectors] table: layout rules of a sectored rigid gear, each broken rule a one-line error with exit code 2 and nothing written."""

import pytest
from conftest import TEMPLATES, edit_toml

from wgcad.cli import main
from wgcad.design import load_design, parse_design
from wgcad.design.sectors import SectorsSpec, validate_sectors
from wgcad.errors import DesignError

D4 = TEMPLATES / "d4_sectored.toml"

# (table, key, new value, field named in the message, words of the rule)
BAD = [
    # docs/models.md 9 as printed: 86 flexspline teeth and 2 x 22 + 2 x 21 = 86 rigid teeth; with the flexspline's pitch in the
    # coupling sectors and 2 pi / 88 in the transmission sectors they cover 2 x (90 + 87.907) = 355.81 deg
    ("drive", "z_flex", "86", "sectors.teeth", "sectors must fill the circle"),
    ("sectors", "teeth", "[21, 22, 21, 23]", "sectors.teeth", "must be identical"),
    ("sectors", "teeth", "[21, 22, 21]", "sectors.teeth", "one tooth count per sector"),
    ("sectors", "teeth", "[20, 22, 20, 22]", "sectors.teeth", "sectors must fill the circle"),
    ("sectors", "kinds", '["coupling", "coupling", "transmission", "transmission"]', "sectors.kinds", "must alternate"),
    ("sectors", "kinds", '["coupling", "transmission"]', "sectors.kinds", "2 x drive.waves = 4 sectors"),
    (
        "sectors",
        "kinds",
        '["coupling", "transmision", "coupling", "transmission"]',
        "sectors.kinds[1]",
        "must be one of transmission, coupling",
    ),
    ("sectors", "pitch_z", "[85, 88, 85, 88]", "sectors.pitch_z[0]", "coupling sector has the flexspline's pitch"),
    ("sectors", "pitch_z", "[84, 84, 84, 84]", "sectors.pitch_z[1]", "pitch other than the flexspline's"),
    ("sectors", "heights", '"patent"', "sectors.heights", "must be one of closed_form, simulated, full, list"),
    ("sectors", "heights", '"list"', "sectors.heights_mm", "one height per coupling tooth (21)"),
    ("sectors", "heights_mm", "[0.3, 0.3]", "sectors.heights_mm", 'used only with heights = "list"'),
    ("sectors", "assign", '"middle"', "sectors.assign", "must be one of boundary, register"),
    ("sectors", "tip_clearance_um", "-5.0", "sectors.tip_clearance_um", "must be in [0, 1000)"),
    ("sectors", "teeth", '"21"', "sectors.teeth", "must be a non-empty list"),
    ("sectors", "teeth", "[21, 22.0, 21, 22]", "sectors.teeth[1]", "must be a whole number"),
    ("sectors", "tooth_count", "[21]", "sectors.tooth_count", "unknown key"),
]


def _run(argv, capsys):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


@pytest.mark.parametrize("table,key,value,field,rule", BAD)
def test_bad_sector_layout_is_one_line_exit_2_nothing_written(tmp_path, capsys, table, key, value, field, rule):
    path = tmp_path / "bad.toml"
    path.write_text(edit_toml(D4.read_text(), table, key, value))
    out = tmp_path / "out"
    code, so, se = _run(["sector", path, "--out", out], capsys)
    assert code == 2
    assert se.count("\n") == 1 and se.startswith("wgcad: error: "), se
    assert "Traceback" not in se
    assert f"error: {field}" in se, se
    assert rule in se, se
    assert not out.exists() or not any(out.iterdir())


def test_listed_height_above_full_height_is_an_error(tmp_path, capsys):
    text = edit_toml(D4.read_text(), "sectors", "heights", '"list"')
    text = edit_toml(text, "sectors", "heights_mm", "[" + ", ".join(["0.5"] * 20 + ["0.75"]) + "]")
    path = tmp_path / "bad.toml"
    path.write_text(text)
    code, so, se = _run(["sector", path, "--out", tmp_path / "out", "--step-deg", "1"], capsys)
    assert code == 2 and se.count("\n") == 1
    assert "sectors.heights_mm[20]" in se and "exceeds the full tooth height 0.7000 mm" in se
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def test_design_without_sectors_is_a_usage_error(tmp_path, capsys):
    code, so, se = _run(["sector", TEMPLATES / "d4_discrete.toml", "--out", tmp_path / "o"], capsys)
    assert code == 2 and se.count("\n") == 1 and "sectors:" in se and "no [sectors] table" in se


def test_template_parses_and_other_templates_have_no_sectors():
    d = load_design(D4)
    assert d.sectors.active and d.sectors.teeth == (21, 22, 21, 22)
    assert not load_design(TEMPLATES / "d4_discrete.toml").sectors.active


def test_rules_directly():
    spec = SectorsSpec(kinds=("coupling", "transmission", "coupling", "transmission"), teeth=(21, 22, 21, 22))
    assert validate_sectors(spec, 84, 88, 2) is spec
    # the flexspline of 86 teeth with a transmission pitch that moves it one tooth a half turn: 23 teeth at 2 pi / (86 x 23/22)
    alt = SectorsSpec(kinds=spec.kinds, teeth=(21, 23, 21, 23), pitch_z=(86.0, 86 * 23 / 22, 86.0, 86 * 23 / 22))
    assert validate_sectors(alt, 86, 88, 2) is alt
    with pytest.raises(DesignError, match="drive.z_flex: must be a multiple of drive.waves"):
        validate_sectors(
            SectorsSpec(kinds=spec.kinds, teeth=(21, 22, 21, 22), pitch_z=(85.0, 88.0, 85.0, 88.0)), 85, 89, 2
        )


def test_parse_design_keeps_lists_as_tuples():
    import tomllib

    data = tomllib.loads(D4.read_text())
    d = parse_design(data)
    assert isinstance(d.sectors.kinds, tuple) and isinstance(d.sectors.teeth, tuple)
    hash(d.sectors)  # frozen and hashable
