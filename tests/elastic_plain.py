"""A plain reference solver of the elastic contact model (docs/models.md 4.1), to check the fast one in wgcad.

What it shares with wgcad is the model's definition: the ring's closed-form
kernels (checked against an FE ring elsewhere), the exact tooth-pair contacts
(clearance engine), the balls' rows along the cam's normals and the contact
laws, and the exact complementarity solver. What it does its own way is every
shortcut of the fast solver: the ring is evaluated from the kernels at every
pass (no tables, no lazily built columns), every tooth pair near engagement is
measured again on the exact geometry at every pass (no Lipschitz skipping), the
compliance is a dense matrix with the supports added in full, and the passes
are a plain fixed-point iteration, halved steps once it stops contracting (no
Anderson acceleration, no warm start). The members' supports (docs/models.md 4.2)
are folded into the compliance the old way, ``A_j A_j' / k_j`` for a sprung
freedom (wgcad solves ``A'F + K a = f`` instead), and the cup's field added in
full; the freedoms' columns and the planes' motions are the model's own
(``model.supports``: their definition, not a shortcut).
"""

from __future__ import annotations

import numpy as np

from wgcad.elastic.cam import ball_rows, cam_excess
from wgcad.elastic.solve import solve_contact_qp
from wgcad.elastic.teeth import pair_contacts
from wgcad.placement import pose_from_displacements, transform

FLOOR = 1e-2  # N, the force floor of the contact secants (as wgcad's)


def _rim(model, psi, loads, motion):
    """w, v, theta (S, z_g) of every section at the tooth angles, from the kernels (``motion`` (S, 3): each
    section's rim motion against the rigid gear)."""
    z_g = model.drive.design.drive.z_flex
    phi = 2 * np.pi * np.arange(z_g) / z_g
    phi = np.where(phi > np.pi, phi - 2 * np.pi, phi)
    w, v, th = model.ring.displacements(phi, psi, loads)
    nom = [
        model.drive.law_at(float(z)).state(phi) if model.drive.coned else model.drive.law.state(phi) for z in model.zs
    ]
    out = []
    for f, n, (dx, dy, rot) in zip(model.scales, nom, motion):
        out.append(
            (
                f * w + dx * np.cos(phi) + dy * np.sin(phi) - rot * n.v,
                f * v - dx * np.sin(phi) + dy * np.cos(phi) + rot * (model.drive.r_m + n.w),
                f * th + rot,
            )
        )
    return phi, out


def _supported(M, q, A, f, k, field):
    """The dense supported solve: the cup's field and the sprung freedoms folded into M (a sprung freedom's external
    load moves it by f/k first), the free ones equalities, the held ones dropped."""
    eq = k == 0
    sp = np.isfinite(k) & (k > 0)
    Ms = M + (A[:, sp] / k[sp]) @ A[:, sp].T
    if field is not None:
        U, W = field
        Ms = Ms + U @ W @ U.T
    qs = q - A[:, sp] @ (f[sp] / k[sp])
    sol = solve_contact_qp(Ms, qs, A[:, eq], f[eq])
    a = np.zeros(len(k))
    a[eq] = sol.a
    a[sp] = -(A[:, sp].T @ sol.F - f[sp]) / k[sp]
    disp = None if field is None else -(field[1] @ (field[0].T @ sol.F))
    return sol.F, a, disp


def plain_solve(model, torque_nm: float, cam_offset_um: float = 0.0, tol: float = 5e-5, max_pass: int = 1000):
    """The load state at ``torque_nm`` (generator at angle 0): rim motion (3,), ball forces (Z,), tooth forces by
    (section, tooth, flank), the rim's (w, v) per section at the tooth angles, and the passes taken."""
    d = model.drive.design.drive
    z_g = d.z_flex
    e = np.array([1e-3 * cam_offset_um, 0.0])
    rows = ball_rows(model, cam_excess(model), e)
    br = model.bearing
    Z = len(br.psi)
    psi_t = 2 * np.pi * np.arange(z_g) / z_g
    psi_t = np.where(psi_t > np.pi, psi_t - 2 * np.pi, psi_t)
    sup = model.supports
    k = sup.stiffness
    f_ext = sup.f_ext(model.torque_sign * 1e3 * torque_nm)
    # start: the rim pressed onto the cam by the balls alone (wgcad's mounted state, checked by its own tests)
    from wgcad.elastic.cam import mounted

    mt = mounted(model, e)
    F_ball, F_teeth, keys = mt.force.copy(), np.zeros(0), np.zeros(0, dtype=int)
    psi_all = np.concatenate([psi_t, br.psi])
    loads, motion = mt.loads.copy(), mt.motion
    omega, last = 1.0, np.inf
    for it in range(max_pass):
        phi, rim = _rim(model, psi_all, loads, motion.sections)
        rots, shifts, origins = [], [], []
        for w, v, th in rim:
            r, s = pose_from_displacements(phi, w, v, th, model.drive.r_m)
            rots.append(r)
            shifts.append(s)
            origins.append(
                np.stack(
                    [
                        (model.drive.r_m + w) * np.cos(phi) - v * np.sin(phi),
                        (model.drive.r_m + w) * np.sin(phi) + v * np.cos(phi),
                    ],
                    axis=-1,
                )
            )
        rot, shift, origin = np.concatenate(rots), np.concatenate(shifts), np.concatenate(origins)
        # every tooth pair whose tooth reaches near the rigid tips, measured on the exact geometry
        tips = transform(model.scene.flex_tip_local, rot, shift)
        near = np.nonzero(np.hypot(tips[..., 0], tips[..., 1]).max(axis=1) >= model.scene.r_tip_b - 0.2)[0]
        lo, up, _ = model.scene.neighbours(shift[near], rot[near])
        t2 = np.repeat(near, 2)
        j2 = np.stack([lo, up], axis=1).ravel()
        g = pair_contacts(model.scene, rot[t2], shift[t2], j2)
        keep = g.gap < 0.1
        t2, flank = t2[keep], np.tile([0, 1], len(near))[keep]
        n, p, gap = g.normal[keep], g.point[keep], g.gap[keep]
        sec, tooth = np.divmod(t2, z_g)
        ph = psi_t[tooth]
        c, s = np.cos(ph), np.sin(ph)
        rel = p - origin[t2]
        b_t = np.stack(
            [n[:, 0] * c + n[:, 1] * s, -n[:, 0] * s + n[:, 1] * c, rel[:, 0] * n[:, 1] - rel[:, 1] * n[:, 0]], -1
        )
        A_t = np.stack([n[:, 0], n[:, 1], p[:, 0] * n[:, 1] - p[:, 1] * n[:, 0], 0 * n[:, 0], 0 * n[:, 0]], -1)
        f_t = model.scales[sec]
        width = model.widths[sec]
        # the current elastic field at each contact's angle: the linear gap is exact at the current state
        U = np.stack(model.ring.displacements(ph, psi_all, loads), axis=-1)
        q_t = gap + (b_t * (f_t[:, None] * U)).sum(axis=1) + (A_t[:, :3] * motion.sections[sec]).sum(axis=1)
        new_keys = t2 * 2 + flank
        Fprev = np.zeros(len(new_keys))
        if keys.size:
            m_ = dict(zip(keys.tolist(), F_teeth.tolist()))
            Fprev = np.array([m_.get(kk, 0.0) for kk in new_keys.tolist()])
        o_t, s_t = model.teeth.tangent(Fprev, width, FLOOR)
        s_t = s_t + model.teeth.bending(p, n, width)
        o_b, s_b = br.tangent(F_ball, FLOOR)
        b = np.concatenate([rows.b, b_t])
        fb = np.concatenate([np.ones(Z), f_t])[:, None] * b
        ang = np.concatenate([br.psi, ph])
        blk = model.ring.block(ang[:, None] - ang[None, :])
        M = np.einsum("ia,ijab,jb->ij", fb, blk, fb) + np.diag(np.concatenate([s_b, s_t]))
        q = np.concatenate([rows.q + o_b, q_t + o_t])
        A3 = np.concatenate([rows.A[:, :3], A_t[:, :3]])
        cam = np.concatenate([rows.A[:, 3:5], np.zeros((len(A_t), 2))])
        plane = np.concatenate([np.full(Z, sup.ball_plane), sec])
        tooth_row = np.concatenate([np.zeros(Z, dtype=bool), np.ones(len(A_t), dtype=bool)])
        A = sup.columns(A3, cam, plane, tooth_row)
        F, a, disp = _supported(M, q, A, f_ext, k, sup.field(A3, plane))
        new_motion = sup.plane_motion(a, disp)
        new_loads = np.zeros_like(loads)
        idx = np.concatenate([z_g + np.arange(Z), tooth])
        np.add.at(new_loads, idx, -(F * np.concatenate([np.ones(Z), f_t]))[:, None] * b)
        # convergence on the teeth's rim points (the fixed point of the re-linearisation)
        _, rim2 = _rim(model, psi_all, new_loads, new_motion.sections)
        move = max(
            float(np.abs(np.concatenate([r2[0] - r1[0] for r1, r2 in zip(rim, rim2)])).max()),
            float(np.abs(np.concatenate([r2[1] - r1[1] for r1, r2 in zip(rim, rim2)])).max()),
        )
        if move < tol:
            loads, motion, F_ball, F_teeth, keys = new_loads, new_motion, F[:Z], F[Z:], new_keys
            break
        if it > 5 and move > 0.95 * last:
            omega = max(omega / 2, 1 / 64)
        last = move
        loads = (1 - omega) * loads + omega * new_loads
        motion = motion.mix(new_motion, omega)
        F_ball = (1 - omega) * F_ball + omega * F[:Z]
        F_teeth, keys = F[Z:], new_keys
    else:
        raise RuntimeError(f"plain solve did not converge in {max_pass} passes (last move {last:.2e} mm)")
    _, rim = _rim(model, psi_all, loads, motion.sections)
    forces = {}
    for kk, FF in zip(keys.tolist(), F_teeth.tolist()):
        if FF > 0:
            forces[(kk // 2) // z_g, (kk // 2) % z_g, kk % 2] = FF
    return {
        "rigid": motion.centre,
        "motion": motion,
        "ball_force": F_ball,
        "tooth_force": forces,
        "rim": rim,
        "passes": it + 1,
    }
