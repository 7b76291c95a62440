"""Design table ``[supports]``: how the loaded model holds each member (flexspline, rigid gear, cam) and whether the rim
is spatial (docs/models.md 4.2), units in the key names."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from ..errors import DesignError, close_matches
from ..numbers import read_float
from .rules import key as _key

__all__ = ["SupportsSpec", "HELD"]

#: a support stiffness of ``inf`` (TOML ``inf``) holds the freedom; 0 leaves it free (docs/models.md 4.2)
HELD = math.inf
#: the largest finite stiffness a design may give, N/mm or N m/rad: beyond it the contact compliances are lost
#: in round-off against the support's and ``inf`` says what is meant
_MAX_STIFFNESS = 1e12
_WHY = "0 floats, inf holds; a finite stiffness up to 1e12 (beyond it only round-off separates it from inf)"


def _stiffness(doc: str, unit: str, default, default_doc: str):
    return _key(
        doc, unit=unit, lo=0.0, hi=_MAX_STIFFNESS, why=_WHY, default=default, default_doc=default_doc, inf_ok=True
    )


@dataclass(frozen=True)
class SupportsSpec:
    """``[supports]``: the rigid-body freedoms of the members of the loaded drive and what holds them.

    [S4]'s system (1) gives the rigid gear, the flexspline and the cam elastic supports (its ``C_1 ... C_3``) and
    the bearing's outer ring its own freedoms; [S1]'s model is spatial (forces along the face width, the ring's
    tilts). Each stiffness here is one of those supports: 0 leaves the freedom free, ``inf`` holds it. A key left
    out takes the default its documentation names (derived from the parts that carry the member, or the limit a
    designer can defend, docs/models.md 4.2).
    """

    rim: str = _key(
        "the rim's model along the face: spatial (sections coupled by the cup's tilt, bending and twist) or planar "
        "(one rigid motion for every section, the cup's twist in series)",
        choices=("spatial", "planar"),
        why="the two formulations of docs/models.md 4.2",
        default="spatial",
    )
    output_bearing_radial_n_per_mm: float = _stiffness(
        "radial stiffness of the output bearing that carries the flexspline's diaphragm",
        "N/mm",
        HELD,
        "inf (held: two orders stiffer than the cup that stands on it, docs/models.md 4.2)",
    )
    output_bearing_tilt_nm_per_rad: float = _stiffness(
        "tilting stiffness of the output bearing that carries the flexspline's diaphragm",
        "N m/rad",
        HELD,
        "inf (held: stiffer than the diaphragm in series with it, docs/models.md 4.2)",
    )
    diaphragm_tilt_nm_per_rad: float | None = _stiffness(
        "tilting stiffness of the cup's diaphragm about a diameter (the cup pivots on it)",
        "N m/rad",
        None,
        "an annular plate clamped at the cup's bolt circle, joined rigidly to the cup wall (docs/models.md 4.2)",
    )
    rigid_gear_radial_n_per_mm: float = _stiffness(
        "radial stiffness of the rigid gear's seat in the housing",
        "N/mm",
        HELD,
        "inf (held: the rigid gear is the housing's datum; every other support is measured from it)",
    )
    rigid_gear_tilt_nm_per_rad: float = _stiffness(
        "tilting stiffness of the rigid gear's seat in the housing",
        "N m/rad",
        HELD,
        "inf (held, as its radial seat)",
    )
    rigid_gear_seat_mm: float | None = _key(
        "axial position of the rigid gear's seat (the plane it tilts about), from the open end",
        unit="mm",
        lo=-1e4,
        hi=1e4,
        why="a sanity bound: within 10 m of the teeth",
        default=None,
        default_doc="the middle of the face width",
    )
    cam_radial_n_per_mm: float = _stiffness(
        "radial stiffness of the wave generator's support (its input shaft and bearings, or coupling)",
        "N/mm",
        HELD,
        "inf (held on its shaft, the cam of [S1] and [S4]; 0 for a generator floating on an Oldham coupling)",
    )

    @classmethod
    def from_table(cls, table: str, data) -> SupportsSpec:
        """Parse ``[supports]``: every stiffness a number >= 0 or ``inf``; ``rim`` a string."""
        if not isinstance(data, dict):
            raise DesignError(table, f"must be a table [{table}], got {type(data).__name__}")
        known = {f.name: f for f in fields(cls)}
        kw = {}
        for k, v in data.items():
            if k not in known:
                near = close_matches(k, known)
                hint = f"; did you mean '{near[0]}'?" if near else f"; valid keys: {', '.join(known)}"
                raise DesignError(f"{table}.{k}", f"unknown key{hint}")
            where = f"{table}.{k}"
            if k == "rim":
                if not isinstance(v, str):
                    raise DesignError(where, f"must be text ('spatial' or 'planar'), got {type(v).__name__}")
                kw[k] = v
                continue
            if isinstance(v, float) and v == math.inf and k != "rigid_gear_seat_mm":
                kw[k] = HELD
                continue
            kw[k] = read_float(where, v)
        return cls(**kw)

    def stiffness(self, key: str) -> float | None:
        """A stiffness in the model's units (N/mm, N mm/rad) from the key ``key`` (N/mm, N m/rad)."""
        v = getattr(self, key)
        if v is None:
            return None
        return 1e3 * v if key.endswith("_nm_per_rad") else float(v)
