"""The ``[sectors]`` table: a sectored rigid gear of a discrete-motion drive, its layout rules and heights (docs/models.md 2.3)."""

from __future__ import annotations

from dataclasses import dataclass, fields

from ..errors import DesignError, close_matches
from ..numbers import read_float, read_int
from .rules import key as _key

__all__ = ["SectorsSpec", "KINDS", "HEIGHT_MODES", "validate_sectors", "sector_pitch_z"]

#: sector kinds: "transmission" sectors have a pitch other than the flexspline's
#: (the output moves), "coupling" sectors the flexspline's pitch (it dwells)
KINDS = ("transmission", "coupling")
#: which coupling-tooth heights are built: the closed form of docs/models.md 2.3, the
#: simulated ones, full height everywhere, or the design's own ``heights_mm``
HEIGHT_MODES = ("closed_form", "simulated", "full", "list")

#: relative tolerance of the fill rule (sum of tooth count x pitch = 2 pi):
#: far above float rounding of a few dozen additions, far below one pitch
_FILL_TOL = 1e-9


@dataclass(frozen=True, slots=True)
class SectorsSpec:
    """``[sectors]``: the rigid gear built from sectors (docs/models.md 2.3), listed counter-clockwise.

    Every sector's teeth sit at its own angular pitch ``2 pi / pitch_z``; each
    tooth owns one pitch of arc, centred on it, so a sector spans
    ``teeth * 2 pi / pitch_z`` and two neighbouring teeth of different
    sectors are half of each pitch apart. The rigid tooth form is the one
    of ``[rigid]`` with ``drive.z_rigid`` (its radii hold in every sector).

    Attributes
    ----------
    kinds : tuple of str
        ``"transmission"`` or ``"coupling"``, one per sector.
    teeth : tuple of int
        Teeth in each sector.
    pitch_z : tuple of float, optional
        Pitch of each sector as the tooth count of a whole gear of that pitch
        (pitch ``2 pi / pitch_z``); default ``drive.z_rigid`` for transmission
        and ``drive.z_flex`` for coupling sectors.
    start_deg : float
        Angle where the first sector begins (its first tooth's pitch starts),
        counter-clockwise from +x.
    heights : str
        Coupling-tooth heights that are built: one of :data:`HEIGHT_MODES`.
    heights_mm : tuple of float, optional
        With ``heights = "list"``: the tooth heights (root to tip, mm) of one
        coupling sector from its first tooth on; every coupling sector gets them.
    tip_clearance_um : float
        Smallest tip clearance the simulated heights keep, um.
    assign : str
        How the closed form assigns a generator angle to a tooth:
        ``"boundary"`` (the major axis on the nearest sector boundary, as
        [S5]'s fig. 3 places the wave: the default) or ``"register"`` (where a
        flexspline tip first faces the tooth's tip, out of register, closest
        to the major axis).
    """

    kinds: tuple = _key(
        'kind of each sector, counter-clockwise: "transmission" or "coupling"',
        rule="2 x drive.waves sectors, kinds alternating, sectors a half turn apart identical",
        default=(),
    )
    teeth: tuple = _key(
        "teeth in each sector",
        unit="teeth",
        rule="one count per sector; sum of teeth / pitch_z over the sectors = 1 (the sectors fill the circle)",
        default=(),
    )
    pitch_z: tuple | None = _key(
        "pitch of each sector as the tooth count of a whole gear of that pitch",
        rule="coupling sectors: drive.z_flex; transmission sectors: any other",
        default=None,
        default_doc="drive.z_rigid (transmission), drive.z_flex (coupling)",
    )
    start_deg: float = _key(
        "angle where the first sector begins, counter-clockwise from +x",
        unit="deg",
        lo=-360.0,
        hi=360.0,
        why="one turn either way",
        default=0.0,
    )
    heights: str = _key(
        "coupling-tooth heights that are built", rule="closed_form | simulated | full | list", default="closed_form"
    )
    heights_mm: tuple | None = _key(
        'with heights = "list": tooth heights (root to tip) of one coupling sector from its first tooth on',
        unit="mm",
        rule="one per coupling tooth, each > 0 and at most the full tooth height",
        default=None,
    )
    tip_clearance_um: float = _key(
        "smallest tip clearance the simulated heights keep",
        unit="um",
        lo=0.0,
        hi=1000.0,
        hi_open=True,
        why="not negative; a millimetre of tip clearance leaves no tooth of a fine-module sector gear",
        default=10.0,
    )
    assign: str = _key(
        "how the closed form assigns a generator angle to a tooth", rule="boundary | register", default="boundary"
    )

    @property
    def active(self) -> bool:
        """Whether the design has a sectored rigid gear (a ``[sectors]`` table with sectors)."""
        return len(self.kinds) > 0

    @classmethod
    def from_table(cls, table: str, data) -> SectorsSpec:
        """Build from the TOML table (lists become tuples); types checked, rules by :func:`validate_sectors`."""
        if not isinstance(data, dict):
            raise DesignError(table, f"must be a table [{table}], got {type(data).__name__}")
        known = [f.name for f in fields(cls)]
        for key in data:
            if key not in known:
                near = close_matches(key, known)
                hint = f"; did you mean '{near[0]}'?" if near else f"; valid keys: {', '.join(known)}"
                raise DesignError(f"{table}.{key}", f"unknown key{hint}")
        for key in ("kinds", "teeth"):
            if key not in data:
                raise DesignError(f"{table}.{key}", "is required")
        kw = {}
        kw["kinds"] = _list(table, "kinds", data["kinds"], str)
        kw["teeth"] = _list(table, "teeth", data["teeth"], int)
        if "pitch_z" in data:
            kw["pitch_z"] = tuple(float(v) for v in _list(table, "pitch_z", data["pitch_z"], float))
        if "heights_mm" in data:
            kw["heights_mm"] = tuple(float(v) for v in _list(table, "heights_mm", data["heights_mm"], float))
        for key, tp in (("start_deg", float), ("tip_clearance_um", float), ("heights", str), ("assign", str)):
            if key in data:
                kw[key] = _scalar(table, key, data[key], tp)
        return cls(**kw)


def _scalar(table, key, value, tp):
    where = f"{table}.{key}"
    if tp is float:
        return read_float(where, value)
    if tp is int:
        return read_int(where, value)
    if not isinstance(value, str):
        raise DesignError(where, f"must be a string, got {type(value).__name__} {value!r}")
    return value


def _list(table, key, value, tp) -> tuple:
    if not isinstance(value, list) or not value:
        raise DesignError(f"{table}.{key}", f"must be a non-empty list, got {value!r}")
    return tuple(_scalar(table, f"{key}[{i}]", v, tp) for i, v in enumerate(value))


def sector_pitch_z(spec: SectorsSpec, z_flex: int, z_rigid: int) -> tuple:
    """Pitch of every sector as a whole gear's tooth count (``pitch_z`` or the defaults of :class:`SectorsSpec`)."""
    if spec.pitch_z is not None:
        return spec.pitch_z
    return tuple(float(z_rigid if k == "transmission" else z_flex) for k in spec.kinds)


def validate_sectors(spec: SectorsSpec, z_flex: int, z_rigid: int, waves: int) -> SectorsSpec:
    """Check the layout rules of a sectored rigid gear; return ``spec`` or raise :class:`DesignError`.

    Rules (docs/models.md 2.3): known kinds, both kinds present, alternating; as
    many sectors as ``2 waves`` so each wave meets one sector of each kind;
    sectors a half turn apart (``waves`` apart in the list) identical; coupling
    pitch equal to the flexspline's, transmission pitch not; the sectors fill
    the circle exactly; heights settings consistent.
    """
    t = "sectors"
    if not spec.active:
        return spec
    n = len(spec.kinds)
    for i, k in enumerate(spec.kinds):
        if k not in KINDS:
            raise DesignError(f"{t}.kinds[{i}]", f"must be one of {', '.join(KINDS)}; got '{k}'")
    if n != 2 * waves:
        # one transmission and one coupling sector per wave: each wave end passes both kinds per wave period
        raise DesignError(
            f"{t}.kinds", f"must list 2 x drive.waves = {2 * waves} sectors (one of each kind per wave), got {n}"
        )
    if len(spec.teeth) != n:
        raise DesignError(f"{t}.teeth", f"must list one tooth count per sector ({n} kinds), got {len(spec.teeth)}")
    for i, z in enumerate(spec.teeth):
        if z < 2:
            raise DesignError(f"{t}.teeth[{i}]", f"must be at least 2 teeth, got {z}")
    for i in range(n):
        if spec.kinds[i] == spec.kinds[(i + 1) % n]:
            raise DesignError(
                f"{t}.kinds",
                f"sectors {i} and {(i + 1) % n} are both {spec.kinds[i]}: transmission and coupling sectors must alternate",
            )
    pz = sector_pitch_z(spec, z_flex, z_rigid)
    if len(pz) != n:
        raise DesignError(f"{t}.pitch_z", f"must list one pitch per sector ({n}), got {len(pz)}")
    for i, p in enumerate(pz):
        if not p > 0:
            raise DesignError(f"{t}.pitch_z[{i}]", f"must be > 0, got {p:g}")
    if z_flex % waves:
        # opposite sectors identical only mesh alike if the flexspline is too
        raise DesignError(
            "drive.z_flex",
            f"must be a multiple of drive.waves = {waves} for a sectored rigid gear (opposite sectors identical), got {z_flex}",
        )
    step = n // waves
    for i in range(n):
        j = (i + step) % n
        if (spec.kinds[i], spec.teeth[i], pz[i]) != (spec.kinds[j], spec.teeth[j], pz[j]):
            raise DesignError(
                f"{t}.teeth",
                f"sectors {i} and {j} lie a wave apart and must be identical (kind, teeth, pitch): "
                f"{spec.kinds[i]} {spec.teeth[i]} x 2pi/{pz[i]:g} vs {spec.kinds[j]} {spec.teeth[j]} x 2pi/{pz[j]:g}",
            )
    for i, (k, p) in enumerate(zip(spec.kinds, pz)):
        if k == "coupling" and abs(p - z_flex) > 1e-9 * z_flex:
            raise DesignError(
                f"{t}.pitch_z[{i}]",
                f"a coupling sector has the flexspline's pitch: pitch_z = drive.z_flex = {z_flex}, got {p:g}",
            )
        if k == "transmission" and abs(p - z_flex) <= 1e-9 * z_flex:
            raise DesignError(
                f"{t}.pitch_z[{i}]",
                f"a transmission sector needs a pitch other than the flexspline's (pitch_z != {z_flex}); "
                "with equal pitch it is a coupling",
            )
    cover = sum(z / p for z, p in zip(spec.teeth, pz))  # in turns: sum of teeth x pitch / 2 pi
    if abs(cover - 1.0) > _FILL_TOL:
        detail = " + ".join(f"{z} x 360/{p:g}" for z, p in zip(spec.teeth, pz))
        raise DesignError(f"{t}.teeth", f"sectors must fill the circle: {detail} = {360.0 * cover:.4f} deg, not 360")
    _choice(f"{t}.heights", spec.heights, HEIGHT_MODES)
    _choice(f"{t}.assign", spec.assign, ("boundary", "register"))
    if spec.heights == "list":
        zc = [z for k, z in zip(spec.kinds, spec.teeth) if k == "coupling"][0]
        if spec.heights_mm is None or len(spec.heights_mm) != zc:
            got = "none" if spec.heights_mm is None else len(spec.heights_mm)
            raise DesignError(
                f"{t}.heights_mm", f'heights = "list" needs one height per coupling tooth ({zc}), got {got}'
            )
        for i, h in enumerate(spec.heights_mm):
            if not h > 0:
                raise DesignError(f"{t}.heights_mm[{i}]", f"must be > 0 mm, got {h:g}")
    elif spec.heights_mm is not None:
        raise DesignError(f"{t}.heights_mm", f'is used only with heights = "list", not "{spec.heights}"; remove it')
    if not 0.0 <= spec.tip_clearance_um < 1000.0:
        raise DesignError(f"{t}.tip_clearance_um", f"must be in [0, 1000) um, got {spec.tip_clearance_um:g}")
    return spec


def _choice(where: str, value: str, choices) -> None:
    if value not in choices:
        raise DesignError(where, f"must be one of {', '.join(choices)}; got '{value}'")
