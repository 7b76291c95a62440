"""One load state of the drive: contact problem re-linearised on the exact tooth geometry until the teeth stop moving (docs/models.md 4, 4.1)."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from math import pi

import numpy as np

from wgcad.errors import DesignError
from wgcad.placement import tooth_pose, transform

from .loaded import LoadedLaw
from .model import ElasticModel
from .solve import ContactSolveError, solve_contact_qp
from .teeth import flank_contacts

__all__ = ["LoadState", "solve_load", "POSITION_TOL", "RADIAL_MARGIN", "GAP_MARGIN"]

#: Re-linearisation stops when no tooth moves by more than this between two
#: solutions, mm (0.2 um: a fifth of the 1 um chord tolerance of the outlines.
#: The gaps are exact for the polygons, whose contact points move from edge to
#: edge: below ~0.1 um the iteration sees that discreteness, not the drive).
POSITION_TOL = 2e-4
#: Teeth whose tips stay this far inside the rigid tip circle are left out, mm:
#: the rim moves by tens of um under rated load; 0.2 mm is four times more.
RADIAL_MARGIN = 0.2
#: Flank pairs farther apart than this are left out of the contact problem, mm
#: (checked again at every re-linearisation on the loaded geometry, so a pair
#: enters as soon as the rim brings it this close).
GAP_MARGIN = 0.1
#: Contact forces below this are floored when the Hertz secants are taken, N
#: (the approach error it leaves is below 1e-5 mm for the balls and teeth of D1).
FORCE_FLOOR = 1e-2
_MAX_LINEARISATIONS = 100
_TRACE = None  # a list to record (pass, change, relaxation, pairs, loaded contacts) while debugging


@dataclass(frozen=True)
class LoadState:
    """A solved load state (lengths mm, angles rad, forces N inside).

    Attributes
    ----------
    torque_nm : float
    cam_offset : (2,) float
        Cam axis offset ``e_h`` in the generator frame, mm.
    laws : list of LoadedLaw
        The loaded neutral line of each section (``model.zs``).
    rigid : (3,) float
        Rim translation ``dx, dy`` (mm) and rotation (rad, counter-clockwise) relative to the rigid gear.
    contacts : dict of arrays
        ``kind`` (0 ball, 1 tooth), ``section``, ``tooth``, ``flank`` (0 lower, 1 upper, -1 ball),
        ``phi`` (rad), ``force`` (N), ``gap`` (exact geometric gap at the solution, mm),
        ``approach`` (contact compliance's share, mm), ``point`` (K, 2).
    residuals : dict
        ``equilibrium`` (relative), ``complementarity`` (relative), ``linearisation_mm``
        (exact minus linearised gap of the loaded contacts), ``iterations``, ``pivots``, ``position_change_mm``.
    timing : dict
        Seconds in ``geometry`` (exact engine, poses) and ``solver`` (compliance matrix, QP).
    """

    model: ElasticModel
    torque_nm: float
    cam_offset: np.ndarray
    laws: list
    rigid: np.ndarray
    contacts: dict
    residuals: dict
    timing: dict = field(default_factory=dict)

    @property
    def mesh_wind_up(self) -> float:
        """Rotation of the toothed rim against the rigid gear, rad (signed so that it grows with torque)."""
        return float(self.model.torque_sign * self.rigid[2])

    @property
    def wind_up(self) -> float:
        """Output wind-up: rim rotation plus the cup's twist ``M / K_cup``, rad."""
        return self.mesh_wind_up + 1e3 * self.torque_nm / self.model.cup_stiffness

    def law(self, section: int = 0) -> LoadedLaw:
        return self.laws[section]


def _cam_offset(e_um: float, e_deg: float) -> np.ndarray:
    e = 1e-3 * e_um
    a = np.deg2rad(e_deg)
    return np.array([e * np.cos(a), e * np.sin(a)])


def _tooth_candidates(model: ElasticModel, law, phi):
    """Poses of teeth at ``phi`` and the mask of those whose tips reach within RADIAL_MARGIN of the rigid tips."""
    rot, shift = tooth_pose(law, phi, model.drive.r_m)
    tips = transform(model.scene.flex_tip_local, rot, shift)
    R = np.hypot(tips[..., 0], tips[..., 1]).max(axis=1)
    return rot, shift, R >= model.scene.r_tip_b - RADIAL_MARGIN


def _geometry(model: ElasticModel, laws, psi, loads, rigid):
    """Tooth contacts of the current state, linearised: arrays for every pair within GAP_MARGIN."""
    d = model.drive
    z_g = d.design.drive.z_flex
    phi_all = 2.0 * pi * np.arange(z_g) / z_g
    phi_all = np.where(phi_all > pi, phi_all - 2.0 * pi, phi_all)
    rows = []
    for s, law in enumerate(laws):
        rot, shift, cand = _tooth_candidates(model, law, phi_all)
        idx = np.nonzero(cand)[0]
        if idx.size == 0:
            continue
        geo = flank_contacts(model.scene, rot[idx], shift[idx])
        st = law.state(phi_all[idx])
        c, sn = np.cos(phi_all[idx]), np.sin(phi_all[idx])
        o = np.stack([(d.r_m + st.w) * c - st.v * sn, (d.r_m + st.w) * sn + st.v * c], axis=-1)
        for fl, key in enumerate(("lower", "upper")):
            g = geo[key]
            keep = g.gap < GAP_MARGIN
            if not keep.any():
                continue
            rows.append(dict(section=np.full(keep.sum(), s), tooth=idx[keep], flank=np.full(keep.sum(), fl),
                             phi=phi_all[idx][keep], gap=g.gap[keep], point=g.point[keep], normal=g.normal[keep],
                             origin=o[keep], rigid_tooth=g.rigid[keep]))
    if not rows:
        return None
    return {k: np.concatenate([r[k] for r in rows]) for k in rows[0]}


def _assemble(model: ElasticModel, geo, psi, loads, rigid, e, F_prev_ball, F_prev_teeth, laws):
    """Vectors and matrices of the linearised contact problem (balls first, then teeth)."""
    ring, br = model.ring, model.bearing
    Z = len(br.psi)
    # balls: b = (-1, 0, 0) at psi_i, A = (-cos, -sin, v_nom), q = clearance - e . e_r (exact: linear in the state)
    centre = laws[0].centre
    v_nom = centre.state(br.psi).v
    cb, sb = np.cos(br.psi), np.sin(br.psi)
    phi_b = br.psi
    b_b = np.tile([-1.0, 0.0, 0.0], (Z, 1))
    A_b = np.stack([-cb, -sb, v_nom], axis=-1)
    o_b, s_b = br.tangent(F_prev_ball, FORCE_FLOOR)
    q_b = br.clearance - (e[0] * cb + e[1] * sb) + o_b
    if geo is None:
        return phi_b, b_b, np.ones(Z), A_b, q_b, s_b
    n, p, o, phi = geo["normal"], geo["point"], geo["origin"], geo["phi"]
    c, sn = np.cos(phi), np.sin(phi)
    rel = p - o
    b_t = np.stack([n[:, 0] * c + n[:, 1] * sn, -n[:, 0] * sn + n[:, 1] * c, rel[:, 0] * n[:, 1] - rel[:, 1] * n[:, 0]], axis=-1)
    f_t = model.scales[geo["section"]]
    A_t = np.stack([n[:, 0], n[:, 1], p[:, 0] * n[:, 1] - p[:, 1] * n[:, 0]], axis=-1)
    U = ring.field(phi, psi, loads)
    Uv = np.stack([U["w"], U["v"], U["theta"]], axis=-1)
    width = model.widths[geo["section"]]
    o_t, s_t = model.teeth.tangent(F_prev_teeth, width, FORCE_FLOOR)
    s_t = s_t + model.teeth.bending(p, n, width)
    q_t = geo["gap"] + f_t * (b_t * Uv).sum(axis=1) + A_t @ rigid + o_t
    return (np.concatenate([phi_b, phi]), np.concatenate([b_b, b_t]), np.concatenate([np.ones(Z), f_t]),
            np.concatenate([A_b, A_t]), np.concatenate([q_b, q_t]), np.concatenate([s_b, s_t]))


def _merge_loads(phi, loads):
    """Generalized loads summed per distinct angle, zero ones dropped (same field, far fewer kernel evaluations)."""
    nz = np.any(loads != 0.0, axis=1)
    u, inv = np.unique(np.round(phi[nz], 15), return_inverse=True)
    out = np.zeros((len(u), 3))
    np.add.at(out, inv, loads[nz])
    return u, out


def _compliance(ring, phi, b, f):
    """``D_jl = f_j f_l b_j' C(phi_j - phi_l) b_l`` through the distinct contact angles."""
    u, inv = np.unique(np.round(phi, 15), return_inverse=True)
    K = ring.block(u[:, None] - u[None, :])  # (n, n, 3, 3)
    fb = b * f[:, None]
    # contract the source side first (3 nonzeros per contact), then gather the observer side
    T = np.einsum("ulab,lb->ula", K[:, inv], fb)  # (n, m, 3)
    return np.einsum("ja,jla->jl", fb, T[inv])


def solve_load(model: ElasticModel, torque_nm: float, cam_offset_um: float = 0.0, cam_offset_deg: float = 0.0,
               tol: float = POSITION_TOL, warm: "LoadState | None" = None) -> LoadState:
    """Solve the drive under output torque ``torque_nm`` with the cam axis offset by ``cam_offset_um`` at ``cam_offset_deg``.

    Generator at angle 0 (major axis on +x, tooth 0 on it, rigid gear fixed).
    Each pass: exact contact geometry of every tooth near engagement from the
    clearance engine at the current loaded poses; the linearised problem
    ``gap = q + (D + diag(s)) F - A a >= 0, F >= 0, F gap = 0, A'F = (0, 0, M)``
    with ``D`` the ring compliance, ``s`` the ball and tooth secant
    compliances, ``A`` the rim's rigid-body freedoms (docs/models.md 4.1);
    then the poses are updated and the pass repeated until no tooth moves by
    more than ``tol`` (mm).

    Raises
    ------
    DesignError
        Negative torque or offset; teeth that never meet while a torque is asked;
        a bearing that cannot carry the load.
    ContactSolveError
        No convergence (never a silent return).
    """
    if not (np.isfinite(torque_nm) and torque_nm >= 0):
        raise DesignError("torque_nm", f"must be >= 0 N m, got {torque_nm:g}")
    if not (np.isfinite(cam_offset_um) and cam_offset_um >= 0):
        raise DesignError("cam_offset_um", f"must be >= 0 um, got {cam_offset_um:g}")
    if not tol > 0:
        raise DesignError("tol", f"must be > 0 mm, got {tol:g}")
    e = _cam_offset(cam_offset_um, cam_offset_deg)
    M_rim = model.torque_sign * 1e3 * torque_nm
    f_ext = np.array([0.0, 0.0, M_rim])
    Z = len(model.bearing.psi)
    psi = np.zeros(0)
    loads = np.zeros((0, 3))
    rigid = np.zeros(3)
    F_ball = np.zeros(Z)
    prev_active = {}
    F_teeth_prev = {}
    if warm is not None:
        psi, loads, rigid = warm.laws[0].psi.copy(), warm.laws[0].loads.copy(), np.array(warm.rigid)
        F_ball = warm.contacts["force"][warm.contacts["kind"] == 0].copy()
    centre = model.drive.law
    t_geo = t_sol = 0.0
    prev_pos = None
    pivots = 0
    omega, last_change, prev_omega = 1.0, np.inf, 1.0
    settled, relaxed = 0, False
    for it in range(_MAX_LINEARISATIONS):
        t0 = time.perf_counter()
        laws = [LoadedLaw(centre, model.section_law(i), model.ring, psi, loads, model.scales[i], tuple(rigid))
                for i in range(len(model.zs))]
        geo = _geometry(model, laws, psi, loads, rigid)
        if geo is None and torque_nm > 0:
            raise DesignError("generator.w0_coef", "the flexspline teeth never reach the rigid teeth (no tooth tip within "
                              f"{RADIAL_MARGIN:g} mm of the rigid tip circle): no torque can be carried")
        keys = [] if geo is None else list(zip(geo["section"].tolist(), geo["tooth"].tolist(), geo["flank"].tolist()))
        F_t_prev = np.array([F_teeth_prev.get(k, 0.0) for k in keys])
        # tooth positions (the carried poses of the engaging teeth) for the convergence test
        pos = {} if geo is None else {k: o for k, o in zip(keys, geo["origin"])}
        rigid_pos = float(rigid[2])
        t1 = time.perf_counter()
        phi_c, b, f, A, q, s = _assemble(model, geo, psi, loads, rigid, e, F_ball, F_t_prev, laws)
        M = _compliance(model.ring, phi_c, b, f)
        M[np.diag_indices_from(M)] += s
        active = np.concatenate([F_ball > 0, np.array([prev_active.get(k, False) for k in keys], dtype=bool)])
        try:
            sol = solve_contact_qp(M, q, A, f_ext, active=active if it else None)
        except ContactSolveError as exc:
            if torque_nm > 0 and geo is not None and "balance" in str(exc):
                raise DesignError("generator.w0_coef", f"no set of tooth contacts can carry {torque_nm:g} N m: the teeth never meet "
                                  "on the working flanks") from None
            raise
        pivots += sol.iterations
        t_sol += time.perf_counter() - t1
        t_geo += t1 - t0
        F = sol.F
        last = (geo, keys, F, sol, phi_c, b, f, A)
        omega_used = omega
        # under-relaxed update once the plain iteration stops contracting: the exact gaps are piecewise
        # smooth in the poses (polygon vertices), which can leave a 2-cycle of sub-micrometre amplitude
        psi_new, loads_new = _merge_loads(phi_c, -(F * f)[:, None] * b)
        F_t_new = {k: float(x) for k, x in zip(keys, F[Z:])}
        if omega < 1.0:
            psi, loads = _merge_loads(np.concatenate([psi, psi_new]), np.concatenate([(1 - omega) * loads, omega * loads_new]))
            rigid = (1 - omega) * rigid + omega * sol.a
            F_ball = (1 - omega) * F_ball + omega * F[:Z]
            F_teeth_prev = {k: (1 - omega) * F_teeth_prev.get(k, 0.0) + omega * F_t_new.get(k, 0.0) for k in set(F_t_new) | set(F_teeth_prev)}
        else:
            psi, loads, rigid = psi_new, loads_new, sol.a.copy()
            F_ball = F[:Z].copy()
            F_teeth_prev = F_t_new
        prev_active = {k: bool(x > 0) for k, x in zip(keys, F[Z:])}
        # convergence: largest move of an engaging tooth between two passes
        if prev_pos is not None:
            common = [k for k in pos if k in prev_pos]
            change = max((float(np.hypot(*(pos[k] - prev_pos[k]))) for k in common), default=0.0)
            # the step the plain iteration takes (a relaxed step is omega times it)
            change = max(change, abs(rigid_pos - prev_rigid) * model.drive.r_m) / prev_omega
            if _TRACE is not None:
                _TRACE.append((it, change, omega, len(pos), int((F > 0).sum())))
            # pairs entering or leaving the GAP_MARGIN band carry no load: not part of the test
            if change < tol:
                break
            # a contact toggling between passes (a linearisation that closes a pair the exact geometry
            # opens) has no fixed point: the relaxed passes settle where it switches; the residual of the
            # nonlinear contact law on the exact geometry is then reported (linearisation_mm)
            settled = settled + 1 if (omega < 1.0 and change * prev_omega < 0.25 * tol) else 0
            if settled >= 3:
                relaxed = True
                break
            if it >= 5 and change > 0.95 * last_change:  # a cycle, not a slow contraction
                omega = max(omega * 0.5, 1.0 / 16.0)
            last_change = change
        prev_pos, prev_rigid, prev_omega = pos, rigid_pos, omega_used
    else:
        raise ContactSolveError(f"load state at {torque_nm:g} N m: tooth positions still moving after {_MAX_LINEARISATIONS} re-linearisations")
    # the reported state is the last contact solution itself (not a relaxed mixture): its forces, points and
    # normals are in equilibrium to round-off; the exact gaps are then measured on the final poses
    geo, keys, F, sol, phi_c, b, f, A = last
    psi, loads = _merge_loads(phi_c, -(F * f)[:, None] * b)
    rigid = sol.a.copy()
    F_ball, Ft = F[:Z], F[Z:]
    model.bearing.check(F_ball)
    t0 = time.perf_counter()
    laws = [LoadedLaw(centre, model.section_law(i), model.ring, psi, loads, model.scales[i], tuple(rigid))
            for i in range(len(model.zs))]
    geo2 = _geometry(model, laws, psi, loads, rigid)
    t_geo += time.perf_counter() - t0
    n_t = len(keys)
    exact = {} if geo2 is None else dict(zip(zip(geo2["section"].tolist(), geo2["tooth"].tolist(), geo2["flank"].tolist()), geo2["gap"]))
    if n_t:
        width = model.widths[geo["section"]]
        appr_t = model.teeth.bending(geo["point"], geo["normal"], width) * Ft + model.teeth.hertz(Ft, width)
        # a pair that left the GAP_MARGIN band on the final poses is open by at least that much
        gap_t = np.array([exact.get(k, GAP_MARGIN) for k in keys])
    else:
        appr_t = gap_t = np.zeros(0)
    cb, sb = np.cos(model.bearing.psi), np.sin(model.bearing.psi)
    v_nom = centre.state(model.bearing.psi)
    wb = model.ring.field(model.bearing.psi, psi, loads)["w"] + rigid[0] * cb + rigid[1] * sb - rigid[2] * v_nom.v
    gap_b = model.bearing.clearance - (e[0] * cb + e[1] * sb) + wb
    appr_b = model.bearing.approach(F_ball)
    # exact complementarity of the nonlinear contacts: gap + approach >= 0, F >= 0, F (gap + approach) = 0
    g_all = np.concatenate([gap_b + appr_b, gap_t + appr_t])
    F_all = np.concatenate([F_ball, Ft])
    loaded = F_all > 0
    lin = float(np.abs(g_all[loaded]).max()) if loaded.any() else 0.0
    r_b = centre.r_m + v_nom.w
    ball_pt = np.stack([r_b * cb - v_nom.v * sb, r_b * sb + v_nom.v * cb], axis=-1)
    empty2 = np.zeros((0, 2))
    contacts = {
        "kind": np.concatenate([np.zeros(Z, int), np.ones(n_t, int)]),
        "section": np.concatenate([np.zeros(Z, int), geo["section"] if n_t else np.zeros(0, int)]),
        "tooth": np.concatenate([np.full(Z, -1), geo["tooth"] if n_t else np.zeros(0, int)]),
        "flank": np.concatenate([np.full(Z, -1), geo["flank"] if n_t else np.zeros(0, int)]),
        "phi": np.concatenate([model.bearing.psi, geo["phi"] if n_t else np.zeros(0)]),
        "force": F_all,
        "gap": np.concatenate([gap_b, gap_t]),
        "approach": np.concatenate([appr_b, appr_t]),
        "point": np.concatenate([ball_pt, geo["point"] if n_t else empty2]),
        "normal": np.concatenate([-np.stack([cb, sb], axis=-1), geo["normal"] if n_t else empty2]),
    }
    residuals = {
        "equilibrium": sol.equilibrium,
        "complementarity": sol.complementarity,
        "linearisation_mm": lin,
        "min_gap_plus_approach_mm": float(g_all.min()) if g_all.size else 0.0,
        "iterations": it + 1,
        "pivots": pivots,
        "position_change_mm": change if prev_pos is not None and it else 0.0,
        "settled_by_relaxation": relaxed,
    }
    return LoadState(model, float(torque_nm), e, laws, rigid, contacts, residuals, {"geometry": t_geo, "solver": t_sol})
