"""The DXF writer without ezdxf (wgcad.export.dxf_tags) writes ezdxf's file byte for byte: for every drawing of
every template (generate with a deformed assembly, the part set) and for random drawings (odd layer names and
colours, construction layers, layers 0 and Defpoints, bulges, texts). ezdxf reads every file back to the same
layers. The byte comparison needs the ezdxf the skeleton was made with; with another one the files are compared
as ezdxf reads them."""

import ezdxf
import numpy as np
import pytest
from conftest import TEMPLATES
from dxf_skeleton_make import make

from wgcad.cli import main
from wgcad.export import dxf as dxf_module
from wgcad.export import dxf_skeleton as sk
from wgcad.export.dxf import DxfLayer, audit_dxf, ezdxf_dxf_text, prepare, read_dxf, write_dxf
from wgcad.export.dxf_tags import dxf_text

ALL = sorted(p.stem for p in TEMPLATES.glob("*.toml"))
SAME_EZDXF = ezdxf.__version__ == sk.EZDXF_VERSION


def same_file(layers, tmp_path):
    """Our file equals ezdxf's: bytes with the skeleton's ezdxf, as ezdxf reads them always."""
    ours = dxf_text(*prepare(layers))
    theirs = ezdxf_dxf_text(layers)
    if SAME_EZDXF:
        assert ours == theirs
    (tmp_path / "ours.dxf").write_text(ours, encoding="utf-8")
    (tmp_path / "theirs.dxf").write_text(theirs, encoding="utf-8")
    assert audit_dxf(tmp_path / "ours.dxf") == 0
    a, b = read_dxf(tmp_path / "ours.dxf"), read_dxf(tmp_path / "theirs.dxf")
    assert list(a) == list(b)
    for name in a:
        for kind in ("outlines", "circles", "texts"):
            assert len(a[name][kind]) == len(b[name][kind])
            for x, y in zip(a[name][kind], b[name][kind]):
                np.testing.assert_array_equal(np.asarray(x, dtype=object), np.asarray(y, dtype=object))
        for (va, ba), (vb, bb) in zip(a[name]["paths"], b[name]["paths"]):
            np.testing.assert_array_equal(va, vb)
            np.testing.assert_array_equal(ba, bb)


def test_skeleton_is_ezdxf_empty_drawing():
    if not SAME_EZDXF:
        pytest.skip(f"skeleton made with ezdxf {sk.EZDXF_VERSION}, {ezdxf.__version__} installed")
    d = make()
    assert sk.PARTS == d["PARTS"] and sk.SLOTS == d["SLOTS"] and sk.LAYERS == d["LAYERS"]
    assert (sk.FIRST_HANDLE, sk.LAYER_TABLE, sk.LTYPE_TABLE, sk.MODEL_SPACE, sk.LTYPES) == (
        d["FIRST_HANDLE"],
        d["LAYER_TABLE"],
        d["LTYPE_TABLE"],
        d["MODEL_SPACE"],
        d["LTYPES"],
    )


def random_layers(rng):
    names = ["0", "Defpoints", "DEFPOINTS", "FLEX", "rigid|xref", "Zähne 1", "a b", "L-2", "x.y"]
    layers, used = [], set()
    for _ in range(int(rng.integers(0, 6))):
        name = str(rng.choice(names))
        if name.lower() in used:
            continue
        used.add(name.lower())
        t = np.sort(rng.uniform(0, 2 * np.pi, int(rng.integers(3, 40))))
        scale = float(rng.choice([1e-3, 1.0, 80.0, 1e4]))
        outline = scale * np.c_[np.cos(t), np.sin(t)] * rng.uniform(0.5, 1.5, (len(t), 1)) + rng.normal(0, 5, 2)
        bulges = np.where(rng.random(len(t)) < 0.5, 0.0, rng.uniform(-1, 1, len(t)))
        layers.append(
            DxfLayer(
                name,
                outlines=(outline,) * int(rng.integers(0, 3)),
                paths=((outline, bulges),) * int(rng.integers(0, 2)),
                circles=tuple(
                    (float(x), float(y), float(r)) for x, y, r in rng.uniform(0.1, 50, (rng.integers(0, 3), 3))
                ),
                texts=((float(rng.normal()), float(rng.normal()), 2.5, "m = 0.5 mm, z = 160, 45°, Ø 80 — ok"),)
                * int(rng.integers(0, 2)),
                color=int(rng.integers(1, 256)),
                construction=bool(rng.random() < 0.4),
            )
        )
    return layers


@pytest.mark.parametrize("seed", range(40))
def test_random_drawings_equal_ezdxf(seed, tmp_path):
    same_file(random_layers(np.random.default_rng(seed)), tmp_path)


def test_no_layers_and_empty_layers(tmp_path):
    same_file([], tmp_path)
    same_file([DxfLayer("EMPTY"), DxfLayer("0", construction=True)], tmp_path)


@pytest.mark.parametrize("name", ALL)
def test_template_drawings_equal_ezdxf(name, tmp_path, monkeypatch):
    drawings = []
    real = dxf_module.write_dxf

    def spy(path, layers):
        layers = list(layers)
        drawings.append(layers)
        real(path, layers)

    monkeypatch.setattr(dxf_module, "write_dxf", spy)
    design = TEMPLATES / f"{name}.toml"
    assert main(["generate", str(design), "--out", str(tmp_path / "g"), "--generator-angle", "7", "--quiet"]) == 0
    assert main(["parts", str(design), "--out", str(tmp_path / "p"), "--format", "dxf", "--quiet"]) == 0
    assert len(drawings) >= 3  # the gears, the deformed assembly, the part set's drawings
    for layers in drawings:
        same_file(layers, tmp_path)


def test_write_dxf_writes_the_text(tmp_path):
    layers = random_layers(np.random.default_rng(7))
    write_dxf(tmp_path / "a.dxf", layers)
    assert (tmp_path / "a.dxf").read_bytes() == dxf_text(*prepare(layers)).encode("utf-8")
