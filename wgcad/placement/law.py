"""Flexspline teeth placed as rigid bodies on the deformed neutral line (docs/models.md 3.1)."""

from __future__ import annotations

from math import pi

import numpy as np

from .. import constants
from ..kinematics import flex_rotation
from ..laws import Law

__all__ = [
    "tooth_angles",
    "tooth_frames",
    "tooth_pose",
    "pose_from_displacements",
    "transform",
    "place_points",
    "place_points_first_order",
    "place_flex_teeth",
    "deformed_curve",
    "join_teeth",
]


def tooth_angles(z_flex: int, z_rigid: int, phi_h: float, teeth=None) -> tuple[np.ndarray, np.ndarray]:
    """Angles of flexspline teeth for generator angle ``phi_h`` (rigid-gear frame).

    The flexspline turns by ``phi_h / u_hg`` (docs/models.md 1, rigid gear as the
    reference frame: with the flexspline fixed the relative motion is the
    same, only the frame that is drawn turns).

    Returns
    -------
    material : (K,) float
        Angle of each tooth's centre line in the rigid-gear frame if the
        rim were undeformed, rad.
    phi : (K,) float
        Angle of each tooth from the generator's major axis, rad.
    """
    k = np.arange(z_flex) if teeth is None else np.asarray(teeth)
    material = 2.0 * pi * k / z_flex + flex_rotation(phi_h, z_flex, z_rigid)
    return material, material - phi_h


def tooth_frames(law: Law, phi, r_m: float):
    """Origin and orientation of the rim cross-section carrying each tooth.

    ``P = (r_m + w) e_r(phi) + v e_t(phi)`` with the tooth turned by
    ``theta`` (docs/models.md 3.1), in the generator frame (major axis on +x).

    Returns
    -------
    origin : (K, 2) float
        Deformed position of the neutral-line point.
    angle : (K,) float
        ``phi + theta``: direction of the cross-section's normal.
    """
    phi = np.asarray(phi, dtype=float)
    st = law.state(phi)
    c, s = np.cos(phi), np.sin(phi)
    rad = r_m + st.w
    origin = np.stack([rad * c - st.v * s, rad * s + st.v * c], axis=-1)
    return origin, phi + st.theta


def transform(local: np.ndarray, rot, shift) -> np.ndarray:
    """Rigid copies of a polygon: ``R(rot[k]) @ local + shift[k]``, ``(K, N, 2)``.

    ``local`` is ``(N, 2)``, ``rot`` ``(K,)`` rad, ``shift`` ``(K, 2)`` mm.
    """
    rot = np.atleast_1d(np.asarray(rot, dtype=float))
    shift = np.atleast_2d(np.asarray(shift, dtype=float))
    c, s = np.cos(rot), np.sin(rot)
    rt = np.empty((len(rot), 2, 2))  # transposed rotations: local @ R^T, one batched matmul
    rt[:, 0, 0], rt[:, 0, 1], rt[:, 1, 0], rt[:, 1, 1] = c, s, -s, c
    out = np.matmul(local, rt)
    out += shift[:, None, :]
    return out


def pose_from_displacements(phi, w, v, theta, r_m: float, frame_angle=0.0, offset=0.0):
    """:func:`tooth_pose` from the neutral-line displacements ``w, v, theta`` at ``phi`` (arrays of one shape).

    ``offset`` (mm, broadcast against ``phi``): the tooth stands that much further out along its centre line
    (the law's ``tooth_offset``), i.e. the tooth frame's point ``p`` is placed as ``p + (offset, 0)``.
    """
    phi = np.asarray(phi, dtype=float)
    c, s = np.cos(phi), np.sin(phi)
    rad = r_m + w
    ox0, oy0 = rad * c - v * s, rad * s + v * c
    fa = np.broadcast_to(np.asarray(frame_angle, dtype=float), phi.shape)
    rot = fa + phi + theta
    c, s = np.cos(fa), np.sin(fa)
    lever = r_m - np.asarray(offset, dtype=float)
    ox = c * ox0 - s * oy0 - lever * np.cos(rot)
    oy = s * ox0 + c * oy0 - lever * np.sin(rot)
    return rot, np.stack([ox, oy], axis=-1)


def tooth_pose(law: Law, phi, r_m: float, frame_angle=0.0):
    """Rigid-body pose of each tooth: the tooth frame (tooth centred on +x) maps to ``R(rot) p + shift``.

    A tooth point ``p`` sits at height ``d = p_x - r_m`` above the neutral
    line and tangential offset ``s = p_y``; it goes to
    ``R(fa) [origin + R(phi + theta) (d, s)]`` (docs/models.md 3.1), i.e.
    ``rot = fa + phi + theta`` and ``shift = R(fa) origin - R(rot) (r_m, 0)``;
    a section whose teeth are offset along their centre lines (``law.tooth_offset``,
    docs/models.md 13.4) takes ``r_m - tooth_offset`` there.

    Returns
    -------
    rot : (K,) float
    shift : (K, 2) float
    """
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    st = law.state(phi)
    return pose_from_displacements(phi, st.w, st.v, st.theta, r_m, frame_angle, law.tooth_offset)


def place_points(local: np.ndarray, law: Law, phi, r_m: float, frame_angle=0.0) -> np.ndarray:
    """Exact placement: each tooth outline turned with its rim cross-section (docs/models.md 3.1).

    Parameters
    ----------
    local : (N, 2) float
        The undeformed tooth, centred on +x (tooth frame).
    phi : (K,) float
        Angles of the teeth from the major axis.
    frame_angle : float or (K,) float
        Added to every rotation: the generator's angle in the output frame.

    Returns
    -------
    (K, N, 2) float
    """
    return transform(local, *tooth_pose(law, phi, r_m, frame_angle))


def place_points_first_order(local: np.ndarray, law: Law, phi, r_m: float, centreline: bool = False) -> np.ndarray:
    """First-order placement: the tooth's rigid-body motion linearised in ``theta``.

    A point at height ``d`` above the neutral line and tangential offset
    ``s`` moves radially by ``w - s theta`` and tangentially by
    ``v + d theta``. On the tooth's centre line (``s = 0``) this is the form
    of [S3 eq. 15] (radial ``w``, tangential ``v + d theta``); with
    ``centreline=True`` that form is applied to every point, as if each
    point lay on the centre line - it then drops ``-s theta``, which is
    first order in ``theta`` (tens of um on a flank). Kept as a cross-check
    of :func:`place_points`: the linearised form differs from the exact one
    by ``O(theta^2)`` times the tooth size, i.e. ``O(W0^2 / r_m)`` for teeth
    of size ~ m ~ W0 (docs/models.md 3.1). Generator frame, ``(K, N, 2)``.
    """
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    st = law.state(phi)
    px = local[:, 0] + law.tooth_offset  # the section's teeth as offset along their centre lines
    d = px - r_m
    s_off = local[:, 1]
    x = px[None, :] + st.w[:, None]
    if not centreline:
        x = x - s_off[None, :] * st.theta[:, None]
    y = s_off[None, :] + st.v[:, None] + d[None, :] * st.theta[:, None]
    c, s = np.cos(phi)[:, None], np.sin(phi)[:, None]
    return np.stack([x * c - y * s, x * s + y * c], axis=-1)


def place_flex_teeth(
    drive, phi_h: float, local: np.ndarray | None = None, teeth=None, z: float | None = None
) -> np.ndarray:
    """Deformed flexspline teeth in the rigid-gear frame at generator angle ``phi_h``.

    Parameters
    ----------
    drive : wgcad.drive.Drive
    phi_h : float
        Generator angle relative to the rigid gear, rad.
    local : (N, 2) float, optional
        Tooth outline in the tooth frame; default one pitch of the flexspline
        boundary (``drive.flex.period``).
    teeth : (K,) int, optional
        Which teeth (default all).
    z : float, optional
        Axial section (coning); default the generator's centre section.

    Returns
    -------
    (K, N, 2) float
    """
    law = drive.law if z is None else drive.law_at(z)
    local = drive.flex.period if local is None else local
    _, phi = tooth_angles(drive.design.drive.z_flex, drive.design.drive.z_rigid, phi_h, teeth)
    return place_points(local, law, phi, drive.r_m, frame_angle=phi_h)


def deformed_curve(law: Law, r_m: float, d: float, phi) -> np.ndarray:
    """Points ``(K, 2)`` of the rim line at height ``d`` above the neutral line (``d = 0``: neutral line), generator frame."""
    origin, ang = tooth_frames(law, phi, r_m)
    return origin + d * np.stack([np.cos(ang), np.sin(ang)], axis=-1)


def _crossing(tail: np.ndarray, head: np.ndarray):
    """First crossing of polyline ``tail`` with polyline ``head``: (tail segment, head segment, point) or None."""
    p0, p1 = tail[:-1, None, :], tail[1:, None, :]
    q0, q1 = head[None, :-1, :], head[None, 1:, :]
    r, sv = p1 - p0, q1 - q0
    den = r[..., 0] * sv[..., 1] - r[..., 1] * sv[..., 0]
    qp = q0 - p0
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (qp[..., 0] * sv[..., 1] - qp[..., 1] * sv[..., 0]) / den
        u = (qp[..., 0] * r[..., 1] - qp[..., 1] * r[..., 0]) / den
    ok = (den != 0) & (t >= 0) & (t <= 1) & (u >= 0) & (u <= 1)
    # a shared end point is a junction, not a crossing
    ok &= ~((t == 1) & (u == 0))
    if not ok.any():
        return None
    i, j = np.argwhere(ok)[0]
    return int(i), int(j), (p0[i, 0] + t[i, j] * r[i, 0])


def join_teeth(teeth: np.ndarray, m: int = 6) -> np.ndarray:
    """One closed outline ``(M, 2)`` from placed pitches ``(K, N, 2)``, each from space centre to space centre.

    Neighbouring teeth turn by slightly different angles, so their root ends
    either leave a sub-micrometre gap (joined straight) or cross (pointed
    cycloidal roots): there both are cut at the crossing, which keeps the
    outline simple.
    """
    K, N, _ = teeth.shape
    first = [0] * K  # first kept vertex index of each tooth
    last = [N - 1] * K  # last kept vertex index
    lead = [None] * K  # point that starts a tooth (a crossing)
    trail = [None] * K  # point that ends a tooth
    for k in range(K):
        nk = (k + 1) % K
        hit = _crossing(teeth[k][N - m :], teeth[nk][:m])
        if hit is not None:
            i, j, p = hit
            last[k], trail[k] = N - m + i, p
            first[nk], lead[nk] = j + 1, p
    out = []
    for k in range(K):
        part = teeth[k][first[k] : last[k] + 1]
        if lead[k] is not None:
            part = np.vstack([lead[k], part])
        if trail[k] is not None:
            part = np.vstack([part, trail[k]])
        out.append(part)
    for k in range(K):
        if trail[k] is None:
            out[k] = _trim_back_step(out[k], out[(k + 1) % K][0])
    return _space(np.vstack(out), constants.MIN_VERTEX_SPACING)


def _trim_back_step(part: np.ndarray, nxt: np.ndarray) -> np.ndarray:
    """Drop end vertices of ``part`` that the next tooth's first vertex ``nxt`` lies behind (or within the minimum spacing of).

    Where neighbouring root lands overlap without crossing (they run
    sub-micrometre apart), joining them straight stepped back along the
    root by 0.06-1 um: the outline now leaves ``part`` at its
    last vertex that ``nxt`` lies ahead of.
    """
    while len(part) > 2:
        d_in = part[-1] - part[-2]
        step = nxt - part[-1]
        if float(np.dot(step, d_in)) > 0.0 and np.hypot(*step) >= constants.MIN_VERTEX_SPACING:
            break
        part = part[:-1]
    return part


def _space(pts: np.ndarray, spacing: float) -> np.ndarray:
    """Drop vertices closer than ``spacing`` to the last kept one (closed outline: the last is also checked against the first)."""
    pts = np.ascontiguousarray(pts)
    while len(pts) > 3:
        step = np.hypot(*(np.roll(pts, -1, axis=0) - pts).T)  # step i: vertex i -> i + 1 (cyclic)
        bad = np.nonzero(step < spacing)[0]
        if bad.size == 0:
            break
        # drop the later vertex of each short step; of a run of short steps only every other one per pass
        bad = bad[np.concatenate([[True], np.diff(bad) > 1])]
        drop = (bad + 1) % len(pts)
        drop = drop[drop != 0] if len(drop) > 1 else drop
        pts = np.delete(pts, drop, axis=0)
    return pts
