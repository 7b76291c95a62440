"""The loaded rim and its teeth: displacements of the neutral line from the ring's loads, every tooth's pose and
neutral-line origin, and the loads moved between the contact solver's angles and the ring's tables
(docs/models.md 4.1). Used by each pass of :func:`wgcad.elastic.state.solve_load`."""

from __future__ import annotations

import numpy as np

from wgcad.placement import pose_from_displacements

from .model import ElasticModel

__all__ = [
    "RADIAL_MARGIN",
    "dense_loads",
    "displaced",
    "loads_on_table",
    "merge_loads",
    "rim_displacements",
    "tooth_origins",
    "tooth_poses",
]

#: Teeth whose tips stay this far inside the rigid tip circle are left out, mm:
#: the rim moves by tens of um under rated load; 0.2 mm is four times more.
RADIAL_MARGIN = 0.2


def rim_displacements(model: ElasticModel, loads: np.ndarray, motion) -> tuple:
    """``w, v, theta`` ``(S, z_g)`` of every section at the tooth angles, and the elastic field ``(3, z_g)`` (centre scale).

    ``motion``: the rim's rigid-body motion against the rigid gear, ``(dx, dy, rot)`` (3,) for every section or
    ``(S, 3)`` one per section (docs/models.md 4.2). The formula of :class:`LoadedLaw` (nominal law + scaled ring
    field + rigid-body motion) on the model's tables: the same numbers, without the kernel evaluations.
    """
    tab = model.tables
    el = tab.tooth_field(loads)
    phi = tab.angles[: tab.z_g]
    c, sn = np.cos(phi), np.sin(phi)
    m = np.asarray(motion, dtype=float).reshape(-1, 3)
    dx, dy, rot = m[:, 0:1], m[:, 1:2], m[:, 2:3]
    nom = tab.nominal
    f = model.scales[:, None]
    # the rim is round when unloaded: the cam's balls bend it (their forces are among the loads), so the
    # elastic field is the whole displacement; the rotation turns the deformed rim, which is the nominal
    # law to within the bearing's clearance (its coupling terms are second order: rot times w, v)
    w = f * el[0] + (dx * c + dy * sn) - rot * nom[:, 1]
    v = f * el[1] + (-dx * sn + dy * c) + rot * (model.drive.r_m + nom[:, 0])
    th = f * el[2] + rot
    return w, v, th, el


def tooth_poses(model: ElasticModel, loads: np.ndarray, motion, tooth_errors=None):
    """Poses of every tooth of every section (flattened ``section * z_g + tooth``), their neutral-line origins and
    the elastic field, plus the indices of the teeth whose tips reach within RADIAL_MARGIN of the rigid tips.

    ``tooth_errors``: ``(turn (S z_g,), move (S z_g, 2))``, each tooth's pose turned about the axis by ``turn``
    then moved by ``move`` (relative to the rigid teeth: an imperfect drive's errors, :func:`solve_load`)."""
    d = model.drive
    z_g = model.tables.z_g
    S = len(model.zs)
    w, v, th, el = rim_displacements(model, loads, motion)
    phi = np.broadcast_to(model.tables.angles[:z_g], (S, z_g))
    off = np.array([model.section_law(i).tooth_offset for i in range(S)])[:, None]
    rot, shift = pose_from_displacements(phi, w, v, th, d.r_m, 0.0, off)
    rot, shift = rot.ravel(), shift.reshape(-1, 2)
    c, sn = np.cos(phi).ravel(), np.sin(phi).ravel()
    w, v = w.ravel(), v.ravel()
    origin = np.stack([(d.r_m + w) * c - v * sn, (d.r_m + w) * sn + v * c], axis=-1)
    if tooth_errors is not None:
        rot = rot + tooth_errors[0]
        shift = displaced(shift, tooth_errors)
        origin = displaced(origin, tooth_errors)
    # outermost tip radius of each placed tooth: |R p + s|^2 = |p|^2 + |s|^2 + 2 p . R^T s, one small product
    tip = model.scene.flex_tip_local
    cr, sr = np.cos(rot), np.sin(rot)
    u = np.stack([cr * shift[:, 0] + sr * shift[:, 1], -sr * shift[:, 0] + cr * shift[:, 1]], axis=-1)
    R = np.sqrt(((tip * tip).sum(axis=1) + 2.0 * (u @ tip.T)).max(axis=1) + (shift * shift).sum(axis=1))
    cand = np.nonzero(R >= model.scene.r_tip_b - RADIAL_MARGIN)[0]
    return rot, shift, origin, el, cand


def merge_loads(phi, loads):
    """Generalized loads summed per distinct angle, zero ones dropped (same field, far fewer kernel evaluations)."""
    nz = np.any(loads != 0.0, axis=1)
    u, inv = np.unique(np.round(phi[nz], 15), return_inverse=True)
    out = np.zeros((len(u), 3))
    np.add.at(out, inv, loads[nz])
    return u, out


def dense_loads(n: int, idx, F, f, b) -> np.ndarray:
    """Generalized loads ``(n, 3)`` on the ring at the table's angles from contact forces ``F`` (N)."""
    out = np.zeros((n, 3))
    np.add.at(out, idx, -(F * f)[:, None] * b)
    return out


def displaced(points: np.ndarray, tooth_errors) -> np.ndarray:
    """Points ``(S z_g, 2)`` of each tooth turned about the axis by ``turn`` and moved by ``move`` (``tooth_errors``)."""
    turn, move = tooth_errors
    ct, st = np.cos(turn), np.sin(turn)
    return np.stack([ct * points[:, 0] - st * points[:, 1], st * points[:, 0] + ct * points[:, 1]], axis=-1) + move


def tooth_origins(model: ElasticModel, loads: np.ndarray, motion, tooth_errors=None) -> np.ndarray:
    """Neutral-line origins ``(S z_g, 2)`` of every tooth of every section (flattened as in :func:`tooth_poses`)."""
    w, v, _, _ = rim_displacements(model, loads, motion)
    phi = model.tables.angles[: model.tables.z_g]
    c, sn = np.cos(phi), np.sin(phi)
    r = model.drive.r_m + w
    out = np.stack([r * c - v * sn, r * sn + v * c], axis=-1).reshape(-1, 2)
    return out if tooth_errors is None else displaced(out, tooth_errors)


def loads_on_table(tab, psi, loads) -> np.ndarray:
    """Generalized loads at angles ``psi`` put on the table's angles (a warm start from a solved state)."""
    out = np.zeros((len(tab.angles), 3))
    where = {}
    for i, a in enumerate(np.round(tab.angles, 15).tolist()):
        where.setdefault(a, i)
    for a, l in zip(np.round(psi, 15).tolist(), loads):
        out[where[a]] += l
    return out
