"""Ring tables of the elastic model (wgcad.elastic.tables): the same numbers as the closed-form ring."""

from pathlib import Path

import numpy as np
import pytest

from wgcad.design import load_design
from wgcad.drive import build_drive
from wgcad.elastic import build_model
from wgcad.elastic.tables import Compliance

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def model():
    return build_model(build_drive(load_design(ROOT / "templates" / "d1_involute.toml")), 3)


def test_influence_is_the_ring_block_and_symmetric(model):
    tab = model.tables
    rng = np.random.default_rng(1)
    n = len(tab.angles)
    for i, j in rng.integers(0, n, size=(20, 2)):
        blk = model.ring.block(np.array(tab.angles[i] - tab.angles[j]))
        assert np.array_equal(tab.influence[3 * i : 3 * i + 3, 3 * j : 3 * j + 3], blk)
    # Maxwell-Betti: the compliance solver reads a load's column as its row
    assert np.abs(tab.influence - tab.influence.T).max() < 1e-12 * np.abs(tab.influence).max()


def test_tooth_field_is_the_ring_field(model):
    tab = model.tables
    rng = np.random.default_rng(2)
    loads = np.zeros((len(tab.angles), 3))
    pick = rng.choice(len(tab.angles), 30, replace=False)
    loads[pick] = rng.normal(size=(30, 3)) * [1e3, 1e3, 1e3]
    el = tab.tooth_field(loads)
    f = model.ring.field(tab.angles[: tab.z_g], tab.angles[pick], loads[pick])
    for row, key in enumerate(("w", "v", "theta")):
        assert np.abs(el[row] - f[key]).max() < 1e-12 * max(np.abs(f[key]).max(), 1e-30)


def test_compliance_columns_are_the_dense_product(model):
    tab = model.tables
    rng = np.random.default_rng(3)
    m = 40
    idx = rng.integers(0, len(tab.angles), m)
    fb = rng.normal(size=(m, 3))
    s = rng.random(m) * 1e-4
    B = np.zeros((m, tab.influence.shape[0]))
    for j in range(m):
        B[j, 3 * idx[j] : 3 * idx[j] + 3] = fb[j]
    ref = B @ tab.influence @ B.T + np.diag(s)
    C = Compliance(tab, idx, fb, s)
    scale = np.abs(ref).max()
    assert np.abs(C.cols(np.array([5, 2, 5, 39])) - ref[:, [5, 2, 5, 39]]).max() < 1e-12 * scale
    assert np.abs(C.dense() - ref).max() < 1e-12 * scale
    assert np.abs(C.diag - np.diag(ref)).max() < 1e-12 * scale


def test_compliance_with_other_contact_compliances(model):
    # a cold start re-solves its first pass with the Hertz contacts linearised again: the ring part's columns
    # built so far are kept and only the diagonal changes; the result must be a fresh Compliance's
    tab = model.tables
    rng = np.random.default_rng(3)
    idx = rng.integers(0, len(tab.angles), 12)
    fb = rng.normal(size=(12, 3))
    s1, s2 = rng.uniform(1e-6, 1e-5, 12), rng.uniform(1e-6, 1e-5, 12)
    C = Compliance(tab, idx, fb, s1)
    C.cols(np.array([2, 5, 7]))  # some columns built before the change
    C2 = C.with_contact(s2)
    ref = Compliance(tab, idx, fb, s2)
    assert np.allclose(C2.diag, ref.diag, rtol=1e-14, atol=0)
    assert np.allclose(C2.dense(), ref.dense(), rtol=1e-13, atol=1e-20)
    assert np.allclose(
        C.dense(), Compliance(tab, idx, fb, s1).dense(), rtol=1e-13, atol=1e-20
    )  # the original unchanged
