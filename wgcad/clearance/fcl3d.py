"""The 3D engine at the edge: tooth solids (coned lofts, prisms) and their exact distance in python-fcl, checking the 2D engine's tightest pairs (docs/models.md 3.1, 5)."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import fcl
import manifold3d
import numpy as np

from ..placement import transform
from ..placement.imperfect import flex_poses, rigid_translation
from .engine import Scene
from .imperfect_scene import ImperfectScene
from .scene import clearance_at_poses

__all__ = [
    "FCL_TOL",
    "loft",
    "flex_tooth_solid",
    "rigid_tooth_solid",
    "loft_error",
    "fcl_distance",
    "check_tooth",
    "verify_worst",
    "PairCheck",
    "ToothCheck",
    "Check3D",
    "imperfect_track",
]

#: Agreement tolerance of an exact comparison, mm. FCL's mesh distance is
#: double precision (~6e-9 mm at 80 mm radius, library notes); 1e-6 mm leaves
#: room for the polygon transforms done twice (numpy here, shapely in 2D).
FCL_TOL = 1e-6


@dataclass(slots=True)
class PairCheck:
    """One rigid tooth against the flexspline tooth: FCL's distance and the 2D engine's over the sections (mm).

    ``bound``: how far below the 2D figure the true surfaces can dip between the sections (None when the 2D figure
    is an overlap); ``witness_z`` and ``clearance_2d_at_witness``: the section through FCL's nearest point and the
    2D clearance there (coned and apart only)."""

    rigid_tooth: int
    fcl_distance: float
    fcl_overlap: bool
    clearance_2d: float
    bound: float | None
    agree: bool
    witness_z: float | None = None
    clearance_2d_at_witness: float | None = None


@dataclass(slots=True)
class ToothCheck:
    """The 3D check of one flexspline tooth (:func:`check_tooth`), mm and rad; times in seconds.

    ``fcl_distance`` / ``fcl_overlap``: the nearest rigid tooth's; ``clearance_2d``: the engine's minimum over the
    sections; ``sections_z``: None without coning; ``bound``: 0 without coning, None for an overlap;
    ``per_tooth``: a :class:`PairCheck` per rigid tooth; ``witness_z``, ``clearance_2d_at_witness``: the nearest
    pair's (coned, apart); ``what``, ``generator_angle``, ``tooth``: set by :func:`verify_worst`."""

    tooth_angle: float
    rigid_teeth: list
    fcl_distance: float
    fcl_overlap: bool
    clearance_2d: float
    sections_z: list | None
    bound: float | None
    loft_error: float
    agree: bool
    per_tooth: list
    timing: dict
    witness_z: float | None = None
    clearance_2d_at_witness: float | None = None
    what: str | None = None
    generator_angle: float | None = None
    tooth: int | None = None


@dataclass(slots=True)
class Check3D:
    """The 3D check of the pairs the 2D audit singles out (:func:`verify_worst`): a :class:`ToothCheck` per pair,
    the loft's sections (``n_sections``: 2 for the prisms of a drive without coning), whether all agree."""

    pairs: list
    n_sections: int
    coned: bool
    agree: bool = field(init=False)

    def __post_init__(self):
        self.agree = all(p.agree for p in self.pairs)


def _clean_ccw(local: np.ndarray) -> np.ndarray:
    """The outline without repeated consecutive points (they make degenerate faces), counter-clockwise."""
    p = np.asarray(local, dtype=float)
    keep = np.hypot(*(p - np.roll(p, 1, axis=0)).T) > 1e-12
    p = p[keep]
    x, y = p[:, 0], p[:, 1]
    if np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y) < 0:
        p = p[::-1]
    return np.ascontiguousarray(p)


def loft(local: np.ndarray, rot, shift, z) -> tuple[np.ndarray, np.ndarray]:
    """Closed triangle mesh through rigid copies of one polygon placed at increasing heights.

    Section ``k`` is ``R(rot[k]) @ local + shift[k]`` at height ``z[k]``.
    Side faces join corresponding vertices of consecutive sections (two
    triangles per quad); both end caps are the polygon's triangulation
    (manifold3d, ear clipping for non-convex outlines), which a rigid motion
    carries over unchanged. Faces are wound outward.

    Parameters
    ----------
    local : (N, 2) float
        Outline, closed implicitly (either orientation; repeated points dropped).
    rot : (K,) float
        Rotations, rad.
    shift : (K, 2) float
        Translations, mm.
    z : (K,) float
        Heights, strictly increasing, K >= 2.

    Returns
    -------
    vertices : (K N, 3) float64
        Section ``k`` holds rows ``k N .. k N + N - 1``.
    faces : (F, 3) int64
        ``F = 2 N (K - 1) + 2 (N - 2)``.
    """
    p = _clean_ccw(local)
    z = np.asarray(z, dtype=float)
    K, N = len(z), len(p)
    if K < 2 or np.any(np.diff(z) <= 0):
        raise ValueError("loft needs at least two sections at strictly increasing heights")
    xy = transform(p, rot, shift)  # (K, N, 2)
    if xy.shape[0] != K:
        raise ValueError(f"{xy.shape[0]} poses for {K} heights")
    V = np.concatenate([xy, np.broadcast_to(z[:, None, None], (K, N, 1))], axis=-1).reshape(-1, 3)
    k = np.arange(K - 1)[:, None] * N
    i = np.arange(N)[None, :]
    a0, b0 = k + i, k + (i + 1) % N
    a1, b1 = a0 + N, b0 + N
    # for a counter-clockwise outline (a0 -> b0 along it) the outward normal of
    # (a0, b0, b1) is (d x e_z) with d the edge direction: to the right, outside
    sides = np.concatenate([np.stack([a0, b0, b1], -1).reshape(-1, 3), np.stack([a0, b1, a1], -1).reshape(-1, 3)])
    cap = np.asarray(manifold3d.triangulate([p]), dtype=np.int64)
    if len(cap) != N - 2:
        raise ValueError(f"cap triangulation has {len(cap)} triangles for {N} vertices: the outline is not simple")
    bottom = cap[:, ::-1]  # seen from below: normal -z
    top = cap + (K - 1) * N
    return V, np.ascontiguousarray(np.concatenate([sides, bottom, top]), dtype=np.int64)


def _heights(scene: Scene, n_sections: int, sections=None) -> np.ndarray:
    bw = float(scene.drive.design.drive.face_width)
    if sections is not None:
        zs = np.unique(np.round(np.asarray(sections, dtype=float), 12))
        if zs.size < 2:
            raise ValueError("a loft needs at least two distinct sections")
        return zs
    if n_sections < 2:
        raise ValueError(f"n_sections must be >= 2, got {n_sections}")
    return np.linspace(0.0, bw, n_sections)


def _flex_poses(scene: Scene, phi: float, zs: np.ndarray, track=None):
    """Poses ``(rot (K,), shift (K, 2))`` of the tooth at ``phi`` in sections ``zs`` (``z=None`` for every one without coning).

    ``track(z)``, if given, places the tooth instead (``z`` a float, or None
    without coning; returns ``rot (1,)``, ``shift (1, 2)`` in the scene's
    frame): a tooth of an imperfect drive, whose pose is not a function of
    its tooth angle (:func:`imperfect_track`).
    """
    if track is not None:
        poses = [track(None)] * len(zs) if not scene.drive.coned else [track(float(z)) for z in zs]
        return np.array([r[0] for r, _ in poses]), np.array([s_[0] for _, s_ in poses])
    if not scene.drive.coned:
        rot, shift = scene.pose(np.array([phi]), None)
        return np.repeat(rot, len(zs)), np.repeat(shift, len(zs), axis=0)
    poses = [scene.pose(np.array([phi]), float(z)) for z in zs]
    return np.array([r[0] for r, _ in poses]), np.array([s[0] for _, s in poses])


def flex_tooth_solid(
    scene: Scene, phi: float, n_sections: int = 9, sections=None, track=None
) -> tuple[np.ndarray, np.ndarray]:
    """The flexspline tooth at tooth angle ``phi`` as a closed mesh lofted through its deformed cross-sections.

    Parameters
    ----------
    scene : Scene
    phi : float
        Tooth angle from the generator's major axis, rad (rigid-gear frame as
        in :meth:`Scene.pose`).
    n_sections : int
        Sections at ``linspace(0, face_width, n_sections)``, each placed with
        ``scene.pose(phi, z)``. Without coning every section is the same
        polygon and the loft is the prism between the two end sections.
    sections : array_like, optional
        Explicit axial positions (mm from the open end) instead of the
        linspace; sorted, duplicates dropped.
    track : callable, optional
        Places the tooth instead of ``scene.pose`` (see :func:`_flex_poses`).

    Returns
    -------
    vertices : (V, 3) float64
        mm, rigid-gear frame, z along the axis.
    faces : (F, 3) int64
    """
    zs = _heights(scene, n_sections, sections)
    if not scene.drive.coned:
        zs = zs[[0, -1]]
    rot, shift = _flex_poses(scene, float(phi), zs, track)
    return loft(scene.flex_local, rot, shift, zs)


def rigid_tooth_solid(scene: Scene, j: int) -> tuple[np.ndarray, np.ndarray]:
    """Rigid tooth ``j`` extruded over the face width: ``(vertices (V, 3), faces (F, 3))``, rigid-gear frame."""
    bw = float(scene.drive.design.drive.face_width)
    j = int(j) % scene.z_b
    rot = np.full(2, scene.rigid_rot[j])
    shift = np.repeat(scene.rigid_shift[j][None, :], 2, axis=0)
    return loft(scene.rigid.local, rot, shift, np.array([0.0, bw]))


def loft_error(scene: Scene, phi: float, zs: np.ndarray, track=None) -> dict:
    """How far the loft through sections ``zs`` can be from the true coned tooth, and how fast the tooth moves along z.

    Between two sections the loft moves each vertex along the chord while
    the true tooth moves it along a curve ``P(z)``. For a curve with a
    (nearly) constant second derivative the largest distance from the chord
    is at the middle of the interval and equals ``|P''| h^2 / 8``: it is
    measured there (the true placement at the middle section against the
    mean of the end vertices) and doubled as a margin for the variation of
    ``P''`` (coning is linear in z, so ``P''`` comes only from the rotation
    and varies by O(h) of itself). A side quad whose two edges move by
    different amounts is not planar; its two triangles deviate from the
    straight slice by at most ``|dP_b - dP_a| / 4`` (at mid-height). The
    loft's slice at any z is within ``chord + twist`` of the true section
    (Hausdorff distance), and equal to it at the sections.

    Returns
    -------
    dict of (K-1,) arrays, one value per interval: ``h`` spacing mm,
    ``chord`` and ``twist`` mm, ``speed`` the largest vertex speed
    ``|dP/dz|`` over the interval (secant speed plus ``4 chord / h``, the
    most the tangent can differ from the secant when ``|P''| = 8 chord / h^2``).
    """
    zs = np.asarray(zs, dtype=float)
    local = _clean_ccw(scene.flex_local)
    rot, shift = _flex_poses(scene, float(phi), zs, track)
    P = transform(local, rot, shift)  # (K, N, 2)
    zm = 0.5 * (zs[:-1] + zs[1:])
    rm, sm = _flex_poses(scene, float(phi), zm, track)
    Q = transform(local, rm, sm)
    h = np.diff(zs)
    chord = 2.0 * np.hypot(*(Q - 0.5 * (P[:-1] + P[1:])).transpose(2, 0, 1)).max(axis=1)
    dP = P[1:] - P[:-1]  # (K-1, N, 2)
    twist = 0.25 * np.hypot(*(np.roll(dP, -1, axis=1) - dP).transpose(2, 0, 1)).max(axis=1)
    speed = np.hypot(*dP.transpose(2, 0, 1)).max(axis=1) / h + 4.0 * chord / h
    return {"h": h, "chord": chord, "twist": twist, "speed": speed}


def _collision_object(mesh) -> fcl.CollisionObject:
    V = np.ascontiguousarray(mesh[0], dtype=np.float64)
    F = np.ascontiguousarray(mesh[1], dtype=np.int32)
    m = fcl.BVHModel()
    m.beginModel(len(V), len(F))
    m.addSubModel(V, F)
    m.endModel()
    return fcl.CollisionObject(m, fcl.Transform())


def fcl_distance(mesh_a, mesh_b, nearest: bool = False):
    """Exact distance between two closed triangle meshes (python-fcl BVHModel).

    FCL gives meshes no penetration depth: overlapping meshes report 0. A
    zero distance is therefore confirmed with ``fcl.collide``: ``overlapping``
    is True when the meshes intersect, False when they only touch (or are
    apart). A mesh wholly inside the other reports a positive distance (not
    the case for neighbouring teeth). A new request and result are made per
    query (a reused ``DistanceResult`` keeps the smallest value seen).

    Parameters
    ----------
    mesh_a, mesh_b : tuple of (V, 3) float and (F, 3) int
    nearest : bool
        Also return the nearest points ``((3,), (3,))`` (meaningless when overlapping).

    Returns
    -------
    distance : float
        mm, >= 0.
    overlapping : bool
    points : tuple of two (3,) arrays (with ``nearest=True``)
    """
    oa, ob = _collision_object(mesh_a), _collision_object(mesh_b)
    res = fcl.DistanceResult()
    d = float(fcl.distance(oa, ob, fcl.DistanceRequest(enable_nearest_points=nearest), res))
    overlapping = False
    if d <= 0.0:
        cres = fcl.CollisionResult()
        overlapping = bool(fcl.collide(oa, ob, fcl.CollisionRequest(), cres) > 0 or cres.is_collision)
        d = 0.0
    if nearest:
        return (
            d,
            overlapping,
            (np.array(res.nearest_points[0], dtype=float), np.array(res.nearest_points[1], dtype=float)),
        )
    return d, overlapping


def _agrees(c2d: float, fcl_d: float, overlap: bool, lower: float, exact: bool) -> bool:
    """The agreement rule (see :func:`check_tooth`)."""
    if c2d < 0.0:
        return overlap
    if overlap:
        # FCL finds the loft overlapping: only right if the true clearance may dip to 0 between sections
        return (not exact) and lower <= FCL_TOL
    if exact:
        return abs(fcl_d - c2d) <= FCL_TOL
    return lower - FCL_TOL <= fcl_d <= c2d + FCL_TOL


def check_tooth(scene: Scene, phi: float, n_sections: int = 9, sections=None, track=None) -> ToothCheck:
    """FCL distance of the flexspline tooth at ``phi`` to the rigid teeth it can touch, against the 2D engine over the same sections.

    Rigid teeth: :meth:`Scene.neighbours` (lower, upper, third) at every
    section, middle section first. 2D figure: ``tooth_clearance(...).min``
    minimised over the sections, and per rigid tooth
    :meth:`Scene.clearance_to` minimised over the sections.

    Agreement rule, per rigid tooth and for the pair:

    * 2D < 0 (penetration in a section): FCL must report overlap (the loft
      contains that section).
    * no coning (the solids are prisms over the same face width, so the 3D
      distance is the 2D one): ``|FCL - 2D| <= FCL_TOL``.
    * coning, 2D > 0: ``lower - FCL_TOL <= FCL <= 2D + FCL_TOL``. The loft
      contains the sections, so FCL cannot exceed their 2D minimum. Below,
      two effects: the true clearance ``c(z)`` may dip between sections
      (``c`` is Lipschitz in z with the vertex speed ``V``, so on an
      interval of length h it stays above ``(c_k + c_{k+1} - V h) / 2``),
      and the loft's slices are within ``chord + twist`` of the true
      sections (:func:`loft_error`). ``lower`` is the smallest interval
      bound minus that geometric error; ``bound = 2D - lower``. The terms
      shrink with the section spacing: the dip and the twist as ``h``, the
      chord as ``h^2``.
    * coning, apart: the tight check. FCL's nearest point on the flexspline
      tooth lies at some ``z_w``. The rigid tooth is a prism, so FCL equals
      the 2D distance of the loft's slice at ``z_w`` (no less: drop the z
      component; no more: the rigid point straight across is as near), and
      that slice is within the loft error of the true section: the 2D
      clearance at ``z_w`` must satisfy ``|FCL - c(z_w)| <= loft_error +
      FCL_TOL``.

    Returns
    -------
    ToothCheck

    With ``track`` (a tooth of an imperfect drive, :func:`imperfect_track`)
    the tooth is placed by it in every section, and ``scene`` is the
    :class:`~wgcad.clearance.imperfect.ImperfectScene` that holds the rigid
    teeth with their errors; ``phi`` only labels the result.
    """
    t0 = time.perf_counter()
    coned = scene.drive.coned
    zs = _heights(scene, n_sections, sections)
    rot, shift = _flex_poses(scene, float(phi), zs if coned else zs[:1], track)
    teeth = _touchable_teeth(scene, rot, shift)
    c, c_engine = _section_clearances(scene, rot, shift, teeth)
    t_2d = time.perf_counter() - t0
    geom, lower_t = _lower_bounds(scene, float(phi), zs, track, c) if coned else (0.0, c.min(axis=0))
    t1 = time.perf_counter()
    flex = flex_tooth_solid(scene, float(phi), sections=zs, track=track)
    per, query_ms = [], []
    for ti, j in enumerate(teeth):
        tq = time.perf_counter()
        d, ov, pts = fcl_distance(flex, rigid_tooth_solid(scene, j), nearest=True)
        query_ms.append(1e3 * (time.perf_counter() - tq))
        per.append((d, _pair_row(scene, phi, zs, track, j, c[:, ti], (float(lower_t[ti]), geom), (d, ov, pts))))
    t_fcl = time.perf_counter() - t1
    d_min, best = min(per, key=lambda t: t[0])
    ov_any = any(r.fcl_overlap for _, r in per)
    c2d = float(c_engine.min())
    c_pairs = float(c.min())
    lower = float(lower_t.min())
    out = ToothCheck(
        tooth_angle=float(phi),
        rigid_teeth=teeth,
        fcl_distance=d_min,
        fcl_overlap=ov_any,
        clearance_2d=c2d,
        sections_z=[float(z) for z in zs] if coned else None,
        bound=(max(c2d - lower, 0.0) if coned else 0.0) if c2d >= 0 else None,
        loft_error=geom,
        agree=bool(
            _agrees(c2d, d_min, ov_any, lower, not coned)
            and all(r.agree for _, r in per)
            and abs(c2d - c_pairs) <= FCL_TOL
        ),
        per_tooth=[r for _, r in per],
        timing={"2d": t_2d, "fcl_total": t_fcl, "fcl_per_query": [1e-3 * q for q in query_ms]},
    )
    if best.witness_z is not None and not ov_any:
        out.witness_z, out.clearance_2d_at_witness = best.witness_z, best.clearance_2d_at_witness
    return out


def _touchable_teeth(scene: Scene, rot, shift) -> list[int]:
    """The rigid teeth the tooth posed ``(rot, shift)`` per section can touch: the neighbours at the middle
    section, then any other section's."""
    n = len(rot)
    teeth = []
    for k in [n // 2] + [k for k in range(n) if k != n // 2]:
        for idx in scene.neighbours(shift[k : k + 1], rot[k : k + 1]):
            if int(idx[0]) not in teeth:
                teeth.append(int(idx[0]))
    return teeth


def _section_clearances(scene: Scene, rot, shift, teeth) -> tuple[np.ndarray, np.ndarray]:
    """2D clearance (mm) per section and rigid tooth ``(K, T)``, and the engine's own figure per section (its
    neighbour search and third-tooth bound)."""
    n = len(rot)
    c = np.array(
        [
            [float(scene.clearance_to(rot[k : k + 1], shift[k : k + 1], np.array([j]))[0]) for j in teeth]
            for k in range(n)
        ]
    )
    c_engine = np.array([float(clearance_at_poses(scene, rot[k : k + 1], shift[k : k + 1]).min[0]) for k in range(n)])
    return c, c_engine


def _lower_bounds(scene: Scene, phi: float, zs, track, c) -> tuple[float, np.ndarray]:
    """A coned drive's loft error (chord + twist, mm) and per rigid tooth the lowest clearance the true surfaces
    can have between the sections (the Lipschitz dip, less the loft error)."""
    err = loft_error(scene, phi, zs, track)
    geom = float(np.max(err["chord"] + err["twist"]))
    vh = err["speed"] * err["h"]
    lo_int = np.minimum(np.minimum(c[:-1], c[1:]), 0.5 * (c[:-1] + c[1:] - vh[:, None]))  # (K-1, T)
    return geom, lo_int.min(axis=0) - geom


def _pair_row(scene: Scene, phi, zs, track, j: int, c_j, bounds, fcl) -> PairCheck:
    """One rigid tooth's row: FCL's ``(distance, overlap, nearest points)`` against the 2D clearances ``c_j`` of its
    sections, with ``bounds`` = (lowest clearance between the sections, loft error); and their agreement."""
    lower, geom = bounds
    d, ov, pts = fcl
    coned = scene.drive.coned
    c2 = float(c_j.min())
    ok = _agrees(c2, d, ov, lower, not coned)
    row = PairCheck(j, d, ov, c2, max(c2 - lower, 0.0) if c2 >= 0 else None, False)
    if coned and not ov:
        # the section through FCL's nearest point on the flexspline tooth: the loft's slice there is within `geom`
        # of the true section, so the 2D clearance of that section must match FCL to `geom`
        zw = float(np.clip(pts[0][2], zs[0], zs[-1]))
        r, s = track(zw) if track is not None else scene.pose(np.array([phi]), zw)
        cw = float(scene.clearance_to(r, s, np.array([j]))[0])
        row.witness_z, row.clearance_2d_at_witness = zw, cw
        ok = ok and abs(d - cw) <= geom + FCL_TOL
    row.agree = bool(ok)
    return row


def imperfect_track(drive, imp, phi_h: float, tooth: int):
    """The pose of flexspline tooth ``tooth`` of an imperfect drive at generator angle ``phi_h``, section by section.

    Returns ``track(z) -> (rot (1,), shift (1, 2))``, relative to the rigid
    gear's own centre as :class:`~wgcad.clearance.imperfect.ImperfectScene`
    holds the rigid teeth (:func:`wgcad.placement.imperfect.flex_poses`).
    """
    centre = rigid_translation(imp)

    def track(z):
        rot, shift = flex_poses(drive, imp, float(phi_h), teeth=np.array([int(tooth)]), z=z)
        return rot, shift - centre

    return track


def verify_worst(drive, result, n_sections: int = 9, imp=None) -> Check3D:
    """3D check (FCL) of the pairs the 2D audit singles out: the tightest tooth and the entry pinch.

    Parameters
    ----------
    drive : wgcad.drive.Drive
    result : wgcad.clearance.engine.AuditResult
        Its ``worst["tooth_angle_deg"]`` and, if present,
        ``entry["pinch_tooth_angle_deg"]`` name the tooth angles.
    n_sections : int
        Loft sections over the face width (coning); the audit's own
        sections are added, so the 2D figure covers the section the audit
        found the minimum in.
    imp : wgcad.placement.imperfect.Imperfections, optional
        The errors of an imperfect drive's audit
        (:func:`wgcad.clearance.imperfect.audit_imperfect`): each pair is
        then the tooth and generator angle the audit names, every part
        placed with its errors (the perfect drive's tooth angle does not
        say where an imperfect tooth is).

    Returns
    -------
    Check3D
        A :class:`ToothCheck` per pair, its ``what`` ``"tightest"`` or ``"entry pinch"``
        (:func:`wgcad.report.check3d.check3d_document` words it).
    """
    scene = Scene(drive)
    if imp is not None:
        scene = ImperfectScene.from_scene(scene, imp)
    bw = float(drive.design.drive.face_width)
    zs = np.linspace(0.0, bw, max(int(n_sections), 2))
    if drive.coned:
        extra = [z for z in result.settings.sections if z is not None]
        zs = np.unique(np.round(np.concatenate([zs, np.asarray(extra, dtype=float)]), 12))
    n = int(len(zs)) if drive.coned else 2
    if imp is not None:
        pairs = []
        for what, f in _imperfect_targets(result):
            track = imperfect_track(drive, imp, f.generator_angle, f.tooth)
            chk = check_tooth(scene, float(f.tooth_angle or 0.0), sections=zs, track=track)
            chk.what, chk.generator_angle, chk.tooth = what, float(f.generator_angle), int(f.tooth)
            pairs.append(chk)
        return Check3D(pairs, n, drive.coned)
    # the records' unrounded tooth angles (rad)
    f = result.findings
    targets = [("tightest", f["min_clearance"].tooth_angle)]
    if np.isfinite(f["entry_pinch"].value) and f["entry_pinch"].tooth_angle is not None:
        targets.append(("entry pinch", f["entry_pinch"].tooth_angle))
    pairs = []
    for what, phi in targets:
        chk = check_tooth(scene, float(phi), sections=zs)
        chk.what = what
        pairs.append(chk)
    return Check3D(pairs, n, drive.coned)


def _imperfect_targets(result):
    """The findings of an imperfect audit that name a sample (tooth and generator angle), with what they are."""
    out = [("tightest", result.findings["min_clearance"])]
    pin = result.findings.get("entry_pinch")
    if pin is not None and pin.tooth is not None and pin.generator_angle is not None and np.isfinite(pin.value):
        out.append(("entry pinch", pin))
    return out
