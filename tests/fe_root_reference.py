"""An independent plane-strain FE reference (scikit-fem, isoparametric P2) for the tooth-root stress concentration of a bent flexspline rim.

Model
-----
A sector of ``pitches`` (odd, >= 5) pitches of the flexspline ``drive.flex``,
tooth frame (middle tooth on +x), bounded by

* the toothed boundary: the exact curve pieces ``g.pieces`` of one pitch
  (the analytic curves whose chord sampling is ``g.period``; every vertex of
  ``g.period`` lies on them), repeated turned by ``k 2 pi / z``; with
  ``exact=False`` the polyline ``g.period`` itself (see the evidence below);
* the bore arc, radius ``drive.flex_rim_radius``;
* two radial end faces at ``+-pitches pi / z``: middle of a space, plain rim.

Linear elasticity, plane strain, E = 206000 MPa, nu = 0.3. Pure bending that
changes the rim's curvature by ``dkappa``: the face at ``-Phi/2`` has
``u_n = 0`` (and its bore node ``u_r = 0``); the face at ``+Phi/2`` has
``u_n = dalpha (rho - r_m) + a`` with ``dalpha = dkappa r_m Phi`` and ``a``
one free unknown shared by the face's nodes (its conjugate force, the net
normal force on the face, is therefore zero); radial
displacements on both faces are free. The sign is chosen so that the toothed
side is in tension (curvature increase for outside teeth, decrease for
inside teeth).

``kt = max sigma_tt / sigma_nom`` over the middle pitch's toothed boundary,
``sigma_tt = t . sigma . t`` (``t`` the boundary tangent, which on a traction
free surface is the largest principal in-plane stress), evaluated from the
adjacent element's P2 displacement gradient at 5 Gauss points per boundary
facet; ``sigma_nom = E / (1 - nu^2) (h1 / 2) |dkappa|``, ``h1 = |r_f - r_bore|``.

Mesh (our own, no mesher library)
---------------------------------
Size field ``h(x) = min(h_far, h_fine + G d_hot(x), h_warm + G d_warm(x))``:
``d_hot`` is the distance to the middle pitch's root region (the boundary
within half a tooth height of the root circle), ``d_warm`` to the other
pitches' root regions; ``h_fine = min(rho_c, h1) / 10 / refine`` with
``rho_c`` the smallest radius of curvature of the middle root region
(0.2 mm fillet for the involute templates), ``h_far = h1 / 5 / refine``,
``h_warm = 3 h_fine``, ``G = 0.3``. The boundary is sampled by arclength with
that spacing (vertices and, half a step on, the P2 mid-nodes, both exactly
on the analytic curves; corners of the outline are kept as vertices). The
interior is filled by Delaunay refinement (scipy.spatial.Delaunay, recomputed
each pass): circumcentres of triangles that are too large for ``h`` or have
an angle under ~27 degrees are inserted unless they fall outside, encroach a
boundary chord's diametral circle or come too close to an existing point.
Triangles whose centroid is outside the polygon are dropped; the code
asserts that every boundary chord is a mesh edge and that the area equals
the polygon's. The curved boundary facets get their exact mid-nodes
(skfem ``MeshTri2``: an isoparametric P2 mesh).

Tolerance evidence (measured, 2-core machine; kt at refine 0.5 / 1 / 2 / 3)
-----------------------------------------------------------------------------
* Plain curved bar (toothed boundary replaced by the root circle, r_m/h1 =
  58, d1_involute): kt = 0.99434 at refine 1, against 0.99427 from the exact
  plane-strain curved-bar solution (:func:`curved_bar_kt`, Michell/Golovin):
  the end-face conditions give pure bending; the Winkler curvature effect
  itself is -0.57 %. (Inside teeth, d3_external: 1.00282 at refine 1,
  1.00221 at refine 4, exact 1.00221.)
* Refinement: d1_involute 2.4034 / 2.3857 / 2.3827 / 2.3806 (13 114 DOFs at
  refine 1, 29 248 at 2); d1_cycloidal 1.9223 / 1.9192 / 1.9185 / 1.9180
  (8 452 DOFs at 1); d2 2.4152 / 2.4017 / 2.3938 / 2.3913 (13 406 at 1).
  Refine 1 -> 2 changes kt by < 0.35 %; about 0.4 s per solve at refine 1.
* Sector length: pitches 5 -> 9 changes kt by < 0.2 %.
* Left and right root of the middle pitch agree to < 0.2 %.
* ``exact=False`` (the polyline ``g.period``, chord tolerance 1e-3 mm: five
  chords turning 11.1 deg each over the 0.2 mm involute fillet, 5.6 deg on
  the cycloidal space bottom) does not converge: each vertex is a re-entrant
  corner, a weak singularity. d1_involute 2.40 / 2.53 / 2.72 (refine 0.5 / 1
  / 2), d1_cycloidal 2.04 / 2.06 / 2.12, d2 2.41 / 2.54 / 2.74. That is why
  the reference meshes the analytic curves that ``g.period`` samples.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import shapely
from scipy.sparse.linalg import spsolve
from scipy.spatial import Delaunay, cKDTree
from skfem import Basis, BilinearForm, ElementTriP2, ElementVector, MeshTri1, MeshTri2, asm

E_MOD = 206000.0  # MPa
NU = 0.3
DKAPPA = 1.0e-4  # 1/mm; the result is linear, any value will do

__all__ = ["reference_root_kt", "curved_bar_kt", "E_MOD", "NU"]


# -- geometry -------------------------------------------------------------------------------


def _rot(p, a):
    c, s = np.cos(a), np.sin(a)
    return np.stack([c * p[..., 0] - s * p[..., 1], s * p[..., 0] + c * p[..., 1]], axis=-1)


def _dense_pieces(pieces, step):
    """Dense exact samples of consecutive pieces; returns (points, corner indices)."""
    chunks, corners, prev_dir = [], [], None
    n_total = 0
    for p in pieces:
        n = max(8, int(np.ceil(p.length() / step)))
        t = np.linspace(p.t0, p.t1, n + 1)
        pts = p.point(t)
        sgn = np.sign(p.t1 - p.t0)
        d0, d1 = p.deriv(np.array([p.t0]))[0] * sgn, p.deriv(np.array([p.t1]))[0] * sgn
        if prev_dir is not None:
            c = (prev_dir[0] * d0[1] - prev_dir[1] * d0[0]) / (np.linalg.norm(prev_dir) * np.linalg.norm(d0))
            dot = np.dot(prev_dir, d0)
            if dot <= 0 or abs(c) > np.sin(np.radians(2.0)):
                corners.append(n_total - 1)
            pts = pts[1:]
        chunks.append(pts)
        n_total += len(pts)
        prev_dir = d1
    return np.concatenate(chunks), corners


def _dense_polyline(poly, step):
    """Dense samples of a polyline, every vertex a corner."""
    chunks, corners, n_total = [poly[:1]], [], 1
    for a, b in zip(poly[:-1], poly[1:]):
        n = max(1, int(np.ceil(np.hypot(*(b - a)) / step)))
        u = np.linspace(0, 1, n + 1)[1:, None]
        chunks.append(a + u * (b - a))
        n_total += n
        corners.append(n_total - 1)
    return np.concatenate(chunks), corners[:-1]


def _resample(dense, corners, size):
    """Vertices and mid-nodes along a dense polyline, spacing ``size(x)``, corners kept.

    Returns vertices (n+1, 2) including both ends and mids (n, 2).
    """
    cuts = [0, *sorted(set(corners)), len(dense) - 1]
    verts, mids = [dense[:1]], []
    for i0, i1 in zip(cuts[:-1], cuts[1:]):
        if i1 <= i0:
            continue
        run = dense[i0 : i1 + 1]
        ds = np.hypot(*np.diff(run, axis=0).T)
        s = np.concatenate([[0.0], np.cumsum(ds)])
        h = size(0.5 * (run[1:] + run[:-1]))
        dens = np.concatenate([[0.0], np.cumsum(ds / h)])
        n = max(1, int(round(dens[-1])))
        targets = np.linspace(0.0, dens[-1], 2 * n + 1)
        st = np.interp(targets, dens, s)
        pts = np.stack([np.interp(st, s, run[:, 0]), np.interp(st, s, run[:, 1])], axis=1)
        pts[-1] = run[-1]
        verts.append(pts[2::2])
        mids.append(pts[1::2])
    return np.concatenate(verts), np.concatenate(mids)


def _size_field(h_far, h_fine, h_warm, grad, hot, warm):
    t_hot, t_warm = cKDTree(hot), (cKDTree(warm) if len(warm) else None)

    def size(x):
        x = np.atleast_2d(x)
        h = np.minimum(h_far, h_fine + grad * t_hot.query(x)[0])
        if t_warm is not None:
            h = np.minimum(h, h_warm + grad * t_warm.query(x)[0])
        return h

    return size


# -- meshing --------------------------------------------------------------------------------


def _circum(P, tri):
    a, b, c = P[tri[:, 0]], P[tri[:, 1]], P[tri[:, 2]]
    ba, ca = b - a, c - a
    d = 2.0 * (ba[:, 0] * ca[:, 1] - ba[:, 1] * ca[:, 0])
    bb, cc = (ba**2).sum(1), (ca**2).sum(1)
    ux = (ca[:, 1] * bb - ba[:, 1] * cc) / d
    uy = (ba[:, 0] * cc - ca[:, 0] * bb) / d
    R = np.hypot(ux, uy)
    lmin = np.min(np.stack([np.hypot(*ba.T), np.hypot(*ca.T), np.hypot(*(c - b).T)]), axis=0)
    return a + np.stack([ux, uy], axis=1), R, lmin


def _triangulate(V, size, h_far, ring, max_pass=60):
    """Delaunay refinement inside the closed polygon V (boundary vertices fixed)."""
    poly = shapely.Polygon(V)
    chord_mid = 0.5 * (V + np.roll(V, -1, axis=0))
    chord_half = 0.5 * np.hypot(*(np.roll(V, -1, axis=0) - V).T)
    t_chord = cKDTree(chord_mid)
    r_max = chord_half.max()

    def admissible(X):
        ok = shapely.contains_xy(poly, X[:, 0], X[:, 1])
        hx = size(X)
        # keep clear of the boundary vertices and of every chord's diametral circle
        ok &= cKDTree(V).query(X)[0] > 0.45 * hx
        for i, near in enumerate(t_chord.query_ball_point(X, r_max * 1.05)):
            if ok[i] and near:
                near = np.asarray(near)
                if np.any(np.hypot(*(chord_mid[near] - X[i]).T) < 1.05 * chord_half[near]):
                    ok[i] = False
        return ok

    # seed: a polar lattice at the far spacing
    r0, r1, th0, th1 = ring
    rr = np.arange(r0 + 0.5 * h_far, r1, h_far)
    seeds = []
    for k, r in enumerate(rr):
        th = np.arange(th0, th1, h_far / r) + (0.5 * (k % 2)) * h_far / r
        seeds.append(np.stack([r * np.cos(th), r * np.sin(th)], axis=1))
    S = np.concatenate(seeds)
    P = np.concatenate([V, S[admissible(S)]])
    for _ in range(max_pass):
        tri = Delaunay(P).simplices
        cen = P[tri].mean(axis=1)
        tri = tri[shapely.contains_xy(poly, cen[:, 0], cen[:, 1])]
        tri = tri[~_flat(P, tri)]
        cc, R, lmin = _circum(P, tri)
        h = size(P[tri].mean(axis=1))
        bad = (R * np.sqrt(3.0) > 1.3 * h) | (R / lmin > 1.1)
        if not bad.any():
            break
        order = np.argsort(-(R / h)[bad])
        cand = cc[bad][order]
        cand = cand[admissible(cand)]
        if not len(cand):
            break
        hc = size(cand)
        dist_old = cKDTree(P).query(cand)[0]
        keep = np.zeros(len(cand), bool)
        acc = []
        for i in range(len(cand)):
            if dist_old[i] < 0.5 * hc[i]:
                continue
            if acc:
                q = np.asarray(acc)
                if np.min(np.hypot(*(cand[q] - cand[i]).T)) < 0.5 * hc[i]:
                    continue
            acc.append(i)
            keep[i] = True
        if not keep.any():
            break
        P = np.concatenate([P, cand[keep]])
    tri = Delaunay(P).simplices
    cen = P[tri].mean(axis=1)
    tri = tri[shapely.contains_xy(poly, cen[:, 0], cen[:, 1])]
    # orientation: counter-clockwise
    tri = tri[~_flat(P, tri)]
    a, b, c = P[tri[:, 0]], P[tri[:, 1]], P[tri[:, 2]]
    area2 = (b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]
    tri[area2 < 0] = tri[area2 < 0][:, [0, 2, 1]]
    # checks: conforming boundary, area of the polygon
    edges = {tuple(sorted(e)) for t in tri for e in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))}
    n = len(V)
    missing = [i for i in range(n) if tuple(sorted((i, (i + 1) % n))) not in edges]
    assert not missing, f"boundary chords missing from the mesh: {missing[:10]}"
    assert abs(0.5 * np.abs(area2).sum() - poly.area) < 1e-9 * poly.area
    return P, tri, _min_angle(P, tri)


def _flat(P, tri):
    """Zero-area triangles (Qhull returns some on collinear boundary vertices)."""
    a, b, c = P[tri[:, 0]], P[tri[:, 1]], P[tri[:, 2]]
    area2 = (b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]
    lmax2 = np.max(np.stack([((b - a) ** 2).sum(1), ((c - b) ** 2).sum(1), ((a - c) ** 2).sum(1)]), axis=0)
    return np.abs(area2) < 1e-9 * lmax2


def _min_angle(P, tri):
    a, b, c = P[tri[:, 0]], P[tri[:, 1]], P[tri[:, 2]]
    la, lb, lc = np.hypot(*(c - b).T), np.hypot(*(a - c).T), np.hypot(*(b - a).T)
    cosA = np.clip((lb**2 + lc**2 - la**2) / (2 * lb * lc), -1, 1)
    cosB = np.clip((la**2 + lc**2 - lb**2) / (2 * la * lc), -1, 1)
    cosC = np.clip((la**2 + lb**2 - lc**2) / (2 * la * lb), -1, 1)
    return float(np.degrees(np.arccos(np.max([cosA, cosB, cosC]))))


# -- the model --------------------------------------------------------------------------------


def _min_curvature_radius(pieces, r_f, depth):
    """Smallest radius of curvature (either sense) of the pieces' points within ``depth`` of the root circle."""
    rmin = np.inf
    for p in pieces:
        t = np.linspace(p.t0, p.t1, 201)
        x = p.point(t)
        near = np.abs(np.hypot(*x.T) - r_f) <= depth
        if not near.any():
            continue
        d1, d2 = p.deriv(t)[near], p.deriv2(t)[near]
        k = np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / np.hypot(*d1.T) ** 3
        k = k[np.isfinite(k)]
        if len(k) and k.max() > 0:
            rmin = min(rmin, 1.0 / k.max())
    return rmin


def _elasticity():
    lam = E_MOD * NU / ((1 + NU) * (1 - 2 * NU))  # plane strain: the 3-D Lame constants
    mu = E_MOD / (2 * (1 + NU))

    @BilinearForm
    def form(u, v, w):
        eu = 0.5 * (u.grad + np.swapaxes(u.grad, 0, 1))
        ev = 0.5 * (v.grad + np.swapaxes(v.grad, 0, 1))
        tr = eu[0, 0] + eu[1, 1]
        return lam * tr * (ev[0, 0] + ev[1, 1]) + 2 * mu * (
            eu[0, 0] * ev[0, 0] + eu[1, 1] * ev[1, 1] + 2 * eu[0, 1] * ev[0, 1]
        )

    return form, lam, mu


def curved_bar_kt(r_in: float, r_out: float, r_m: float, toothed_outside: bool = True) -> float:
    """Exact plane-strain pure-bending ``kt`` of a plain curved bar (Michell/Golovin), with this module's definitions.

    Stress function ``A ln r + B r^2 ln r + C r^2``: the end faces turn by
    ``4 B Phi / E'`` (so ``B = E' r_m dkappa / 4``), and ``sigma_r = 0`` on both
    radii gives ``sigma_theta(b) = 2 B (1 - 2 a^2 ln(b/a) / (b^2 - a^2))``.
    Returns ``sigma_theta`` on the ``toothed`` surface over ``E' (h/2) dkappa``.
    """
    a, b = r_in, r_out
    g = 2 * a * a * b * b * np.log(b / a) / (b * b - a * a)  # A / B
    r = b if toothed_outside else a
    s = 2.0 - 2 * g / r**2  # sigma_theta(r) / B, after eliminating C
    return float(abs(s * r_m / 4.0) / ((b - a) / 2.0))


def reference_root_kt(drive, pitches: int = 5, refine: float = 1.0, *, plain: bool = False, exact: bool = True) -> dict:
    """Tooth-root stress concentration of ``drive.flex`` under pure bending (module docstring).

    Parameters
    ----------
    pitches : odd int >= 5
        Pitches in the sector; the middle one is measured.
    refine : float
        Divides every mesh size (1: the default mesh; 2: about 4x the DOFs).
    plain : bool
        Replace the toothed boundary by the root circle (a plain curved bar
        of thickness h1): a self-check, ``kt`` close to 1.
    exact : bool
        True: the analytic curve pieces of the outline; False: the sampled
        polyline ``g.period``.

    Returns
    -------
    dict
        ``kt``; ``angle`` (rad, polar angle of the peak in the tooth frame,
        0 = middle tooth centre) and ``radius`` (mm) of the peak; ``dofs``
        (displacement DOFs); also ``kt_left``/``kt_right`` (peak on each
        side of the tooth centre), ``sigma_nom`` (MPa), ``dkappa``,
        ``elements``, ``min_angle`` (deg).
    """
    if pitches < 5 or pitches % 2 == 0:
        raise ValueError(f"pitches must be odd and >= 5, got {pitches}")
    g = drive.flex
    z = g.spec.z
    inside = bool(g.spec.internal)  # teeth on the inner side of the rim
    r_f, r_b, r_m = float(g.r_f), float(drive.flex_rim_radius), float(drive.r_m)
    h1 = abs(r_f - r_b)
    tooth_h = abs(g.r_a - r_f)
    half = pitches // 2
    pa = 2 * np.pi / z
    Phi = pitches * pa
    th_a, th_b = -0.5 * Phi, 0.5 * Phi

    # the toothed boundary, increasing polar angle, as dense exact samples
    step = min(h1, tooth_h) / 2000.0
    if plain:
        tt = np.linspace(th_a, th_b, int(np.ceil(r_f * Phi / step)) + 1)
        dense = np.stack([r_f * np.cos(tt), r_f * np.sin(tt)], axis=1)
        corners, rho_c = [], h1
    elif exact and g.pieces:
        pieces = [q.rotated(k * pa) for k in range(-half, half + 1) for q in g.pieces]
        dense, corners = _dense_pieces(pieces, step)
        rho_c = _min_curvature_radius(g.pieces, r_f, 0.5 * tooth_h)
    else:
        per = np.asarray(g.period, float)
        poly = np.concatenate([_rot(per, k * pa)[(1 if k > -half else 0) :] for k in range(-half, half + 1)])
        dense, corners = _dense_polyline(poly, step)
        # the polyline's discrete radius of curvature (mean chord / turning angle) in the root zone
        d = np.diff(per, axis=0)
        turn = np.abs(np.arctan2(d[:-1, 0] * d[1:, 1] - d[:-1, 1] * d[1:, 0], (d[:-1] * d[1:]).sum(1)))
        r_disc = 0.5 * np.hypot(*d[:-1].T) + 0.5 * np.hypot(*d[1:].T)
        near = np.abs(np.hypot(*per[1:-1].T) - r_f) <= 0.5 * tooth_h
        with np.errstate(divide="ignore"):
            rho_c = float(np.clip((r_disc / turn)[near].min(), h1 / 20, h1))

    # size field
    rad = np.hypot(*dense.T)
    ang = np.arctan2(dense[:, 1], dense[:, 0])
    root_zone = np.abs(rad - r_f) <= 0.5 * tooth_h + 1e-12
    mid = np.abs(ang) <= pa / 2 + 1e-12
    h_far = h1 / 5.0 / refine
    h_fine = min(rho_c, h1) / 10.0 / refine
    size = _size_field(h_far, h_fine, 3 * h_fine, 0.3, dense[root_zone & mid], dense[root_zone & ~mid])

    # boundary loop: toothed (th_a -> th_b), face B, bore (th_b -> th_a), face A
    vt, mt = _resample(dense, corners, size)
    p_end_b, p_end_a = dense[-1], dense[0]
    bore_b, bore_a = r_b * np.array([np.cos(th_b), np.sin(th_b)]), r_b * np.array([np.cos(th_a), np.sin(th_a)])
    lin = np.linspace(0, 1, 2001)[:, None]
    vfb, mfb = _resample(p_end_b + lin * (bore_b - p_end_b), [], size)
    tb = np.linspace(th_b, th_a, int(np.ceil(r_b * Phi / step)) + 1)
    vbo, mbo = _resample(np.stack([r_b * np.cos(tb), r_b * np.sin(tb)], axis=1), [], size)
    vfa, mfa = _resample(bore_a + lin * (p_end_a - bore_a), [], size)
    V = np.concatenate([vt[:-1], vfb[:-1], vbo[:-1], vfa[:-1]])
    M = np.concatenate([mt, mfb, mbo, mfa])
    kind = np.concatenate([np.full(len(mt), 0), np.full(len(mfb), 1), np.full(len(mbo), 2), np.full(len(mfa), 3)])
    ring = (min(r_b, r_f - (tooth_h if inside else 0)), max(r_b, g.r_a if not inside else r_f), th_a, th_b)

    P, tri, min_ang = _triangulate(V, size, h_far, ring)

    # isoparametric P2 mesh: exact mid-nodes on the boundary
    m1 = MeshTri1(P.T.copy(), tri.T.copy())
    m2 = MeshTri2.from_mesh(m1)
    nv = m1.p.shape[1]
    fac = np.sort(m1.facets, axis=0)
    fid = {(int(a), int(b)): i for i, (a, b) in enumerate(fac.T)}
    n = len(V)
    bfac = np.array([fid[tuple(sorted((i, (i + 1) % n)))] for i in range(n)])
    doflocs = m2.doflocs.copy()
    assert np.allclose(doflocs[:, nv + bfac].T, 0.5 * (V + np.roll(V, -1, axis=0)))
    doflocs[:, nv + bfac] = M.T
    m2 = MeshTri2(doflocs, m2.t)

    e = ElementVector(ElementTriP2())
    basis = Basis(m2, e, intorder=4)
    form, lam, mu = _elasticity()
    K = asm(form, basis).tocsr()
    ndof = K.shape[0]

    # end-face conditions by a transformation u = T q + u0
    sign = -1.0 if inside else 1.0  # toothed side in tension
    dkappa = sign * DKAPPA
    dalpha = dkappa * r_m * Phi
    dx = np.concatenate([basis.nodal_dofs[0], basis.facet_dofs[0]])
    dy = np.concatenate([basis.nodal_dofs[1], basis.facet_dofs[1]])
    X = basis.doflocs[:, dx].T
    rho = np.hypot(*X.T)
    on_a = np.abs(X[:, 0] * np.sin(th_a) - X[:, 1] * np.cos(th_a)) < 1e-9 * r_f
    on_b = np.abs(X[:, 0] * np.sin(th_b) - X[:, 1] * np.cos(th_b)) < 1e-9 * r_f
    free = ~(on_a | on_b)
    rows, cols, vals = [], [], []
    nq = 0
    fi = np.nonzero(free)[0]
    for d in (dx, dy):
        rows.append(d[fi])
        cols.append(nq + np.arange(len(fi)))
        vals.append(np.ones(len(fi)))
        nq += len(fi)
    u0 = np.zeros(ndof)
    ia = np.nonzero(on_a)[0]
    ia = ia[np.argsort(np.abs(rho[ia] - r_b))][1:]  # the bore node of face A is held radially too
    for idx, th in ((ia, th_a), (np.nonzero(on_b)[0], th_b)):
        er = np.array([np.cos(th), np.sin(th)])
        for d, c in ((dx, er[0]), (dy, er[1])):
            rows.append(d[idx])
            cols.append(nq + np.arange(len(idx)))
            vals.append(np.full(len(idx), c))
        nq += len(idx)
    ib = np.nonzero(on_b)[0]
    et = np.array([-np.sin(th_b), np.cos(th_b)])
    for d, c in ((dx, et[0]), (dy, et[1])):
        rows.append(d[ib])
        cols.append(np.full(len(ib), nq))
        vals.append(np.full(len(ib), c))
        u0[d[ib]] = c * dalpha * (rho[ib] - r_m)
    nq += 1
    T = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(ndof, nq))
    Kr = (T.T @ K @ T).tocsc()
    q = spsolve(Kr, -(T.T @ (K @ u0)))
    u = T @ q + u0

    # boundary stress of the middle pitch's toothed facets
    cm = 0.5 * (V + np.roll(V, -1, axis=0))
    sel = (kind == 0) & (np.abs(np.arctan2(cm[:, 1], cm[:, 0])) <= pa / 2)
    # the adjacent element's gradient at Gauss points of each facet, in its own reference coordinates
    gx, _ = np.polynomial.legendre.leggauss(5)
    sq = 0.5 * (gx + 1.0)
    ref_edges = {
        0: (np.array([0.0, 0.0]), np.array([1.0, 0.0])),  # skfem's triangle facets (0,1), (1,2), (0,2)
        1: (np.array([1.0, 0.0]), np.array([0.0, 1.0])),
        2: (np.array([0.0, 0.0]), np.array([0.0, 1.0])),
    }
    fsel = bfac[sel]
    tind = m2.f2t[0, fsel]
    loc = np.argmax(m2.t2f[:, tind] == fsel[None, :], axis=0)
    s_tt, xq = [], []
    for j, (r0, r1) in ref_edges.items():
        el = tind[loc == j]
        if not len(el):
            continue
        Xr = r0[:, None] + (r1 - r0)[:, None] * sq[None, :]
        bj = Basis(m2, e, quadrature=(Xr, np.full(len(sq), 1.0 / len(sq))), elements=el)
        G = np.array(bj.interpolate(u).grad)  # (2, 2, nel, nqp)
        J = m2._mapping().DF(Xr, tind=el)  # (2, 2, nel, nqp)
        tvec = np.einsum("ijkl,j->ikl", J, r1 - r0)
        tvec = tvec / np.hypot(tvec[0], tvec[1])
        eps = 0.5 * (G + np.swapaxes(G, 0, 1))
        tr = eps[0, 0] + eps[1, 1]
        s_xx, s_yy, s_xy = lam * tr + 2 * mu * eps[0, 0], lam * tr + 2 * mu * eps[1, 1], 2 * mu * eps[0, 1]
        tx, ty = tvec
        s_tt.append((tx * tx * s_xx + ty * ty * s_yy + 2 * tx * ty * s_xy).ravel())
        xq.append(np.array(bj.global_coordinates()).reshape(2, -1))
    s_tt, xq = np.concatenate(s_tt), np.concatenate(xq, axis=1)
    s_nom = E_MOD / (1 - NU**2) * (h1 / 2) * abs(dkappa)
    k_all = s_tt / s_nom
    xs, ys = xq[0], xq[1]
    i = int(np.argmax(k_all))
    left, right = ys < 0, ys >= 0
    return {
        "kt": float(k_all[i]),
        "angle": float(np.arctan2(ys[i], xs[i])),
        "radius": float(np.hypot(xs[i], ys[i])),
        "dofs": int(ndof),
        "kt_left": float(k_all[left].max()),
        "kt_right": float(k_all[right].max()),
        "sigma_nom": float(s_nom),
        "dkappa": float(dkappa),
        "elements": int(tri.shape[0]),
        "min_angle": min_ang,
        "h_fine": float(h_fine),
    }
