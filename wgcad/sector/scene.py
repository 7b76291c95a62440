"""Clearance sweep of a sectored drive: flexspline teeth against variable-height sector teeth over the cycle, tip-to-tip findings (docs/models.md 2.3, 5).

Which shortcuts of docs/models.md 7 still hold:

* **mesh period**: none. The rigid teeth do not repeat with one pitch, so
  the state at ``phi_h`` and ``phi_h + 2 pi / N`` differ; every generator
  angle of the sweep is computed.
* **identical waves**: yes, with opposite sectors identical (validated) and
  ``z_flex`` a multiple of the waves: the flexspline advances by whole
  teeth per half turn (:class:`~wgcad.sector.motion.MotionLaw`), so the scene
  at ``phi_h + pi`` is the scene at ``phi_h`` turned by ``pi``. A sweep
  over half a turn with every tooth covers the whole turn.
* **mirror**: holds only when the heights and layout are symmetric about a
  sector's middle; not assumed (the symmetry of the heights is a result
  that the tests check, so it must not be an input).
* **radial culling**: yes, exactly as in the plain audit: a flexspline tooth
  whose outermost point lies inside the smallest rigid tip radius by more
  than ``cull`` cannot come closer than that to any rigid tooth.
* **branch and bound**: its speed bound is the plain scene's; not used here.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from math import pi

import numpy as np

from .. import constants
from ..clearance.distance import Template, signed_clearance
from ..placement import tooth_pose, transform
from ..profiles.sampling import polar
from ..profiles.sector import SectorLayout, TeethByHeight
from .motion import MotionLaw, motion_law

__all__ = [
    "SectoredScene",
    "SweepPairs",
    "SectoredAudit",
    "SectorSpot",
    "sectored_audit",
    "sweep_angles",
    "flex_state",
    "facing_flex_tooth",
    "DEFAULT_STEP_DEG",
    "DEFAULT_CULL",
]

#: generator-angle step of the sweeps, deg: a flexspline tip moves radially by
#: at most |w'| ~ W0 per rad, 1.4 um per 0.1 deg at W0 = 0.8 mm
DEFAULT_STEP_DEG = 0.1

#: the third-nearest rigid tooth is measured only when the flexspline tooth's centre line lies within this fraction of
#: a pitch of the nearer bracketing tooth's (see :meth:`SectoredScene.pairs`)
THIRD_TOOTH_WITHIN = 0.15

#: teeth radially clear of every rigid tip by more than this (mm) are not
#: measured: their clearance is at least this, far above any finding
DEFAULT_CULL = 0.05


def _wrap(a):
    return (np.asarray(a) + pi) % (2.0 * pi) - pi


def flex_state(law, r_m: float, motion: MotionLaw, z_g: int, phi_h):
    """Poses of every flexspline tooth at generator angles ``phi_h (A,)`` with the motion law: rot ``(A, z)``, shift
    ``(A, z, 2)`` (rigid frame) and each tooth's material angle from the major axis ``(A, z)`` (docs/models.md 3.1)."""
    phi_h = np.atleast_1d(np.asarray(phi_h, dtype=float))
    g = motion(phi_h)
    mat = 2.0 * pi * np.arange(z_g)[None, :] / z_g + g[:, None]
    phi = _wrap(mat - phi_h[:, None])
    fa = np.broadcast_to(phi_h[:, None], phi.shape)
    rot, shift = tooth_pose(law, phi.ravel(), r_m, frame_angle=fa.ravel())
    A, z = phi.shape
    return rot.reshape(A, z), shift.reshape(A, z, 2), phi


def facing_flex_tooth(law, r_m: float, motion: MotionLaw, z_g: int, phi_h: float, centres) -> tuple:
    """The flexspline tooth whose centre line stands nearest each rigid tooth centre ``centres`` (rad) at the generator
    angle ``phi_h``, and that tooth's material angle from the major axis: ``(index (K,), angle (K,))``."""
    rot, shift, phi = flex_state(law, r_m, motion, z_g, np.array([phi_h]))
    rot, shift, phi = rot[0], shift[0], phi[0]
    ang = np.arctan2(shift[:, 1] + r_m * np.sin(rot), shift[:, 0] + r_m * np.cos(rot))
    k = np.argmin(np.abs(_wrap(np.asarray(centres)[:, None] - ang[None, :])), axis=1)
    return k, phi[k]


def sweep_angles(step_deg: float = DEFAULT_STEP_DEG) -> np.ndarray:
    """Generator angles over half a turn (identical waves), rad."""
    n = int(round(180.0 / step_deg))
    return np.arange(n) * (pi / n)


class SectoredScene:
    """A drive's flexspline against a sectored rigid gear of given tooth heights (rigid-gear frame).

    Parameters
    ----------
    drive : wgcad.drive.Drive
        The flexspline, the deformation law and the rigid tooth form.
    layout : SectorLayout
    teeth : TeethByHeight
    heights : (N,) float
        Height of every rigid tooth, mm.
    """

    def __init__(self, drive, layout: SectorLayout, teeth: TeethByHeight, heights):
        self.drive = drive
        self.layout = layout
        self.teeth = teeth
        self.z_g = drive.design.drive.z_flex
        self.law = drive.law
        self.r_m = drive.r_m
        self.motion: MotionLaw = motion_law(layout, self.z_g)
        fl = drive.flex
        self.flex = Template(fl.tooth_polygon())
        psi_g = fl.tip_thickness / (2.0 * fl.r_a)
        # the flexspline tooth's tip land: its two corners and its middle (tooth frame)
        self.flex_tip = polar(fl.r_a, np.array([-psi_g, 0.0, psi_g]))
        R = np.hypot(self.flex.local[:, 0], self.flex.local[:, 1])
        self.flex_outer = np.ascontiguousarray(self.flex.local[R >= fl.r_a - 0.5 * abs(fl.r_a - fl.r_f)])
        g_full = teeth.full
        #: tip half-angle of the full-height tooth: "facing" (out of register) is judged against it at every height
        self.psi_full = g_full.tip_thickness / (2.0 * g_full.r_a)
        self.set_heights(heights)

    def set_heights(self, heights) -> None:
        """Rebuild the rigid teeth for new heights (templates cached per height)."""
        h = np.asarray(heights, dtype=float)
        self.heights = h
        cache: dict = getattr(self, "_templates", {})
        self._templates = cache
        self.rigid_templates = []
        self.r_tip = np.empty(len(h))
        self.psi_tip = np.empty(len(h))
        for i, hi in enumerate(h):
            key = round(float(hi), 12)
            if key not in cache:
                g = self.teeth.gear(hi)
                cache[key] = (Template(g.tooth_polygon()), g.r_a, g.tip_thickness / (2.0 * g.r_a))
            t, ra, psi = cache[key]
            self.rigid_templates.append(t)
            self.r_tip[i] = ra
            self.psi_tip[i] = psi

    def flex_state(self, phi_h: np.ndarray):
        """Poses of every flexspline tooth at generator angles ``phi_h (A,)``: rot ``(A, z)``, shift ``(A, z, 2)``, phi ``(A, z)``."""
        return flex_state(self.law, self.r_m, self.motion, self.z_g, phi_h)

    def pairs(self, phi_h: np.ndarray, cull: float = DEFAULT_CULL, teeth=None) -> SweepPairs:
        """Flexspline-rigid tooth pairs worth measuring over the generator angles ``phi_h``.

        Each flexspline tooth is paired with the two rigid teeth that bracket
        its centre line, and with the next nearest where it can reach it
        (:data:`THIRD_TOOTH_WITHIN`); teeth radially clear of the
        smallest rigid tip radius by more than ``cull`` are left out.
        ``teeth`` restricts the rigid teeth (indices).
        """
        phi_h = np.atleast_1d(np.asarray(phi_h, dtype=float))
        rot, shift, phi = self.flex_state(phi_h)
        A, z = rot.shape
        rot, shift, phi = rot.ravel(), shift.reshape(-1, 2), phi.ravel()
        ai = np.repeat(np.arange(A), z)
        ki = np.tile(np.arange(z), A)
        outer = transform(self.flex_outer, rot, shift)
        R_out = np.hypot(outer[..., 0], outer[..., 1]).max(axis=1)
        near = R_out > self.r_tip.min() - cull
        rot, shift, phi, ai, ki = rot[near], shift[near], phi[near], ai[near], ki[near]
        # centre-line point of each tooth -> its angle in the rigid frame
        cx = shift[:, 0] + self.r_m * np.cos(rot)
        cy = shift[:, 1] + self.r_m * np.sin(rot)
        ang = np.arctan2(cy, cx)
        c = self.layout.centres
        N = len(c)
        base = c[0]
        rel = (ang - base) % (2.0 * pi)
        up = np.searchsorted(c - base, rel) % N
        lo = (up - 1) % N
        d_lo = np.abs(_wrap(ang - c[lo]))
        d_up = np.abs(_wrap(ang - c[up]))
        near_lo = d_lo < d_up
        third = np.where(near_lo, (lo - 1) % N, (up + 1) % N)
        # Both tooth polygons span half a pitch either side of their centre lines (their bodies are closed there), so a
        # flexspline tooth reaches past the nearer bracketing tooth only when its centre line is almost on that tooth's;
        # 0.15 pitch covers the tilt of the tooth (theta ~ 0.05 rad swings its corners by < 0.1 pitch).
        d_near = np.where(near_lo, d_lo, d_up)
        need3 = d_near < THIRD_TOOTH_WITHIN * self.layout.pitch[np.where(near_lo, lo, up)]
        rows = np.concatenate([np.arange(len(ang)), np.arange(len(ang)), np.nonzero(need3)[0]])
        ri = np.concatenate([lo, up, third[need3]])
        sel = np.ones(len(ri), dtype=bool) if teeth is None else np.isin(ri, np.asarray(teeth))
        rows, ri = rows[sel], ri[sel]
        # angle from the nearer wave end (the law repeats every 2 pi / waves)
        per = 2.0 * pi / self.drive.design.drive.waves
        phi = (phi + 0.5 * per) % per - 0.5 * per
        return SweepPairs(
            phi_h=phi_h, angle=ai[rows], flex=ki[rows], rigid=ri, rot=rot[rows], shift=shift[rows], phi=phi[rows]
        )

    def facing(self, pairs: SweepPairs, psi=None) -> np.ndarray:
        """Whether each pair's flexspline tip land faces the rigid tooth's tip land (overlapping angular extents), ``(P,)`` bool.

        The rigid tip land is the full-height tooth's (``psi`` overrides it,
        ``(P,)`` rad): out of register is a property of where the teeth
        stand, not of how high the rigid tooth is. A lowered internal tooth
        is wider at its new tip; a flexspline tip that misses the full tip
        land but touches the wider one meets the flank just below the old
        tip and is counted as a flank finding.
        """
        pts = transform(self.flex_tip, pairs.rot, pairs.shift)
        c = self.layout.centres[pairs.rigid]
        a = _wrap(np.arctan2(pts[..., 1], pts[..., 0]) - c[:, None])
        lo, hi = a.min(axis=1), a.max(axis=1)
        ps = self.psi_full if psi is None else psi
        return (hi >= -ps) & (lo <= ps)

    def clearance(self, pairs: SweepPairs, heights=None) -> np.ndarray:
        """Signed clearance of every pair (mm, negative = penetration depth), grouped per rigid tooth template.

        ``heights`` (``(P,)``) measures each pair against a rigid tooth of that
        height instead of the scene's.
        """
        out = np.empty(len(pairs.rigid))
        if heights is None:
            keys = np.array([id(self.rigid_templates[i]) for i in pairs.rigid]) if len(pairs.rigid) else np.zeros(0)
            groups = {}
            for n, i in enumerate(pairs.rigid):
                groups.setdefault(keys[n], (self.rigid_templates[i], []))[1].append(n)
        else:
            groups = {}
            for n, h in enumerate(np.asarray(heights, dtype=float)):
                key = round(float(h), 12)
                if key not in groups:
                    groups[key] = (Template(self.teeth.gear(h).tooth_polygon()), [])
                groups[key][1].append(n)
        for tmpl, members in groups.values():
            sel = np.asarray(members)
            rb = self.layout.centres[pairs.rigid[sel]]
            out[sel] = signed_clearance(self.flex, pairs.rot[sel], pairs.shift[sel], tmpl, rb, np.zeros((len(sel), 2)))
        return out


@dataclass(frozen=True, slots=True)
class SweepPairs:
    """Tooth pairs of a sweep: generator-angle index, flexspline tooth, rigid tooth, the flexspline tooth's pose and angle from the major axis."""

    phi_h: np.ndarray
    angle: np.ndarray
    flex: np.ndarray
    rigid: np.ndarray
    rot: np.ndarray
    shift: np.ndarray
    phi: np.ndarray

    def take(self, sel) -> SweepPairs:
        return SweepPairs(
            self.phi_h, self.angle[sel], self.flex[sel], self.rigid[sel], self.rot[sel], self.shift[sel], self.phi[sel]
        )

    def __len__(self) -> int:
        return len(self.rigid)


@dataclass(slots=True)
class SectoredAudit:
    """Findings of a sectored sweep (lengths mm, angles rad; :func:`wgcad.report.sector.sectored_audit_document`
    rounds and converts them).

    ``tip_to_tip`` lists, per rigid tooth that meets a flexspline tip
    tip-to-tip (facing tip lands, clearance within the contact tolerance),
    its worst sample.
    """

    min_clearance: float
    worst: SectorSpot | None
    tip_to_tip: list
    min_tip_clearance: float
    worst_tip: SectorSpot | None
    flank_interference: bool
    min_flank_clearance: float
    interference_tol: float
    counts: dict
    settings: dict
    elapsed_s: float = 0.0
    per_tooth_tip: np.ndarray = field(default=None, repr=False)
    #: every rigid tooth's smallest clearance over the cycle (any pair, mm; inf: never measured), the generator angle
    #: (rad) and the flexspline tooth of that sample (-1: none)
    per_tooth_min: np.ndarray = field(default=None, repr=False)
    per_tooth_generator_angle: np.ndarray = field(default=None, repr=False)
    per_tooth_flex: np.ndarray = field(default=None, repr=False)

    @property
    def has_tip_to_tip(self) -> bool:
        return len(self.tip_to_tip) > 0

    @property
    def interferes(self) -> bool:
        """Tip-to-tip contact or flank interference left anywhere in the cycle: the drive does not run."""
        return self.has_tip_to_tip or self.flank_interference


@dataclass(slots=True)
class SectorSpot:
    """Where a sectored sweep found a figure: the pair's clearance (mm), the generator angle (rad), the flexspline tooth
    and its angle from the major axis (rad), the rigid tooth, its sector (index, kind, place in it), its angle from the
    sector boundary (rad) and its built height (mm)."""

    clearance: float
    generator_angle: float
    flex_tooth: int
    flex_tooth_angle: float
    rigid_tooth: int
    sector: int
    sector_kind: str
    tooth_in_sector: int
    from_boundary: float
    rigid_tooth_height: float


def _where(scene: SectoredScene, pairs: SweepPairs, n: int, c: float) -> SectorSpot:
    lay = scene.layout
    i = int(pairs.rigid[n])
    s = int(lay.sector[i])
    return SectorSpot(
        clearance=float(c),
        generator_angle=float(pairs.phi_h[pairs.angle[n]]),
        flex_tooth=int(pairs.flex[n]),
        flex_tooth_angle=float(pairs.phi[n]),
        rigid_tooth=i,
        sector=s,
        sector_kind=lay.kinds[s],
        tooth_in_sector=int(lay.index[i]),
        from_boundary=float(lay.delta[i]),
        rigid_tooth_height=float(scene.heights[i]),
    )


def sectored_audit(
    scene: SectoredScene,
    step_deg: float = DEFAULT_STEP_DEG,
    cull: float = DEFAULT_CULL,
    interference_tol: float = constants.INTERFERENCE_TOL,
) -> SectoredAudit:
    """Sweep the generator over the cycle (half a turn: identical waves) and report tip-to-tip and flank findings.

    A pair meets *tip-to-tip* when its tip lands face each other
    (:meth:`SectoredScene.facing`) and its clearance is at most the contact
    tolerance: the flexspline tip lands on the rigid tip instead of entering
    a space (docs/models.md 5). Other pairs below ``-interference_tol`` are flank
    (or root) interference.
    """
    import time

    t0 = time.perf_counter()
    angles = sweep_angles(step_deg)
    pairs = scene.pairs(angles, cull)
    c = scene.clearance(pairs)
    face = scene.facing(pairs)
    tips = np.nonzero(face & (c <= interference_tol))[0]
    per_tooth = {}
    for n in tips:
        i = int(pairs.rigid[n])
        if i not in per_tooth or c[n] < c[per_tooth[i]]:
            per_tooth[i] = n
    tip_list = [_where(scene, pairs, n, c[n]) for _, n in sorted(per_tooth.items())]
    tip_min = np.full(scene.layout.n_teeth, np.inf)
    np.minimum.at(tip_min, pairs.rigid[face], c[face])
    k = int(np.argmin(c)) if len(c) else None
    fk = np.nonzero(face)[0]
    kt = int(fk[np.argmin(c[fk])]) if fk.size else None
    nf = np.nonzero(~face)[0]
    min_flank = float(c[nf].min()) if nf.size else float("inf")
    N = scene.layout.n_teeth
    order = np.lexsort((c, pairs.rigid))  # by tooth, then clearance: each tooth's first row is its smallest
    first = order[np.unique(pairs.rigid[order], return_index=True)[1]] if len(c) else np.zeros(0, dtype=int)
    t_min, t_ang, t_flex = np.full(N, np.inf), np.full(N, np.nan), np.full(N, -1)
    ri = pairs.rigid[first]
    t_min[ri], t_ang[ri], t_flex[ri] = c[first], pairs.phi_h[pairs.angle[first]], pairs.flex[first]
    return SectoredAudit(
        min_clearance=float(c[k]) if k is not None else float("inf"),
        worst=_where(scene, pairs, k, c[k]) if k is not None else None,
        tip_to_tip=tip_list,
        min_tip_clearance=float(c[kt]) if kt is not None else float("inf"),
        worst_tip=_where(scene, pairs, kt, c[kt]) if kt is not None else None,
        flank_interference=bool(min_flank < -interference_tol),
        min_flank_clearance=min_flank,
        interference_tol=interference_tol,
        counts={"generator_angles": int(len(angles)), "pairs_measured": int(len(c)), "facing_pairs": int(face.sum())},
        settings={
            "step_deg": step_deg,
            "sweep": "half turn, every tooth (identical waves)",
            "cull_um": 1e3 * cull,
            "mesh_period": False,
            "mirror": False,
        },
        elapsed_s=time.perf_counter() - t0,
        per_tooth_tip=tip_min,
        per_tooth_min=t_min,
        per_tooth_generator_angle=t_ang,
        per_tooth_flex=t_flex,
    )
