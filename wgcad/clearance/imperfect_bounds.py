"""Lower bounds of an imperfect drive's clearance: the perfect drive's c(phi) less each tooth's error reach (docs/models.md 6.2, 7).

:class:`PerfectBound` bounds the perfect drive's clearance on a fixed grid of
tooth angles (its own culling and branch and bound, which the perfect drive's
symmetries still serve); :class:`ErrorBound` bounds how far the errors move
a tooth against the rigid tooth it faces. Their difference bounds every
sample of the imperfect sweep (:mod:`wgcad.clearance.imperfect`).
"""

from __future__ import annotations

from math import pi

import numpy as np

from ..placement.imperfect import Imperfections, cam_offset, coning_factor, flex_deviations, rigid_translation
from .scene import Scene
from .search import SectionSearch, evaluate

__all__ = ["PerfectBound", "PerfectBounds", "ErrorBound", "GRID_LOSS", "chunk_bounds"]


class PerfectBound:
    """Lower bounds of the perfect drive's clearance ``c(phi)`` of one section on a fixed grid of tooth angles (docs/models.md 7).

    The grid covers one folded half-wave ``[0, pi / n_w]`` (the perfect drive
    has identical, mirror-symmetric waves), spaced so that the Lipschitz
    interpolation between grid points loses at most :data:`GRID_LOSS`. The
    perfect engine's own culling and branch and bound fill it: points whose
    bound lies below ``best + band`` are evaluated, the others keep a bound
    at least that high. Its size does not depend on the sweep.
    """

    def __init__(self, scene: Scene, z, settings):
        half = pi / scene.n_w
        self.V = scene.speed_bound(np.linspace(-half, half, 4097), z)  # per rad of tooth angle, every phi
        n = int(np.ceil(half * self.V / (2.0 * GRID_LOSS))) + 1
        self.h = half / (n - 1)
        self.grid = np.linspace(0.0, half, n)
        self.search = SectionSearch(scene, self.grid, z, settings)
        self.search.prepare_bound()
        self.z, self.half = z, half

    @property
    def lower(self) -> np.ndarray:
        return self.search.lower

    def at(self, phi: np.ndarray) -> np.ndarray:
        """Lower bound of ``c`` at tooth angles ``phi`` (any), from the two grid points around each."""
        key = np.abs((phi + self.half) % (2.0 * self.half) - self.half)
        i0 = np.minimum((key / self.h).astype(int), len(self.grid) - 2)
        lo = self.search.lower
        d0 = key - self.grid[i0]
        return np.maximum(lo[i0] - self.V * d0, lo[i0 + 1] - self.V * (self.h - d0))


#: largest loss (mm) of the perfect bound from interpolating between its grid points: the grid
#: holds ~6000 tooth angles per section for D1; a finer one costs more perfect evaluations
GRID_LOSS = 0.5e-3


class PerfectBounds:
    """The perfect drive's bounds of every section (:class:`PerfectBound`), searched together: the best of any prunes all."""

    def __init__(self, scene: Scene, sections: list, settings):
        self.evaluate = evaluate
        self.scene, self.sections = scene, sections
        self.pb = [PerfectBound(scene, z, settings) for z in sections]
        self.res = [p.search for p in self.pb]
        self.best = evaluate(scene, self.res, [r.coarse() for r in self.res], sections)
        self.band = -np.inf

    def extend(self, band: float) -> None:
        """Evaluate every grid point whose bound lies below ``best + band``; the others keep bounds at least that high."""
        if band <= self.band:
            return
        ev, sc, res, zs = self.evaluate, self.scene, self.res, self.sections
        for stride in (64, 16, 4, 1):
            self.best = ev(sc, res, [r.candidates(stride, self.best + band) for r in res], zs)
        self.best = ev(sc, res, [r.culled_needed(self.best + band) for r in res], zs)
        self.band = band

    @property
    def evaluated(self) -> int:
        return int(sum(r.evaluated.sum() for r in self.res))


class ErrorBound:
    """How far the errors move a flexspline tooth relative to the rigid teeth it faces, per sample, mm.

    A sample's clearance differs from the perfect drive's at the same tooth
    angle by at most the largest displacement of a point of the tooth in
    the frame of the rigid tooth it is measured against (a signed distance,
    and a penetration depth, move by no more than the bodies do). To first
    order that displacement is one vector for the whole tooth
    (docs/models.md 6.2), with ``t``, ``e`` the tangent and radius at the
    tooth's material angle ``mat``:

        (dalpha r_m - dev(mat) r_b) t + drho e + c E - T

    (the flexspline's run-out and eccentricity along and across the rim,
    the rigid tooth's run-out turn, the cam offset ``E`` scaled by coning,
    the rigid gear's eccentric shift ``T``); errors of the same direction
    cancel in it. What the vector leaves out is bounded term by term
    (:meth:`remainder`): the rim's deformation and the tooth's turn under
    ``dalpha``, the tooth's extent about its centre line, and the rigid
    teeth within three pitches having run-out turns other than ``dev(mat)``.
    """

    def __init__(self, scene: Scene, imp: Imperfections, sections: list):
        drive = scene.drive
        self.imp, self.scene = imp, scene
        self.z_g, self.z_b = scene.z_g, scene.z_b
        self.r_m = r_m = drive.r_m
        self.r_g, self.r_b = drive.flex.r, drive.rigid.r
        self.u = scene.ratios["u_hg"]
        self.T = rigid_translation(imp)
        phi = np.linspace(-pi, pi, 8192, endpoint=False)
        lever_f0 = float(np.hypot(scene.flex_local[:, 0] - r_m, scene.flex_local[:, 1]).max())
        R_loc = np.hypot(scene.flex_local[:, 0], scene.flex_local[:, 1])
        half_w = float(np.abs(scene.flex_local[:, 1]).max())
        gamma_b = 2.0 * pi / scene.z_b
        self.a_b = 0.5 * imp.rigid_runout / self.r_b  # largest run-out turn of a rigid tooth, rad
        da_max = (0.5 * imp.flex_runout + abs(imp.flex_ecc)) / self.r_g
        self.k_gain, self.rho_gain, self.dev_gain, self.fixed, self.cz = [], [], [], [], []
        for z in sections:
            st = scene.law(z).state(phi)
            # a face-modified section's teeth stand tooth_offset further out: every lever and radius grows by at most it
            off = abs(scene.law(z).tooth_offset)
            lever_f, R_hi, R_lo = lever_f0 + off, R_loc.max() + off, R_loc.min() - off
            w_max, v_max = float(np.abs(st.w).max()), float(np.abs(st.v).max())
            dth = float(np.abs(st.dtheta).max())
            # 1 % on every maximum over the grid of rim angles (they vary by far less between its points)
            self.k_gain.append(
                1.01 * (float(np.hypot(st.dw - st.v, st.w + st.dv).max()) + r_m * da_max + (1.0 + dth) * lever_f)
            )
            self.rho_gain.append(1.01 * (float(np.abs(st.theta).max()) + da_max * (1.0 + dth)))
            # a flexspline tooth point p: | |p| - r_b | and its angle from mat (tooth half-width, v, theta)
            rad_spread = float(max(abs(R_hi + w_max - self.r_b), abs(R_lo - w_max - self.r_b)))
            ang = half_w / R_lo + v_max / r_m + float(np.abs(st.theta).max())
            self.dev_gain.append(1.01 * (rad_spread + self.r_b * ang))
            self.fixed.append(1.01 * self.a_b * 3.0 * gamma_b * (R_hi + w_max))
            self.cz.append(coning_factor(drive, z))
        # second order: the rigid frame's own turn applied to the displacement (|dev| |Delta|), bounded
        # with the largest displacement the amplitudes allow
        self.second = self.a_b * imp.amplitude

    def bound(self, k, phi_h) -> np.ndarray:
        """Largest relative displacement (mm) of teeth ``k`` (Kk,) at generator angles ``phi_h`` (B,), every section, ``(S, Kk, B)``."""
        imp = self.imp
        k = np.asarray(k)
        phi_h = np.asarray(phi_h, dtype=float)
        da, dr = flex_deviations(imp, k, self.z_g, self.r_g)
        da, dr = da[:, None], dr[:, None]
        # mat = A_k + B_h: its sines and cosines from the two factors' (outer products, no trigonometry on K x B)
        A, Bh = 2.0 * pi * k / self.z_g, phi_h / self.u
        ca, sa, cb, sb = np.cos(A)[:, None], np.sin(A)[:, None], np.cos(Bh)[None, :], np.sin(Bh)[None, :]
        c, s = ca * cb - sa * sb, sa * cb + ca * sb
        p = imp.rigid_runout_phase - imp.rigid_install
        dev = self.a_b * (s * np.cos(p) + c * np.sin(p))  # a_b sin(mat + p)
        E = cam_offset(imp, phi_h, phi_h / self.u)  # (B, 2)
        tan = da * self.r_m - dev * self.r_b
        bx = -tan * s + dr * c - self.T[0]
        by = tan * c + dr * s - self.T[1]
        ada, adr, adev = np.abs(da), np.abs(dr), np.abs(dev)
        out = np.empty((len(self.cz), len(k), len(phi_h)))
        for si, cz in enumerate(self.cz):
            rem = (
                ada * self.k_gain[si]
                + adr * self.rho_gain[si]
                + adev * self.dev_gain[si]
                + (self.fixed[si] + self.second)
            )
            out[si] = np.hypot(bx + cz * E[None, :, 0], by + cz * E[None, :, 1]) + rem
        return out

    def largest(self, angles: np.ndarray) -> float:
        """The largest :meth:`bound` over the teeth and (up to 90 of the) angles, mm.

        Only the width of the perfect drive's search rests on it, not a
        bound's validity, so a subsample of the angles is enough.
        """
        return float(self.bound(np.arange(self.z_g), angles[:: max(1, len(angles) // 90)]).max())


def chunk_bounds(pb, eb, angles, a0, a1, z_g, S):
    """Lower bounds of the imperfect clearance of samples (section, tooth, angle) of angles ``a0:a1``, ``(S, z_g, B)``."""
    ph = angles[a0:a1]
    k = np.arange(z_g)[:, None]
    phi = 2.0 * pi * k / z_g + ph[None, :] * (1.0 / eb.u - 1.0)
    out = -eb.bound(np.arange(z_g), ph)
    for si in range(S):
        out[si] += pb[si].at(phi)
    return out
