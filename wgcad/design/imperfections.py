"""``[imperfections]``: gear run-out and eccentricity, cam mounting error, installation angles (docs/models.md 6.1, 6.2)."""

from __future__ import annotations

from dataclasses import dataclass, fields

from .rules import Rel, key

__all__ = ["ImperfectionsSpec"]


@dataclass(frozen=True)
class ImperfectionsSpec:
    """``[imperfections]``: manufacturing and mounting errors of a drive (all optional, default a perfect drive).

    Amplitudes in micrometres, phases and angles in degrees. Phases of a
    gear's errors are counted in that gear's own frame from its reference
    tooth (flexspline tooth 0, the rigid gear's space on +x at assembly);
    the cam phases from the cam's major axis (cam-borne), the flexspline's
    reference (flexspline-borne) or +x of the housing (stationary).
    """

    # first-harmonic run-out (docs/models.md 6.2): tooth i deviates along the pitch circle by
    # (F/2) sin(a_i + xi), a_i its angle in its gear; F is the kinematic-error tolerance F_g, F_b
    flex_runout_um: float = key(
        "flex runout (F_g)",
        unit="um",
        lo=0.0,
        hi=Rel("m/4 (in um)", lambda c: 250.0 * c["m"]),
        why="an amplitude (the phase carries the direction), at most a quarter module: beyond it the teeth no longer mesh",
        default=0.0,
    )
    flex_runout_phase_deg: float = key(
        "flex runout phase (xi_g)", unit="deg", lo=-360.0, hi=360.0, why="one turn either way", default=0.0
    )
    rigid_runout_um: float = key(
        "rigid runout (F_b)",
        unit="um",
        lo=0.0,
        hi=Rel("m/4 (in um)", lambda c: 250.0 * c["m"]),
        why="an amplitude (the phase carries the direction), at most a quarter module: beyond it the teeth no longer mesh",
        default=0.0,
    )
    rigid_runout_phase_deg: float = key(
        "rigid runout phase (xi_b)", unit="deg", lo=-360.0, hi=360.0, why="one turn either way", default=0.0
    )
    # geometric eccentricity (docs/models.md 6.1): the gear's pitch circle off its axis
    flex_eccentricity_um: float = key(
        "flex eccentricity (e_yr: tooth ring off the flexspline's bore)",
        unit="um",
        lo=0.0,
        hi=Rel("m/4 (in um)", lambda c: 250.0 * c["m"]),
        why="an amplitude (the phase carries the direction), at most a quarter module: beyond it the teeth no longer mesh",
        default=0.0,
    )
    flex_eccentricity_phase_deg: float = key(
        "flex eccentricity phase", unit="deg", lo=-360.0, hi=360.0, why="one turn either way", default=0.0
    )
    rigid_eccentricity_um: float = key(
        "rigid eccentricity (e_br: rigid gear off the drive axis)",
        unit="um",
        lo=0.0,
        hi=Rel("m/4 (in um)", lambda c: 250.0 * c["m"]),
        why="an amplitude (the phase carries the direction), at most a quarter module: beyond it the teeth no longer mesh",
        default=0.0,
    )
    rigid_eccentricity_phase_deg: float = key(
        "rigid eccentricity phase", unit="deg", lo=-360.0, hi=360.0, why="one turn either way", default=0.0
    )
    # cam mounting error, three components (docs/models.md 6.2)
    cam_offset_cam_um: float = key(
        "cam offset cam (e_h^h, rotating with the cam)",
        unit="um",
        lo=0.0,
        hi=Rel("m/4 (in um)", lambda c: 250.0 * c["m"]),
        why="an amplitude (the phase carries the direction), at most a quarter module: beyond it the teeth no longer mesh",
        default=0.0,
    )
    cam_offset_cam_phase_deg: float = key(
        "cam offset cam phase (f^h, from the cam's major axis)",
        unit="deg",
        lo=-360.0,
        hi=360.0,
        why="one turn either way",
        default=0.0,
    )
    cam_offset_flex_um: float = key(
        "cam offset flex (e_h^g, rotating with the flexspline)",
        unit="um",
        lo=0.0,
        hi=Rel("m/4 (in um)", lambda c: 250.0 * c["m"]),
        why="an amplitude (the phase carries the direction), at most a quarter module: beyond it the teeth no longer mesh",
        default=0.0,
    )
    cam_offset_flex_phase_deg: float = key(
        "cam offset flex phase (f^g)", unit="deg", lo=-360.0, hi=360.0, why="one turn either way", default=0.0
    )
    cam_offset_fixed_um: float = key(
        "cam offset fixed (e_h^b, stationary)",
        unit="um",
        lo=0.0,
        hi=Rel("m/4 (in um)", lambda c: 250.0 * c["m"]),
        why="an amplitude (the phase carries the direction), at most a quarter module: beyond it the teeth no longer mesh",
        default=0.0,
    )
    cam_offset_fixed_phase_deg: float = key(
        "cam offset fixed phase (f^b)", unit="deg", lo=-360.0, hi=360.0, why="one turn either way", default=0.0
    )
    # assembly levers: each gear's error pattern turned by this angle (docs/models.md 6.2)
    rigid_install_angle_deg: float = key(
        "rigid install angle", unit="deg", lo=-360.0, hi=360.0, why="one turn either way", default=0.0
    )
    flex_install_angle_deg: float = key(
        "flex install angle", unit="deg", lo=-360.0, hi=360.0, why="one turn either way", default=0.0
    )

    @property
    def amplitudes_um(self) -> dict:
        """Every amplitude, by key (um)."""
        return {f.name: getattr(self, f.name) for f in fields(self) if f.name.endswith("_um")}

    @property
    def any(self) -> bool:
        """True if any error amplitude is non-zero (the installation angles alone change nothing)."""
        return any(v != 0.0 for v in self.amplitudes_um.values())
