"""Sectored rigid gear of a discrete-motion drive: tooth positions per sector and variable-height teeth (docs/models.md 2.3)."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from math import pi

import numpy as np

from .. import constants
from ..design.sectors import SectorsSpec, sector_pitch_z
from ..errors import DesignError
from . import pieces as pc
from .band import band_points
from .gear import Gear, ToothSpec, make_gear, rotate
from .sampling import arc_points

__all__ = ["SectorLayout", "sector_layout", "full_height", "TeethByHeight", "sectored_outline", "sectored_gear_outline"]

#: Teeth lower than this fraction of the module are left out (a root arc runs
#: on): a stub of a few micrometres has no flank to mesh with, and its tip land
#: would be wider than the space it sits in.
MIN_HEIGHT_COEF = 0.05


@dataclass(frozen=True, slots=True)
class SectorLayout:
    """Where every tooth of a sectored rigid gear sits. Angles rad, counter-clockwise.

    Attributes
    ----------
    centres : (N,) float
        Tooth centre lines, increasing from ``bounds[0]``.
    sector : (N,) int
        Sector of each tooth (index into the design's lists).
    index : (N,) int
        Position of the tooth in its sector, from 0.
    coupling : (N,) bool
        Tooth of a coupling sector.
    pitch : (N,) float
        Angular pitch of the tooth's sector.
    delta : (N,) float
        Angle from the tooth centre to the nearer boundary of its sector.
    bounds : (n + 1,) float
        Sector boundaries; sector ``s`` spans ``bounds[s] .. bounds[s + 1]``.
    kinds : tuple of str
    spaces : (N,) float
        Centre of the space after each tooth (between tooth ``i`` and ``i + 1``).
    """

    centres: np.ndarray
    sector: np.ndarray
    index: np.ndarray
    coupling: np.ndarray
    pitch: np.ndarray
    delta: np.ndarray
    bounds: np.ndarray
    kinds: tuple
    spaces: np.ndarray

    @property
    def n_teeth(self) -> int:
        return len(self.centres)

    def coupling_sector_teeth(self, s: int | None = None) -> np.ndarray:
        """Indices of the teeth of coupling sector ``s`` (default the first coupling sector), in order."""
        if s is None:
            s = self.kinds.index("coupling")
        return np.nonzero(self.sector == s)[0]


def sector_layout(spec: SectorsSpec, z_flex: int, z_rigid: int) -> SectorLayout:
    """Tooth positions of a validated :class:`SectorsSpec`: each tooth owns one pitch of its sector, centred on it."""
    pz = sector_pitch_z(spec, z_flex, z_rigid)
    start = np.deg2rad(spec.start_deg)
    centres, sector, index, coupling, pitch, delta = [], [], [], [], [], []
    bounds = [start]
    a = start
    for s, (kind, z, p_z) in enumerate(zip(spec.kinds, spec.teeth, pz)):
        p = 2.0 * pi / p_z
        k = np.arange(z)
        c = a + (k + 0.5) * p
        centres.append(c)
        sector.append(np.full(z, s))
        index.append(k)
        coupling.append(np.full(z, kind == "coupling"))
        pitch.append(np.full(z, p))
        delta.append(np.minimum(c - a, a + z * p - c))
        a += z * p
        bounds.append(a)
    c = np.concatenate(centres)
    nxt = np.append(c[1:], c[0] + 2.0 * pi)
    out = SectorLayout(
        c,
        np.concatenate(sector),
        np.concatenate(index),
        np.concatenate(coupling),
        np.concatenate(pitch),
        np.concatenate(delta),
        np.array(bounds),
        tuple(spec.kinds),
        0.5 * (c + nxt),
    )
    for name in ("centres", "sector", "index", "coupling", "pitch", "delta", "bounds", "spaces"):
        getattr(out, name).setflags(write=False)
    return out


def full_height(rigid: Gear) -> float:
    """Full tooth height of the rigid gear, root to tip, mm (``r_f - r_a`` internal, ``r_a - r_f`` external)."""
    return float(abs(rigid.r_f - rigid.r_a))


@dataclass(slots=True)
class TeethByHeight:
    """Rigid teeth of one tooth form at any height, built by :func:`make_gear` with a tip-radius override and cached.

    A shorter tooth keeps the flanks, fillets and root of the full one and is
    cut at another tip circle (docs/models.md 2.3: ``h_i = r_fix - r_ari``). Where
    the root fillet would reach the lowered tip circle, the fillet is made as
    large as still fits (and the fact recorded in :attr:`fillet_cut`).
    """

    base: ToothSpec
    full: Gear
    tol: float = constants.CHORD_TOL
    _cache: dict = field(default_factory=dict, repr=False)
    fillet_cut: dict = field(default_factory=dict)

    @property
    def height(self) -> float:
        return full_height(self.full)

    def gear(self, h: float) -> Gear:
        """The rigid gear whose teeth are ``h`` high (``0 < h <= full``), mm."""
        key = round(float(h), 12)
        if key in self._cache:
            return self._cache[key]
        H = self.height
        if key >= H - 1e-12:
            g = self.full
        else:
            sp = self.base
            tip = self.full.r_f - key if sp.internal else self.full.r_f + key
            sp = replace(sp, tip_radius=tip)
            try:
                g = make_gear(sp, self.tol)
            except DesignError as e:
                if not e.field.endswith("fillet_coef"):
                    raise
                lo, hi = 0.0, sp.fillet_coef
                for _ in range(30):  # largest fillet that still meets the lowered tip: bisection to ~1e-9 m
                    mid = 0.5 * (lo + hi)
                    try:
                        make_gear(replace(sp, fillet_coef=mid), self.tol)
                        lo = mid
                    except DesignError:
                        hi = mid
                g = make_gear(replace(sp, fillet_coef=lo), self.tol)
                self.fillet_cut[key] = lo
        self._cache[key] = g
        return g

    def polygon(self, h: float) -> np.ndarray:
        """One tooth ``(n, 2)`` in the tooth frame (centred on +x), closed through the body, counter-clockwise."""
        return self.gear(h).tooth_polygon()


def _core(g: Gear) -> np.ndarray:
    """The tooth from root-circle end to root-circle end, increasing angle, tooth frame (the root arcs cut off)."""
    half = g.half_period
    R = np.hypot(half[:, 0], half[:, 1])
    on_root = np.nonzero(np.abs(R - g.r_f) <= 1e-9 * g.r_f)[0]
    end = int(on_root[0]) if on_root.size else len(half) - 1
    half = half[: end + 1]
    mirror = half[::-1] * np.array([1.0, -1.0])
    return np.concatenate([mirror[:-1], half])


def _core_band(g: Gear, tol: float) -> np.ndarray:
    """As :func:`_core`, in a symmetric chord band of ``tol`` (docs/models.md appendix A): the exact pieces of one pitch less its root arcs."""
    ps = list(g.pieces)

    def on_root(p):
        return p.kind == "arc" and abs(p.radius - g.r_f) <= 1e-9 * g.r_f and float(np.hypot(*p.center)) <= 1e-9 * g.r_f

    while ps and on_root(ps[0]):
        ps.pop(0)
    while ps and on_root(ps[-1]):
        ps.pop()
    pts = [band_points(p, tol) for p in ps]
    return np.concatenate([x[:-1] for x in pts] + [pts[-1][-1:]])


def sectored_outline(layout: SectorLayout, teeth: TeethByHeight, heights: np.ndarray, band: bool = False) -> np.ndarray:
    """The toothed boundary of the whole sectored rigid gear, ``(M, 2)``, counter-clockwise, closed implicitly.

    Tooth ``i`` (its flanks, fillets and tip at height ``heights[i]``) is
    turned to ``layout.centres[i]``; neighbouring teeth are joined by root
    arcs. A height below :data:`MIN_HEIGHT_COEF` m leaves the tooth out.
    With ``band`` (the exports) every curve is drawn in the symmetric chord
    band of the teeth's tolerance (:mod:`wgcad.profiles.band`: the error
    split either side of the curve) instead of chords through points of it
    (one-sided: the polygons the clearance engine's bounds assume).

    Raises
    ------
    DesignError
        Teeth of neighbouring pitches overlap at the root (``sectors.pitch_z``).
    """
    r_f = teeth.full.r_f
    m = teeth.base.module
    keep = np.nonzero(np.asarray(heights) >= MIN_HEIGHT_COEF * m)[0]
    cores = [
        (layout.centres[i], _core_band(teeth.gear(heights[i]), teeth.tol) if band else _core(teeth.gear(heights[i])))
        for i in keep
    ]
    pieces = []
    for j, (c, core) in enumerate(cores):
        pts = rotate(core, c)
        pieces.append(pts)
        c_next, core_next = cores[(j + 1) % len(cores)]
        a0 = c + float(np.arctan2(core[-1, 1], core[-1, 0]))
        a1 = c_next + float(np.arctan2(core_next[0, 1], core_next[0, 0]))
        if j == len(cores) - 1:
            a1 += 2.0 * pi
        if not a1 > a0:
            raise DesignError(
                "sectors.pitch_z",
                f"teeth at {np.rad2deg(c):.3f} and {np.rad2deg(c_next):.3f} deg overlap at the root circle",
            )
        arc = (
            band_points(pc.arc((0.0, 0.0), r_f, a0, a1), teeth.tol)
            if band
            else arc_points((0.0, 0.0), r_f, a0, a1, teeth.tol)
        )
        pieces.append(arc[1:-1])
    out = np.concatenate(pieces)
    keep_pt = np.ones(len(out), dtype=bool)
    keep_pt[1:] = np.hypot(*np.diff(out, axis=0).T) > constants.DUPLICATE_TOL
    out = np.ascontiguousarray(out[keep_pt])
    out.setflags(write=False)
    return out


def sectored_gear_outline(
    layout: SectorLayout, teeth: TeethByHeight, coupling_heights: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Heights of every tooth (coupling teeth from ``coupling_heights`` per sector position, the rest full) and the outline.

    Returns
    -------
    heights : (N,) float, mm
    outline : (M, 2) float
    """
    H = teeth.height
    h = np.full(layout.n_teeth, H)
    ch = np.asarray(coupling_heights, dtype=float)
    sel = layout.coupling
    h[sel] = ch[layout.index[sel]]
    return h, sectored_outline(layout, teeth, h)
