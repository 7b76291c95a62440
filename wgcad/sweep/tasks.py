"""A sweep task: a batch of whole samples computed in one worker process, with the heavy shared data built once per process.

What samples share is cached per process (:data:`_CACHE`, small LRU maps
keyed by a hash of what decides the object): the drive (tooth outlines) per
geometry, the KE contact table per geometry and cam-borne offset, the
elastic model per geometry and bearing; and the figures of the models that
do not see a sample's varied tables (the no-load audit of a tolerance
sample sees the nominal geometry: one audit serves them all). A Dask worker keeps its process
between tasks, so a Monte Carlo over tolerances builds them once per worker;
nothing heavy is shipped with a task (its payload is the spec as data).

Every object cached is a pure function of its key, so a result does not
depend on which process computed it or what it computed before: the same
sample gives the same bits on any worker (tests/test_sweep_dask.py).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import hashlib
import json
import math
import os
import threading
import time
from collections import OrderedDict

import numpy as np

from wgcad.units import ARCMIN_PER_RAD, ARCSEC_PER_RAD, UM_PER_MM

from ..accuracy import ke as K
from ..clearance.engine import AuditSettings, audit
from ..design.imperfections import ImperfectionsSpec
from ..design.schema import parse_design
from ..drive import build_drive
from ..errors import DesignError, ModelError, WgcadError
from ..placement.imperfect import Imperfections
from .recorded import parse_figure
from .sampling import envelope_amplitudes_um, sample_design_data, sample_values

__all__ = ["run_batch", "run_sample", "columns_of", "cache_info", "clear_cache", "noop"]

_AS = ARCSEC_PER_RAD
#: entries kept per kind: a grid study walks its grid point by point (samples of a point are
#: consecutive), so a few entries suffice; each D2 contact table is ~100 MB at most
_SIZES = {"base": 4, "drive": 4, "table": 3, "model": 2, "audit": 64, "load": 64}
_CACHE: dict = {k: OrderedDict() for k in _SIZES}
_LOCK = threading.RLock()
_STATS = {"built": 0, "hits": 0}


def _h(obj) -> str:
    return hashlib.sha256(json.dumps(obj, sort_keys=True, default=repr).encode()).hexdigest()[:20]


def _cached(kind: str, key: str, build):
    with _LOCK:
        c = _CACHE[kind]
        if key in c:
            c.move_to_end(key)
            _STATS["hits"] += 1
            return c[key]
        val = build()
        c[key] = val
        _STATS["built"] += 1
        while len(c) > _SIZES[kind]:
            c.popitem(last=False)
        return val


def cache_info() -> dict:
    """Entries and build/hit counts of this process's cache (benchmarks, tests)."""
    with _LOCK:
        return {**{k: len(v) for k, v in _CACHE.items()}, **_STATS}


def clear_cache() -> None:
    with _LOCK:
        for v in _CACHE.values():
            v.clear()
        _STATS.update(built=0, hits=0)


_ALLOCATOR = {"set": False}


def _allocator() -> None:
    """Undo, once per process, the malloc tuning a Dask nanny gives its workers.

    The nanny spawns workers with ``MALLOC_TRIM_THRESHOLD_=65536``; setting
    it turns off glibc's adaptive mmap threshold, so every array above 128 kB
    is a fresh mmap whose pages fault in anew: D2's KE ran almost twice as
    slow per sample, most of it in the kernel, and two such workers on two
    cores ran at a third of their speed (README, sweeps). Large thresholds
    keep the arrays of a sample in the heap for the next; the memory a worker
    holds stays that of its largest sample. glibc only; elsewhere a no-op.
    """
    if _ALLOCATOR["set"]:
        return
    _ALLOCATOR["set"] = True
    try:
        name = ctypes.util.find_library("c")
        libc = ctypes.CDLL(name) if name else None
        if libc is not None and hasattr(libc, "mallopt"):
            libc.mallopt(-3, 64 << 20)  # M_MMAP_THRESHOLD: arrays up to 64 MB from the heap
            libc.mallopt(-1, 128 << 20)  # M_TRIM_THRESHOLD: give memory back above 128 MB of free top
    except (OSError, AttributeError):  # not glibc: its allocator has no such tuning
        pass


def noop(x=None):
    """A task that does nothing: the runner measures Dask's round trip with it."""
    return x


def columns_of(payload: dict) -> list[str]:
    """Result columns in order: index, grid index, draw, parameters, figures, status, reason."""
    return (
        ["sample", "grid_point", "draw"]
        + [p.name for p in payload["parameters"]]
        + list(payload["record"])
        + ["status", "reason"]
    )


def _geometry_key(data: dict) -> str:
    # what the drive and the tooth outlines depend on (the model tables ride along harmlessly)
    return _h({k: v for k, v in data.items() if k not in ("imperfections", "load")})


def _base(payload):
    return _cached("base", payload["fingerprint"], lambda: parse_design(payload["design"]))


def _drive(data, design):
    return _cached("drive", _geometry_key(data), lambda: build_drive(design))


def _ke(payload, data, design, drive) -> dict:
    imp = Imperfections.from_spec(design.imperfections)
    # the table is built for the sweep's largest amplitudes (module docstring of sampling) and the
    # sample's own cam-borne offset (exact in the table); a sample beyond them gets its own table
    amp = design.imperfections.amplitudes_um
    if payload.get("ke_table", "shared") == "per_sample":
        env = dict(amp)  # the table of wgcad ke for this very drive
    else:
        env = envelope_amplitudes_um(_base(payload).imperfections, payload["parameters"])
        env = {k: max(env[k], amp[k]) for k in env}
    env["cam_offset_cam_um"] = amp["cam_offset_cam_um"]
    env_spec = ImperfectionsSpec(**{**design.imperfections.__dict__, **env})
    tab_imp = Imperfections.from_spec(env_spec)
    key = _h([_geometry_key(data), env, design.imperfections.cam_offset_cam_phase_deg, payload["ke_per_mesh"]])
    tab = _cached("table", key, lambda: K.contact_table(drive, tab_imp, payload["ke_per_mesh"]))
    res = K.kinematic_error(drive, imp, table=tab)
    if res.deep_overlap_fraction > 0:
        # the figure exists only where its model holds (docs/models.md 6.2): this sample's is not recorded
        raise ModelError(
            f"KE outside the linear error model: at {100 * res.deep_overlap_fraction:.1f} % of the angles the "
            f"first contact overlaps so deeply (turning back > {K.DEEP_OVERLAP * _AS:.0f} arcsec) that the "
            "model does not hold; more side clearance or smaller errors, or the elastic model (load figures)"
        )
    lm = res.lost_motion
    return {
        "ke_pp_arcsec": res.ke_pp * _AS,
        "lost_motion_min_arcsec": float(lm.min()) * _AS,
        "lost_motion_max_arcsec": float(lm.max()) * _AS,
        "ke_deep_overlap_fraction": float(res.deep_overlap_fraction),
    }


def _audit(payload, data, drive) -> dict:
    # the audit sees the geometry only: the samples of one grid point share it (computed once per worker)
    key = _h([_geometry_key(data), payload["audit_step_deg"], payload["audit_sections"]])
    return dict(_cached("audit", key, lambda: _audit_run(payload, drive)))


def _audit_run(payload, drive) -> dict:
    n = int(round(360.0 / payload["audit_step_deg"]))
    bw = drive.design.drive.face_width
    secs = np.unique(np.concatenate([drive.sections(payload["audit_sections"]), [0.0, bw]]))  # as wgcad audit
    r = audit(drive, AuditSettings(angles=np.deg2rad(np.arange(n) * (360.0 / n)), sections=secs))
    return {
        "min_clearance_um": 1e3 * r.min_clearance,
        "entry_gap_um": 1e3 * r.entry_gap,
        "backlash_arcmin": float(np.rad2deg(r.backlash) * 60.0) if np.isfinite(r.backlash) else math.nan,
    }


def _model_key(data: dict) -> str:
    # what the elastic model depends on: every table but [imperfections] (the geometry, [material], [bearing],
    # [load]'s ball phase and tooth compliance, [parts]' diaphragm, [supports]' stiffnesses)
    return _h({k: v for k, v in data.items() if k != "imperfections"})


def _load(payload, data, design, drive, torques) -> dict:
    key = _h([_model_key(data), payload["load_sections"], sorted(torques)])
    return dict(_cached("load", key, lambda: _load_run(payload, data, design, drive, torques)))


def _load_run(payload, data, design, drive, torques) -> dict:
    from ..elastic.model import build_model
    from ..elastic.sweep import torque_sweep

    key = _h([_model_key(data), payload["load_sections"]])
    model = _cached("model", key, lambda: build_model(drive, payload["load_sections"]))
    ld = design.load
    res = torque_sweep(model, sorted(torques), ld.cam_offset_um, ld.cam_offset_deg)
    out = {}
    for lv in res.levels:
        figures = {
            "entry_gap_um": UM_PER_MM * lv.entry_gap,
            "teeth_in_contact": float(lv.teeth_in_contact),
            "min_clearance_um": UM_PER_MM * lv.min_clearance,
            "wind_up_arcmin": ARCMIN_PER_RAD * lv.state.wind_up,
            "largest_tooth_force_n": float(lv.tooth_forces.max()),
            "max_ball_load_n": float(lv.ball_loads.max()),
        }
        for name, v in figures.items():
            out[f"{name}@{lv.torque_nm:g}Nm"] = float(v)
    return out


def run_sample(payload: dict, i: int) -> dict:
    """One sample: its parameter values, every recorded figure, and ``status`` with the reason.

    ``refused``: a design rule refuses the sample (:class:`~wgcad.errors.DesignError`:
    a field rule, a derived-geometry rule); ``failed``: a model gives up with
    its reason (another :class:`~wgcad.errors.WgcadError`, e.g. the contact
    solver does not converge); ``error``: any other exception, with its type
    and message (a bug to report). None of them stops the sweep.
    """
    values = sample_values(payload, i)
    row = {"sample": int(i)}
    g, r = divmod(int(i), payload["samples"])
    row["grid_point"], row["draw"] = g, r
    row.update(values)
    for name in payload["record"]:
        row[name] = math.nan
    row["status"], row["reason"] = "ok", ""
    try:
        data = sample_design_data(payload["design"], payload["parameters"], values)
        design = parse_design(data, source=f"sample {i}")
        drive = _drive(data, design)
        kinds = {}
        for name in payload["record"]:
            model, base, t = parse_figure(name)
            kinds.setdefault(model, set()).add(t)
        figs = {}
        if "ke" in kinds:
            figs.update(_ke(payload, data, design, drive))
        if "audit" in kinds:
            figs.update(_audit(payload, data, drive))
        if "load" in kinds:
            figs.update(_load(payload, data, design, drive, kinds["load"]))
        for name in payload["record"]:
            model, base, t = parse_figure(name)  # "x@500.0Nm" and "x@500Nm" are the same figure
            row[name] = float(figs[base if t is None else f"{base}@{t:g}Nm"])
    except DesignError as e:
        row["status"], row["reason"] = "refused", " ".join(str(e).split())[:300]
    except WgcadError as e:  # a model that gives up with its reason (contact solver not converged, geometry)
        row["status"], row["reason"] = "failed", f"{type(e).__name__}: {' '.join(str(e).split())}"[:300]
    except Exception as e:  # noqa: BLE001 - one sample's bug must not stop a day-long sweep; it is counted and shown
        row["status"], row["reason"] = "error", f"{type(e).__name__}: {' '.join(str(e).split())}"[:300]
    return row


def run_batch(payload: dict, start: int, stop: int) -> dict:
    """Samples ``start .. stop - 1`` as columns, plus timings (kept out of the results: they differ run to run).

    Returns
    -------
    dict
        ``columns`` (name -> list), ``start``, ``stop``, ``compute_s``
        (seconds in this task), ``cpu_s`` (this process's CPU seconds in it: less
        than ``compute_s`` when the cores are shared), ``built`` (shared objects
        this task had to build), ``pid`` and ``rss_mb`` (the process and its
        resident memory at the task's end: whether a long run's workers grow).
    """
    _allocator()
    t0, c0 = time.perf_counter(), time.process_time()
    b0 = _STATS["built"]
    rows = [run_sample(payload, i) for i in range(start, stop)]
    cols = {c: [r.get(c) for r in rows] for c in columns_of(payload)}
    return {
        "columns": cols,
        "start": start,
        "stop": stop,
        "compute_s": time.perf_counter() - t0,
        "cpu_s": time.process_time() - c0,
        "built": _STATS["built"] - b0,
        "pid": os.getpid(),
        "rss_mb": _rss_mb(),
    }


def _rss_mb() -> float:
    """This process's resident memory now, MB (psutil comes with Dask's distributed)."""
    import psutil

    return psutil.Process().memory_info().rss / 2**20
