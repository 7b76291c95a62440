"""The elastic model of a whole drive built from its design: ring stiffness, bearing, tooth compliance, sections (docs/models.md 4.1)."""

from __future__ import annotations

from dataclasses import dataclass, field
from math import pi

import numpy as np

from wgcad.clearance.engine import Scene
from wgcad.design.load import require_bearing
from wgcad.errors import DesignError

from .bearing import FlexibleBearing, ball_contact
from .ring import Ring
from .supports import Supports, build_supports
from .tables import RingTables, ring_tables
from .teeth import ToothCompliance

__all__ = ["ElasticModel", "build_model"]


@dataclass(frozen=True, slots=True)
class ElasticModel:
    """Everything the contact solver needs that does not depend on the load.

    Attributes
    ----------
    drive : wgcad.drive.Drive
    scene : Scene
        The exact 2D clearance engine's static data (nominal drive).
    ring : Ring
        The rim as one ring at the generator's centre section (Ritz reduction, see :func:`build_model`).
    bearing : FlexibleBearing
    teeth : ToothCompliance
    zs : (S,) float
        Axial positions of the sections, mm from the open end.
    widths : (S,) float
        Face width each section stands for (trapezoid weights), mm.
    scales : (S,) float
        Coning factor ``W0(z)/W0`` of each section.
    cup_stiffness : float
        Torsional stiffness of the cup between the generator's centre plane and the diaphragm, N mm/rad (inf
        without coning data): what the planar model adds to the wind-up in series.
    torque_sign : float
        +1 when the load torque on the flexspline is counter-clockwise (working flank ``upper``).
    ei_parts : dict
        The bending-stiffness contributions, N mm^2 (reported).
    tables : RingTables
        The ring's influence and the nominal rim at the tooth and ball angles (what every solver pass reads).
    supports : Supports
        The members' freedoms and what holds them, the cup's fields (docs/models.md 4.2).
    """

    drive: object
    scene: Scene
    ring: Ring
    bearing: FlexibleBearing
    teeth: ToothCompliance
    zs: np.ndarray
    widths: np.ndarray
    scales: np.ndarray
    cup_stiffness: float
    torque_sign: float
    ei_parts: dict
    tables: RingTables
    supports: Supports

    @property
    def support_stiffness(self) -> np.ndarray:
        """Stiffness of each freedom of the contact problem (:attr:`Supports.names`): 0 free, inf held."""
        return self.supports.stiffness

    #: results reused between load states of this model (the tooth pairs measured at the nominal state)
    cache: dict = field(default_factory=dict, repr=False, compare=False)

    def section_law(self, i: int):
        """Nominal law of section ``i`` (one object per section, so loaded states can share its evaluations)."""
        key = ("section_law", i)
        if key not in self.cache:
            self.cache[key] = self.drive.law_at(float(self.zs[i])) if self.drive.coned else self.drive.law
        return self.cache[key]


def _coning(drive):
    g = drive.design.generator
    if g.cone_length is None:
        return None
    l_c, z_h = g.cone_length, g.generator_z
    return lambda z: (l_c - np.asarray(z, dtype=float)) / (l_c - z_h)


def _int_f2(f, a: float, b: float) -> float:
    """Integral of f(z)^2 over [a, b] (f linear: Simpson is exact)."""
    if b <= a:
        return 0.0
    m = 0.5 * (a + b)
    return float((b - a) / 6.0 * (f(a) ** 2 + 4.0 * f(m) ** 2 + f(b) ** 2))


def build_model(drive, sections: int = 3, rim: str | None = None, plate=None) -> ElasticModel:
    """The elastic model of ``drive`` from its ``[material]`` and ``[bearing]`` tables (docs/models.md 4.1).

    Ring stiffness by a Ritz reduction of the cup: the rim's displacement at
    axial position ``z`` is ``f(z)`` times the displacement at the generator's
    centre line (``f`` the coning law of docs/models.md 3.1, ``f = 1`` without
    coning), so a load at section ``z`` acts on the reduced ring with weight
    ``f(z)`` and the ring's bending stiffness is
    ``EI = E [h_eq^3/12 int_rim f^2 dz + t_cup^3/12 int_cup f^2 dz + b_o t_o^3/12]``:
    the toothed rim (equivalent thickness ``h_eq``), the plain cup wall up to
    the diaphragm, and the bearing's outer ring bending with it (merged with
    the flexspline: in contact where it carries load).

    ``plate``: the cup's diaphragm ``(r_i, r_o, h)`` (mm) its tilting
    stiffness is derived from, in place of ``[parts]``' geometric defaults
    (the rating passes the part set's sized one, wgcad.rating.plate_sizing).

    Raises
    ------
    DesignError
        Missing bearing data, external deformation (not modelled), or
        geometry that leaves no raceway.
    """
    d = drive.design
    if drive.external:
        raise DesignError(
            "drive.deformation", "the load model covers internal deformation (generator inside the flexspline) only"
        )
    if not (isinstance(sections, int) and sections >= 1):
        raise DesignError("sections", f"must be a whole number >= 1, got {sections!r}")
    br = require_bearing(d)
    mat = d.material
    E = mat.youngs_modulus_gpa * 1e3  # MPa = N/mm^2
    G = E / (2.0 * (1.0 + mat.poisson))
    flex = drive.flex
    h1 = d.flexspline.rim_thickness
    h_eq = mat.rim_equivalent_thickness_mm or h1 + 0.3 * abs(flex.r_a - flex.r_f)
    t_cup = mat.cup_wall_thickness_mm or h1
    bw = d.drive.face_width
    f = _coning(drive)
    if f is None:
        rim_w, cup = bw, 0.0
        f_of = lambda z: np.ones_like(np.asarray(z, dtype=float))  # noqa: E731
    else:
        rim_w = _int_f2(f, 0.0, bw)
        cup = _int_f2(f, bw, d.generator.cone_length)
        f_of = f
    parts = {
        "toothed_rim": E * h_eq**3 / 12.0 * rim_w,
        "cup_wall": E * t_cup**3 / 12.0 * cup,
        "bearing_outer_ring": E * br.width_mm * br.outer_ring_thickness_mm**3 / 12.0,
    }
    ring = Ring(drive.r_m, sum(parts.values()))
    e_prime = E / (1.0 - mat.poisson**2)
    race_r = drive.flex_rim_radius - br.outer_ring_thickness_mm
    if race_r - br.ball_diameter_mm <= 0:
        raise DesignError(
            "bearing.ball_diameter_mm",
            f"ball {br.ball_diameter_mm:g} mm does not fit inside the outer ring (raceway radius {race_r:g} mm)",
        )
    inner, outer = ball_contact(br.ball_diameter_mm, race_r, br.groove_conformity, e_prime)
    psi = np.deg2rad(d.load.ball_phase_deg) + 2.0 * pi * np.arange(br.balls) / br.balls
    bearing = FlexibleBearing(
        psi, 1e-3 * (br.internal_clearance_um + br.fit_clearance_um), inner.c + outer.c, max(inner.q, outer.q)
    )
    zs = drive.sections(sections)
    widths = np.full(1, bw) if sections == 1 else bw * np.diff(np.concatenate([[0.0], 0.5 * (zs[1:] + zs[:-1]), [bw]]))
    scene = Scene(drive)
    bending = d.load.tooth_compliance == "hertz_bending"
    teeth = ToothCompliance(E, mat.poisson, 0.5 * pi * d.drive.module, flex.r_f, drive.rigid.r_f, with_bending=bending)
    laws = [drive.law_at(float(z)) if drive.coned else drive.law for z in zs]
    tables = ring_tables(ring, d.drive.z_flex, psi, laws, drive.law)
    if rim is not None and rim not in ("spatial", "planar"):
        raise DesignError("supports.rim", f"must be 'spatial' or 'planar', got {rim!r}")
    spatial = None if rim is None else rim == "spatial"
    supports = build_supports(drive, zs, E, G, t_cup, d.supports, spatial, plate)
    k_cup = 1.0 / supports.cup_twist if supports.cup_twist > 0 else float("inf")
    return ElasticModel(
        drive,
        scene,
        ring,
        bearing,
        teeth,
        zs,
        widths,
        np.asarray(f_of(zs), dtype=float),
        float(k_cup),
        1.0 if scene.working == "upper" else -1.0,
        parts,
        tables,
        supports,
    )
