"""Design tables of the elastic model: ``[material]``, ``[bearing]``, ``[load]`` (docs/models.md 4.1), units in the key names."""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import DesignError
from .rules import key as _key

__all__ = ["MaterialSpec", "BearingSpec", "LoadSpec", "require_bearing"]


@dataclass(frozen=True, slots=True)
class MaterialSpec:
    """``[material]``: the flexspline and bearing material and the rim's bending section."""

    youngs_modulus_gpa: float = _key(
        "Young's modulus of the flexspline and bearing material (steel 206)",
        unit="GPa",
        lo=0.0,
        lo_open=True,
        hi=1200.0,
        why="above 0; no engineering material is stiffer than ~1200 GPa",
        default=206.0,
    )
    poisson: float = _key(
        "Poisson's ratio of the material",
        lo=0.0,
        hi=0.5,
        hi_open=True,
        why="a stable isotropic solid has 0 <= nu < 0.5",
        default=0.3,
    )
    #: thickness of a plain ring as stiff in bending as the toothed rim, mm;
    #: default rim_thickness + 0.3 (tip - root radius) (docs/models.md 4.1: teeth
    #: add little bending stiffness because the spaces interrupt them)
    rim_equivalent_thickness_mm: float | None = _key(
        "thickness of a plain ring as stiff in bending as the toothed rim",
        unit="mm",
        lo=0.0,
        lo_open=True,
        hi=100.0,
        why="a positive wall, at most the 100 mm no thin-ring model covers",
        default=None,
        default_doc="rim_thickness + 0.3 (tip - root radius)",
    )
    #: thickness of the cup wall between the toothed rim and the diaphragm, mm;
    #: default = flexspline.rim_thickness
    cup_wall_thickness_mm: float | None = _key(
        "thickness of the cup wall between toothed rim and diaphragm",
        unit="mm",
        lo=0.0,
        lo_open=True,
        hi=100.0,
        why="a positive wall, at most the 100 mm no thin-ring model covers",
        default=None,
        default_doc="flexspline.rim_thickness",
    )
    # ---- strength (wgcad rating; docs/models.md 10) ----
    ultimate_strength_mpa: float | None = _key(
        "tensile strength S_u of the flexspline steel",
        unit="MPa",
        lo=0.0,
        lo_open=True,
        hi=5000.0,
        why="positive; no steel is stronger than ~5000 MPa",
        default=None,
        default_doc="required by wgcad rating",
    )
    yield_strength_mpa: float | None = _key(
        "yield strength S_y of the flexspline steel (the static check of the peak stress)",
        unit="MPa",
        lo=0.0,
        lo_open=True,
        hi=5000.0,
        rule="at most ultimate_strength_mpa",
        why="positive; no steel is stronger than ~5000 MPa",
        default=None,
        default_doc="0.9 ultimate_strength_mpa (a quenched and tempered steel)",
    )
    endurance_limit_mpa: float | None = _key(
        "rotating-beam endurance limit S_e' of a polished specimen, before the modifying factors",
        unit="MPa",
        lo=0.0,
        lo_open=True,
        hi=2500.0,
        rule="below ultimate_strength_mpa",
        why="positive; below the strength",
        default=None,
        default_doc="0.5 ultimate_strength_mpa, at most 700 MPa (Shigley, steels)",
    )
    surface_finish: str = _key(
        "finish of the tooth roots (sets the surface factor k_a = a S_u^b, Shigley table 6-2)",
        choices=("ground", "machined", "hot_rolled", "forged"),
        default="machined",
    )
    reliability: float = _key(
        "share of parts that must reach the endurance limit (reliability factor k_e = 1 - 0.08 z)",
        lo=0.5,
        hi=0.99999,
        why="from the median to five nines, the range of the factor's normal model",
        default=0.99,
    )


@dataclass(frozen=True, slots=True)
class BearingSpec:
    """``[bearing]``: the flexible bearing between cam and flexspline."""

    balls: int | None = _key(
        "rolling bodies in the flexible bearing",
        lo=3,
        hi=1000,
        why="at least 3 to hold the ring; 1000 is beyond any flexible bearing",
        default=None,
        default_doc="required by the load model",
    )
    ball_diameter_mm: float | None = _key(
        "ball diameter",
        unit="mm",
        lo=0.0,
        lo_open=True,
        hi=200.0,
        why="positive; 200 mm is beyond any flexible bearing",
        default=None,
        default_doc="required by the load model",
    )
    width_mm: float | None = _key(
        "bearing width",
        unit="mm",
        lo=0.0,
        lo_open=True,
        hi=1000.0,
        why="positive; a sanity bound",
        default=None,
        default_doc="required by the load model",
    )
    outer_ring_thickness_mm: float | None = _key(
        "outer ring thickness under the raceway",
        unit="mm",
        lo=0.0,
        lo_open=True,
        hi=100.0,
        why="positive; a thin ring",
        default=None,
        default_doc="required by the load model",
    )
    internal_clearance_um: float = _key(
        "radial gap at a ball inside the bearing",
        unit="um",
        lo=0.0,
        hi=1000.0,
        why="a gap, not an interference; above 1 mm no bearing carries the cam",
        default=0.0,
    )
    fit_clearance_um: float = _key(
        "radial gap between the bearing outer ring and the flexspline bore",
        unit="um",
        lo=0.0,
        hi=1000.0,
        why="a gap, not an interference; above 1 mm the cam law is lost",
        default=0.0,
    )
    groove_conformity: float = _key(
        "groove radius / ball diameter",
        lo=0.5,
        lo_open=True,
        hi=1.0,
        hi_open=True,
        why="above 0.5 or the ball jams in its groove; below 1 for a groove at all",
        default=0.52,
    )
    # ---- friction (wgcad rating; docs/models.md 10.8) ----
    lubricant_viscosity_cst: float = _key(
        "kinematic viscosity of the bearing's lubricant (base oil) at the operating temperature, for Palmgren's "
        "viscous friction term",
        unit="mm^2/s",
        lo=0.0,
        lo_open=True,
        hi=10000.0,
        why="positive; above 10000 mm^2/s no rolling bearing runs",
        default=30.0,
        default_doc="30 (an ISO VG 32 oil near 40 C; assumed)",
    )
    viscous_friction_factor: float = _key(
        "Palmgren's lubrication factor f0 of the viscous friction term",
        lo=0.0,
        hi=20.0,
        why="not negative; Palmgren's table ends below 20",
        default=2.0,
        default_doc="2 (deep-groove ball bearing, oil bath or grease; Palmgren, as tabulated by Harris & Kotzalas)",
    )
    seal_torque_nmm: float = _key(
        "drag torque of the bearing's seals between its rings, as the seal's maker gives it",
        unit="N mm",
        lo=0.0,
        hi=1e5,
        why="not negative; 100 N m of seal drag is beyond any flexible bearing",
        default=0.0,
        default_doc="0 (no seals)",
    )


@dataclass(frozen=True, slots=True)
class LoadSpec:
    """``[load]``: the operating load of the drive."""

    rated_torque_nm: float | None = _key(
        "the design torque: the output torque the parts are sized for (bolts) and the load audit sweeps to by "
        "default; outputs call it design torque (design_torque_nm), not the rated torque of wgcad rating "
        "(docs/glossary.md)",
        unit="N m",
        lo=0.0,
        hi=1e7,
        why="not negative; 10 MN m is beyond any harmonic drive",
        default=None,
    )
    cam_offset_um: float = _key(
        "radial offset e_h of the cam axis from the rigid gear's",
        unit="um",
        lo=0.0,
        hi=10000.0,
        why="a magnitude (the direction is cam_offset_deg); 10 mm is far beyond any mounting error",
        default=0.0,
    )
    cam_offset_deg: float = _key(
        "direction of e_h from the generator's major axis",
        unit="deg",
        lo=-360.0,
        hi=360.0,
        why="one turn either way",
        default=0.0,
    )
    ball_phase_deg: float = _key(
        "angle of the first ball from the major axis",
        unit="deg",
        lo=-360.0,
        hi=360.0,
        why="one turn either way",
        default=0.0,
    )
    input_speed_rpm: float = _key(
        "input (wave generator) speed the bearing life is rated at",
        unit="rpm",
        lo=0.0,
        lo_open=True,
        hi=1e5,
        why="positive; 100000 rpm is beyond any flexible bearing",
        default=2000.0,
    )
    required_life_h: float = _key(
        "L10 life the wave-generator bearing must reach at the rated torque and input speed",
        unit="h",
        lo=0.0,
        lo_open=True,
        hi=1e7,
        why="positive; 1e7 h is over a thousand years",
        default=7000.0,
    )
    fatigue_safety_min: float = _key(
        "smallest Goodman safety factor of the flexspline the rated torque may leave",
        lo=1.0,
        hi=10.0,
        why="at least the Goodman line itself; 10 is beyond any design practice",
        default=1.0,
    )
    ratcheting_safety_min: float = _key(
        "smallest ratio of ratcheting torque to rated torque",
        lo=1.0,
        hi=10.0,
        why="the teeth must not skip at the rated torque; 10 is beyond any design practice",
        default=1.0,
    )
    output_inertia_kg_m2: float | None = _key(
        "moment of inertia on the output, for the first torsional natural frequency",
        unit="kg m^2",
        lo=0.0,
        lo_open=True,
        hi=1e6,
        why="positive; a sanity bound",
        default=None,
        default_doc="none: the frequency is not computed",
    )
    tooth_friction: float = _key(
        "Coulomb coefficient of friction of the tooth flanks (sliding and at rest)",
        lo=0.0,
        hi=0.5,
        why="not negative; above 0.5 the flanks are dry and galling, outside any lubricated gear",
        default=0.07,
        default_doc="0.07 (lubricated steel flanks in mixed lubrication, 0.05-0.1)",
    )
    tooth_compliance: str = _key(
        "what a tooth pair's compliance holds besides the flanks' Hertz approach",
        choices=("hertz_bending", "hertz"),
        why="[S1] writes the pair's approach lambda(Q) by Hertz alone; with both teeth's bending and shear it is "
        "the reading of docs/models.md 4.1",
        default="hertz_bending",
    )


def require_bearing(d) -> BearingSpec:
    """The ``[bearing]`` table with every field the elastic model needs, or :class:`DesignError`."""
    br = d.bearing
    for key in ("balls", "ball_diameter_mm", "width_mm", "outer_ring_thickness_mm"):
        if getattr(br, key) is None:
            raise DesignError(f"bearing.{key}", "is required by the load model (wgcad audit --torque-nm)")
    return br
