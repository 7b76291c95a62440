"""Sweep specification files: the base design, parameters (distributions or grids), figures, samples, seed, limits.

A sweep spec is TOML, validated like a design (one-line errors naming the
field and the rule, :class:`~wgcad.errors.DesignError`, exit 2)::

    [sweep]
    name = "D2 tolerance Monte Carlo"
    design = "d2_imperfect.toml"      # relative to this file
    samples = 10000                   # random draws (per grid point)
    seed = 1

    [figures]
    record = ["ke_pp_arcsec", "entry_gap_um@500Nm"]

    [parameters.imperfections.flex_runout_um]
    distribution = "normal"
    mean = 75.0
    sd = 12.5

    [parameters.generator.w0_coef]
    grid = [1.0, 1.1, 1.2]

    [limits]
    ke_pp_arcsec = { max = 600.0 }

Parameters are design keys (``table.key``, their units in their names and in
docs/design-keys.md); every sampled design is checked by the design rules
(:func:`wgcad.design.with_changes`), and a refused one is a recorded sample,
not an error of the spec.
"""

from __future__ import annotations

import hashlib
import json
import tomllib
from dataclasses import dataclass, fields
from pathlib import Path

from ..design.files import parse_toml, read_design_text
from ..design.rules import key_meta
from ..design.schema import TABLES, base_type, parse_design
from ..errors import DesignError, InputFileError, close_matches
from ..numbers import read_float, show_value
from .recorded import check_figures

__all__ = ["Parameter", "SweepSpec", "parse_spec", "load_spec", "MAX_SAMPLES", "DISTRIBUTIONS"]

#: largest number of samples of one sweep: 1e8 rows of ~100 bytes is 10 GB of results, already a
#: cluster job; beyond, split the study
MAX_SAMPLES = 100_000_000
DISTRIBUTIONS = ("normal", "uniform", "grid")
_TOP = ("sweep", "figures", "parameters", "limits")
_SWEEP_KEYS = ("name", "design", "samples", "seed", "batch")
_FIG_KEYS = ("record", "audit_step_deg", "audit_sections", "load_sections", "ke_per_mesh", "ke_table")
#: ``figures.ke_table``: one KE contact table per worker for the sweep's largest amplitudes, or one per sample
KE_TABLES = ("shared", "per_sample")
_PARAM_KEYS = {
    "normal": ("distribution", "mean", "sd"),
    "uniform": ("distribution", "lo", "hi"),
    "grid": ("distribution", "values", "grid"),
}


@dataclass(frozen=True)
class Parameter:
    """One varied design key: ``table.key`` and how it varies.

    ``kind`` is ``normal`` (``a`` mean, ``b`` standard deviation),
    ``uniform`` (``a`` lowest, ``b`` highest) or ``grid`` (``values``).
    """

    name: str
    table: str
    key: str
    kind: str
    a: float = 0.0
    b: float = 0.0
    values: tuple = ()

    @property
    def random(self) -> bool:
        return self.kind != "grid"

    @property
    def phase(self) -> bool:
        """An angle whose effect is periodic (phases, installation angles): summarised as a circle."""
        return self.key.endswith("_phase_deg") or self.key.endswith("_angle_deg")

    def reach(self) -> float:
        """The largest value the parameter takes in practice: the grid's or range's top, mean + 6 sd (P ~ 1e-9)."""
        if self.kind == "normal":
            return self.a + 6.0 * self.b
        if self.kind == "uniform":
            return self.b
        return max(float(v) for v in self.values)


@dataclass(frozen=True)
class SweepSpec:
    """A validated sweep specification."""

    name: str
    design_path: str
    design_data: dict
    parameters: tuple
    record: tuple
    samples: int
    seed: int
    limits: dict
    batch: int = 0
    audit_step_deg: float = 0.5
    audit_sections: int = 3
    load_sections: int = 3
    ke_per_mesh: int = 16
    ke_table: str = "shared"
    source: str = "<memory>"

    @property
    def grid(self) -> tuple:
        return tuple(p for p in self.parameters if not p.random)

    @property
    def random(self) -> tuple:
        return tuple(p for p in self.parameters if p.random)

    @property
    def grid_points(self) -> int:
        n = 1
        for p in self.grid:
            n *= len(p.values)
        return n

    @property
    def total(self) -> int:
        """Samples in all: grid points times random draws per point."""
        return self.grid_points * self.samples

    def fingerprint(self) -> str:
        """Hash of everything that decides the samples and their results (not the limits, not the batch size)."""
        doc = {
            "design": self.design_data,
            "parameters": [p.__dict__ for p in self.parameters],
            "record": list(self.record),
            "samples": self.samples,
            "seed": self.seed,
            "settings": [self.audit_step_deg, self.audit_sections, self.load_sections, self.ke_per_mesh, self.ke_table],
        }
        return hashlib.sha256(json.dumps(doc, sort_keys=True, default=str).encode()).hexdigest()[:16]

    def payload(self) -> dict:
        """What a task needs, small and picklable (the design as data: remote workers need not see the file)."""
        return {
            "design": self.design_data,
            "parameters": self.parameters,
            "record": self.record,
            "samples": self.samples,
            "seed": self.seed,
            "grid_shape": tuple(len(p.values) for p in self.grid),
            "audit_step_deg": self.audit_step_deg,
            "audit_sections": self.audit_sections,
            "load_sections": self.load_sections,
            "ke_per_mesh": self.ke_per_mesh,
            "ke_table": self.ke_table,
            "fingerprint": self.fingerprint(),
        }


def _unknown(where: str, keys, known) -> None:
    for k in keys:
        if k not in known:
            near = close_matches(str(k), known)
            hint = f"; did you mean '{near[0]}'?" if near else f"; valid keys: {', '.join(known)}"
            raise DesignError(f"{where}.{k}" if where else str(k), f"unknown key{hint}")


def _number(where: str, v) -> float:
    return read_float(where, v)


def _whole(where: str, v, lo: int, hi: int) -> int:
    if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
        raise DesignError(where, f"must be a whole number in [{lo}, {hi}], got {show_value(v)}")
    return v


def _field_types() -> dict:
    """``{table: {key: (base type, choices)}}`` of every design key (from the design schema)."""
    out = {}
    for t, cls in TABLES.items():
        if hasattr(cls, "from_table"):  # tables with lists (sectors) cannot be swept key by key
            continue
        out[t] = {f.name: (base_type(f.type)[0], key_meta(f).get("choices")) for f in fields(cls)}
    return out


def _parameter(name: str, table: str, key: str, d) -> Parameter:
    where = f"parameters.{name}"
    types = _field_types()
    if table not in types:
        near = close_matches(table, types)
        raise DesignError(
            where,
            "unknown design table" + (f"; did you mean '{near[0]}'?" if near else f"; tables: {', '.join(types)}"),
        )
    if key not in types[table]:
        near = close_matches(key, types[table])
        raise DesignError(where, f"not a key of [{table}]" + (f"; did you mean '{table}.{near[0]}'?" if near else ""))
    if table == "drive" and key == "name":
        raise DesignError(where, "the drive's name cannot be swept")
    if not isinstance(d, dict):
        raise DesignError(
            where, f"must be a table with distribution = normal/uniform or grid = [...], got {type(d).__name__}"
        )
    base, choices = types[table][key]
    kind = d.get("distribution", "grid" if ("grid" in d or "values" in d) else None)
    if kind not in DISTRIBUTIONS:
        raise DesignError(f"{where}.distribution", f"must be one of {', '.join(DISTRIBUTIONS)}; got {kind!r}")
    _unknown(where, d, _PARAM_KEYS[kind])
    if kind == "grid":
        if "grid" in d and "values" in d:
            raise DesignError(where, "give grid or values, not both")
        vals = d.get("grid", d.get("values"))
        if not isinstance(vals, list) or not vals or len(vals) > 100_000:
            raise DesignError(f"{where}.grid", f"must be a list of 1 to 100000 values, got {vals!r}")
        out = []
        for i, v in enumerate(vals):
            w = f"{where}.grid[{i}]"
            if base is str:
                if not isinstance(v, str) or (choices and v not in choices):
                    raise DesignError(w, f"must be one of {', '.join(choices or ())}; got {v!r}")
            elif base is int:
                v = _whole(w, v, -(10**9), 10**9)
            else:
                v = _number(w, v)
            out.append(v)
        if len(set(out)) != len(out):
            raise DesignError(f"{where}.grid", "values repeat; each grid value once")
        return Parameter(name, table, key, "grid", values=tuple(out))
    if base is not float:
        raise DesignError(
            where,
            f"{'a whole-number' if base is int else 'a text'} key: give it a grid of values, not a {kind} distribution",
        )
    if kind == "normal":
        for k in ("mean", "sd"):
            if k not in d:
                raise DesignError(f"{where}.{k}", "is required for a normal distribution")
        mean, sd = _number(f"{where}.mean", d["mean"]), _number(f"{where}.sd", d["sd"])
        if not sd > 0:
            raise DesignError(f"{where}.sd", f"must be > 0, got {sd:g}")
        return Parameter(name, table, key, "normal", mean, sd)
    for k in ("lo", "hi"):
        if k not in d:
            raise DesignError(f"{where}.{k}", "is required for a uniform distribution")
    lo, hi = _number(f"{where}.lo", d["lo"]), _number(f"{where}.hi", d["hi"])
    if not hi > lo:
        raise DesignError(f"{where}.hi", f"must be > lo = {lo:g}, got {hi:g}")
    return Parameter(name, table, key, "uniform", lo, hi)


def _parameters(data) -> tuple:
    if not isinstance(data, dict) or not data:
        raise DesignError("parameters", "at least one parameter is required ([parameters.TABLE.KEY])")
    out = []
    for top, v in data.items():
        if "." in top:  # [parameters."table.key"]
            table, _, key = top.partition(".")
            out.append(_parameter(top, table, key, v))
            continue
        if not isinstance(v, dict) or not v or not all(isinstance(x, dict) for x in v.values()):
            raise DesignError(
                f"parameters.{top}", "expected [parameters.TABLE.KEY] tables, e.g. [parameters.generator.w0_coef]"
            )
        for key, d in v.items():
            out.append(_parameter(f"{top}.{key}", top, key, d))
    if len(out) > 64:
        raise DesignError("parameters", f"at most 64 parameters, got {len(out)}")
    return tuple(out)


def parse_spec(
    data: dict, source: str = "<memory>", base_dir: Path | None = None, design_data: dict | None = None
) -> SweepSpec:
    """Build and validate a :class:`SweepSpec` from a TOML dict.

    ``design_data`` (the base design as a TOML dict) is read from ``sweep.design``
    (relative to ``base_dir``) when not given.
    """
    if not isinstance(data, dict):
        raise DesignError("<file>", "must be a TOML document with tables")
    _unknown("", data, _TOP)
    sw = data.get("sweep")
    if not isinstance(sw, dict):
        raise DesignError("sweep", "table [sweep] is required (name, design, samples, seed)")
    _unknown("sweep", sw, _SWEEP_KEYS)
    for k in ("design", "seed"):
        if k not in sw:
            raise DesignError(f"sweep.{k}", "is required")
    name = sw.get("name", "sweep")
    if not isinstance(name, str) or not 1 <= len(name) <= 200 or "\n" in name:
        raise DesignError("sweep.name", "must be 1 to 200 characters, one line")
    seed = _whole("sweep.seed", sw["seed"], 0, 2**63 - 1)
    batch = _whole("sweep.batch", sw.get("batch", 0), 0, 1_000_000)
    dpath, design_data = _base_design(sw["design"], base_dir, design_data)
    base = parse_design(design_data, source=dpath)  # the base design must pass the rules itself
    params = _parameters(data.get("parameters"))
    seen = set()
    for p in params:
        if (p.table, p.key) in seen:
            raise DesignError(f"parameters.{p.name}", "given twice")
        seen.add((p.table, p.key))
    samples = _samples(sw, params)
    fig = data.get("figures")
    if not isinstance(fig, dict):
        raise DesignError("figures", "table [figures] is required (record = [...])")
    _unknown("figures", fig, _FIG_KEYS)
    rec = fig.get("record")
    if not isinstance(rec, list) or not rec or not all(isinstance(r, str) for r in rec):
        raise DesignError("figures.record", 'must be a non-empty list of figure names, e.g. ["ke_pp_arcsec"]')
    if len(set(rec)) != len(rec):
        raise DesignError("figures.record", "a figure is named twice")
    step = _number("figures.audit_step_deg", fig.get("audit_step_deg", 0.5))
    if not 0.01 <= step <= 10.0:
        raise DesignError("figures.audit_step_deg", f"must be in [0.01, 10] degrees, got {step:g}")
    kt = fig.get("ke_table", "shared")
    if kt not in KE_TABLES:
        raise DesignError("figures.ke_table", f"must be one of {', '.join(KE_TABLES)}; got {kt!r}")
    spec = SweepSpec(
        name=name,
        design_path=dpath,
        design_data=design_data,
        parameters=params,
        record=tuple(rec),
        samples=samples,
        seed=seed,
        limits={},
        batch=batch,
        audit_step_deg=step,
        audit_sections=_whole("figures.audit_sections", fig.get("audit_sections", 3), 1, 50),
        load_sections=_whole("figures.load_sections", fig.get("load_sections", 3), 1, 20),
        ke_per_mesh=_whole("figures.ke_per_mesh", fig.get("ke_per_mesh", 16), 1, 512),
        ke_table=kt,
        source=source,
    )
    check_figures(spec, base)
    limits = _limits(data.get("limits", {}), spec.record)
    return SweepSpec(**{**spec.__dict__, "limits": limits})


def _base_design(dpath, base_dir: Path | None, design_data: dict | None) -> tuple[str, dict]:
    """The base design's path and TOML dict: read from ``sweep.design`` (relative to ``base_dir``) unless given."""
    if not isinstance(dpath, str) or not dpath:
        raise DesignError("sweep.design", f"must be the path of a design file, got {dpath!r}")
    if design_data is not None:
        return dpath, design_data

    p = Path(dpath)
    if not p.is_absolute() and base_dir is not None:
        p = base_dir / p
    text = read_design_text(p)
    try:
        return str(p), tomllib.loads(text)
    except (tomllib.TOMLDecodeError, RecursionError) as e:
        raise InputFileError(f"{p}: not valid TOML ({e})") from None


def _samples(sw: dict, params) -> int:
    """``sweep.samples``: random draws per grid point, required with a distribution, 1 without; within MAX_SAMPLES
    in all."""
    has_random = any(p.random for p in params)
    if has_random and "samples" not in sw:
        # how many drives to draw is the study's first decision: not a default taken silently
        raise DesignError("sweep.samples", "required when a parameter has a distribution (random draws per grid point)")
    samples = _whole("sweep.samples", sw.get("samples", 1), 1, MAX_SAMPLES)
    if not has_random and samples != 1:
        raise DesignError(
            "sweep.samples", f"no parameter has a distribution, so every grid point has one sample; got {samples}"
        )
    npts = 1
    for p in params:
        if not p.random:
            npts *= len(p.values)
    if npts * samples > MAX_SAMPLES:
        raise DesignError(
            "sweep.samples", f"{npts} grid points x {samples} samples = {npts * samples} exceeds {MAX_SAMPLES}"
        )
    return samples


def _limits(lim, record) -> dict:
    """The ``[limits]`` table: ``{figure: (min or None, max or None)}`` of recorded figures."""
    if not isinstance(lim, dict):
        raise DesignError("limits", "must be a table of FIGURE = { min = ..., max = ... }")
    limits = {}
    for k, v in lim.items():
        where = f"limits.{k}"
        if k not in record:
            near = close_matches(k, record)
            raise DesignError(
                where, "not a recorded figure (figures.record)" + (f"; did you mean '{near[0]}'?" if near else "")
            )
        if not isinstance(v, dict) or not v:
            raise DesignError(where, "must be { min = ... } and/or { max = ... }")
        _unknown(where, v, ("min", "max"))
        lo = _number(f"{where}.min", v["min"]) if "min" in v else None
        hi = _number(f"{where}.max", v["max"]) if "max" in v else None
        if lo is not None and hi is not None and not hi > lo:
            raise DesignError(f"{where}.max", f"must be > min = {lo:g}, got {hi:g}")
        limits[k] = (lo, hi)
    return limits


def load_spec(path) -> SweepSpec:
    """Read, parse and validate a sweep spec file (and its base design).

    Raises
    ------
    InputFileError
        Missing, unreadable, not a regular file, too large, invalid TOML (spec or design).
    DesignError
        A rule of the spec or of the base design is broken.
    """
    p = Path(path)
    try:
        text = read_design_text(p)
    except InputFileError as e:  # the reader speaks of design files
        raise InputFileError(str(e).replace("design file", "sweep spec file")) from None
    return parse_spec(parse_toml(text, p, "a sweep spec"), source=str(p), base_dir=p.parent)
