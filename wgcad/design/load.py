"""Design tables of the elastic model: ``[material]``, ``[bearing]``, ``[load]`` (theory.md 4.1), units in the key names."""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import DesignError

__all__ = ["MaterialSpec", "BearingSpec", "LoadSpec", "validate_load_tables", "require_bearing"]


@dataclass(frozen=True)
class MaterialSpec:
    """``[material]``: the flexspline and bearing material and the rim's bending section."""

    youngs_modulus_gpa: float = 206.0  # steel
    poisson: float = 0.3
    #: thickness of a plain ring as stiff in bending as the toothed rim, mm;
    #: default rim_thickness + 0.3 (tip - root radius) (docs/models.md 4.1: teeth
    #: add little bending stiffness because the spaces interrupt them)
    rim_equivalent_thickness_mm: float | None = None
    #: thickness of the cup wall between the toothed rim and the diaphragm, mm;
    #: default = flexspline.rim_thickness
    cup_wall_thickness_mm: float | None = None


@dataclass(frozen=True)
class BearingSpec:
    """``[bearing]``: the flexible bearing between cam and flexspline."""

    balls: int | None = None
    ball_diameter_mm: float | None = None
    width_mm: float | None = None
    outer_ring_thickness_mm: float | None = None  # under the raceway
    internal_clearance_um: float = 0.0  # radial gap at a ball inside the bearing
    fit_clearance_um: float = 0.0  # radial gap between the outer ring and the flexspline bore
    groove_conformity: float = 0.52  # groove radius / ball diameter


@dataclass(frozen=True)
class LoadSpec:
    """``[load]``: the operating load of the drive."""

    rated_torque_nm: float | None = None  # output torque the audit sweeps to by default
    cam_offset_um: float = 0.0  # radial offset e_h of the cam axis from the rigid gear's
    cam_offset_deg: float = 0.0  # its direction from the generator's major axis
    ball_phase_deg: float = 0.0  # angle of the first ball from the major axis


def _nonneg(where: str, value) -> None:
    if value is not None and value < 0:
        raise DesignError(where, f"must be >= 0, got {value:g}")


def _pos(where: str, value) -> None:
    if value is not None and not value > 0:
        raise DesignError(where, f"must be > 0, got {value:g}")


def validate_load_tables(d) -> None:
    """Field rules of the three tables (raises :class:`DesignError` naming the field)."""
    mat, br, ld = d.material, d.bearing, d.load
    _pos("material.youngs_modulus_gpa", mat.youngs_modulus_gpa)
    if not 0.0 <= mat.poisson < 0.5:
        raise DesignError("material.poisson", f"must be in [0, 0.5), got {mat.poisson:g}")
    _pos("material.rim_equivalent_thickness_mm", mat.rim_equivalent_thickness_mm)
    _pos("material.cup_wall_thickness_mm", mat.cup_wall_thickness_mm)
    if br.balls is not None and br.balls < 3:
        raise DesignError("bearing.balls", f"must be at least 3, got {br.balls}")
    for key in ("ball_diameter_mm", "width_mm", "outer_ring_thickness_mm"):
        _pos(f"bearing.{key}", getattr(br, key))
    for key in ("internal_clearance_um", "fit_clearance_um"):
        _nonneg(f"bearing.{key}", getattr(br, key))
    if not 0.5 < br.groove_conformity < 1.0:
        raise DesignError("bearing.groove_conformity", f"must be in (0.5, 1), got {br.groove_conformity:g}")
    _nonneg("load.rated_torque_nm", ld.rated_torque_nm)
    _nonneg("load.cam_offset_um", ld.cam_offset_um)


def require_bearing(d) -> BearingSpec:
    """The ``[bearing]`` table with every field the elastic model needs, or :class:`DesignError`."""
    br = d.bearing
    for key in ("balls", "ball_diameter_mm", "width_mm", "outer_ring_thickness_mm"):
        if getattr(br, key) is None:
            raise DesignError(f"bearing.{key}", "is required by the load model (wgcad audit --torque-nm)")
    return br
