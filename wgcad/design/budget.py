"""The work and memory a run will need, estimated from the design before any large allocation, and the budget it must fit.

The estimate is closed-form in the design's sizes: outline vertices per
tooth from the chord tolerance (the sagitta of a chord of length ``c`` on a
curve of radius ``R`` is ``c^2 / (8 R)``, so a curve of a given shape needs
a number of chords proportional to ``sqrt(m / tol)``), audit samples from the
generator-angle step, the tooth count and the sections. Its coefficients were
fitted to measured runs (``tests/test_design_budget.py`` checks the vertex
counts against built gears, ``benchmarks/`` the memory against peak RSS) and
err on the high side.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import ceil, sqrt

from .. import constants
from ..errors import DesignError

__all__ = [
    "DEFAULT_MAX_MEMORY_MB",
    "RunShape",
    "RunEstimate",
    "outline_vertices_per_tooth",
    "estimate_run",
    "check_budget",
    "estimate_sector_mb",
    "check_sector_budget",
    "estimate_load_mb",
    "check_load_budget",
]

#: Memory a run may use by default, MB. The bundled templates need 0.1-0.2 GB
#: for ``generate`` and a default ``audit``; 2 GB fits beside other work on a
#: small machine and is raised with ``--max-memory-mb``.
DEFAULT_MAX_MEMORY_MB = 2048.0

# vertices of one pitch of outline ~ A + B sqrt(m / tol): fitted on 1000 built
# gears of random designs (tests/test_stability.py's generator) at chord
# tolerances 0.01-10 um: the upper envelope of the counts plus ~20 % (the floor A comes
# from the fixed minimum of sampled pieces)
_VERTS_A = 16.0
# (double_arc: arcs and a line, 30-40 vertices per pitch of a D1-sized tooth at 1 um, within the involute's bound)
_VERTS_B = {"involute": 2.2, "cycloidal": 2.6, "double_arc": 2.2}
# bytes: the interpreter and imports; per outline vertex written to DXF + STL (both gears, with the solids'
# triangles); per audit sample (generator angle x tooth: angle arrays, folding, sorting); per distinct tooth angle
# and section (search state); per vertex of a tooth evaluated in one batch (placed copies, polygons, distances).
# Fitted to the peak RSS (VmHWM) of `generate` on every template at 1 um with and without STL and D4 at 0.1 um, and
# of a default `audit` and D1's at 0.05 deg x 3 sections, on a 2-core Linux machine: 68-76 MB without STL, 79-101 MB
# with it, 52-89 MB for the default audits, 154 MB for the fine one. The estimate is 1.17-1.81x those peaks: another
# machine's peaks ran up to 8 % higher (its numpy and allocator), and the estimate must stay above them and within
# 2x (tests/test_design_budget.py). The STL cost is taken per estimated outline vertex (an upper count).
_BASE_B = 88e6
_PER_EXPORT_VERTEX_B = 1000.0
# a conjugate gear's envelope of the mating tooth's motion (docs/models.md 13): D1's peaks 4-14 MB higher with it
_CONJUGATE_B = 10e6
_PER_SAMPLE_B = 32.0
_PER_UNIQUE_SECTION_B = 20.0
_PER_BATCH_VERTEX_B = 50.0
_PER_BOUND_VERTEX_B = 16.0
# the branch-and-bound's coarse pass evaluates every 256th distinct tooth angle of
# large sweeps and the finer passes only the few whose bound is below the minimum
_BOUND_BATCH_DIVISOR = 256


@dataclass(frozen=True, slots=True)
class RunEstimate:
    """What a run is expected to need.

    Attributes
    ----------
    vertices_per_tooth : dict
        ``{"flexspline": n, "rigid": n}``, one pitch of outline.
    outline_vertices : int
        Both gears' whole outlines.
    audit_samples : int
        Generator angles x flexspline teeth x sections (0 without an audit).
    memory_mb : float
        Estimated peak memory, MB.
    """

    vertices_per_tooth: dict
    outline_vertices: int
    audit_samples: int
    memory_mb: float

    def as_dict(self) -> dict:
        return {
            "vertices_per_tooth": dict(self.vertices_per_tooth),
            "outline_vertices": self.outline_vertices,
            "audit_samples": self.audit_samples,
            "memory_mb": round(self.memory_mb, 1),
        }


@dataclass(frozen=True, slots=True)
class RunShape:
    """What a run will do, as far as its memory goes: the audit's size and shortcuts and the exports.

    Attributes
    ----------
    angles, sections : int
        Generator angles over a revolution and cross-sections of an audit
        (``angles=0``: no audit). Without coning one section is computed.
    use_period, use_waves, use_mirror, bound : bool
        The audit's shortcuts (:class:`wgcad.clearance.engine.AuditSettings`):
        without them far more samples are kept and evaluated at once.
    exports : bool
        Whether the STL solids of the outlines are written (``generate``; its DXF alone fits in the base).
    """

    angles: int = 0
    sections: int = 1
    use_period: bool = True
    use_waves: bool = True
    use_mirror: bool = True
    bound: bool = True
    exports: bool = True


def outline_vertices_per_tooth(form: str, module: float, tol: float) -> int:
    """Upper estimate of the vertices of one pitch of a sampled outline (tip, flanks, fillets, root)."""
    return int(ceil(_VERTS_A + _VERTS_B.get(form, max(_VERTS_B.values())) * sqrt(module / tol)))


def estimate_run(
    design,
    tol: float = constants.CHORD_TOL,
    *,
    run: RunShape = RunShape(),
    vertices_per_tooth: dict | None = None,
) -> RunEstimate:
    """Estimate the outline sizes, audit samples and peak memory of a run, from the design alone.

    Parameters
    ----------
    design : Design
        A validated design (field bounds hold, so every product below is finite).
    tol : float
        Chord tolerance, mm.
    run : RunShape
        The audit and exports of the run (the default: the outlines and their exports, no audit).
    vertices_per_tooth : dict, optional
        Measured vertices of one pitch (``{"flexspline": n, "rigid": n}``) of
        gears already built, instead of the upper estimate.
    """
    if not tol > 0:
        raise DesignError("chord_tol", f"must be > 0, got {tol:g}")
    dr = design.drive
    form = design.tooth.form
    per = outline_vertices_per_tooth(form, dr.module, tol)
    verts = dict(vertices_per_tooth) if vertices_per_tooth else {"flexspline": per, "rigid": per}
    n_out = verts["flexspline"] * dr.z_flex + verts["rigid"] * dr.z_rigid
    mem = _BASE_B + n_out * 16.0 * 6  # outline arrays and their intermediates (angles, radii, polar)
    if run.exports:
        mem += n_out * _PER_EXPORT_VERTEX_B
    mem += _CONJUGATE_B * sum(getattr(design, g).flanks == "conjugate" for g in ("flexspline", "rigid"))
    samples = 0
    if run.angles > 0:
        secs = run.sections if design.generator.cone_length is not None else 1
        n_s = run.angles * dr.z_flex
        samples = n_s * secs
        fold = 1
        if run.use_period:
            fold *= 2 if run.use_mirror else 1
            fold *= dr.waves if (run.use_waves and dr.z_flex % dr.waves == 0) else 1
        n_u = n_s // fold if run.use_period else n_s
        batch = n_u * secs if not run.bound else max(1, n_u * secs // _BOUND_BATCH_DIVISOR)
        p = verts["flexspline"] + 2  # a tooth polygon: one pitch closed through the body
        mem += (
            n_s * _PER_SAMPLE_B
            + n_u * secs * _PER_UNIQUE_SECTION_B
            + n_u * 0.5 * p * _PER_BOUND_VERTEX_B  # radial bound: the tip half of every distinct tooth angle, placed
            + batch * p * _PER_BATCH_VERTEX_B
        )
    return RunEstimate(verts, int(n_out), int(samples), mem / 1e6)


# `wgcad sector`: its sweeps hold every (generator angle, flexspline tooth) pair of half a turn at once.
# Measured peak RSS of `wgcad sector templates/d4_sectored.toml --no-stl` (84 teeth, /usr/bin/time -f %M):
# 466 MB at 0.1 deg, 886 MB at 0.05, 2146 MB at 0.02, 4248 MB at 0.01: 45 MB plus 2.78 kB per pair;
# the estimate takes 20 % more per pair
_SECTOR_BASE_MB = 45.0
_SECTOR_PER_PAIR_B = 1.2 * 2.78e3


def estimate_sector_mb(z_flex: int, step_deg: float) -> float:
    """Memory (MB) of ``wgcad sector`` at generator-angle step ``step_deg`` for ``z_flex`` flexspline teeth."""
    return _SECTOR_BASE_MB + _SECTOR_PER_PAIR_B * _sector_angles(step_deg) * z_flex / 1e6


def _sector_angles(step_deg: float) -> float:
    """The sweeps' generator angles over half a turn; a step so fine that they overflow a float (a subnormal step)
    counts 1e300, still far beyond any budget."""
    angles = 180.0 / step_deg
    return float(round(angles)) if angles < 1e300 else 1e300


def check_sector_budget(z_flex: int, step_deg: float, max_memory_mb: float | None = DEFAULT_MAX_MEMORY_MB) -> float:
    """Refuse a sector run whose estimated memory exceeds ``max_memory_mb`` (one line naming --step-deg)."""
    mb = estimate_sector_mb(z_flex, step_deg)
    if max_memory_mb is not None and mb > max_memory_mb:
        raise DesignError(
            "--step-deg",
            f"a step of {step_deg:g} deg needs about {mb:.4g} MB ({_sector_angles(step_deg):.6g} generator angles x "
            f"{z_flex} teeth held at once), more than the budget of {max_memory_mb:g} MB; coarsen --step-deg or "
            "raise --max-memory-mb",
        )
    return mb


# `wgcad audit --torque-nm`: every level's solved state is kept until the entry gaps of all levels are refined in
# one engine call. Measured peak RSS (/usr/bin/time -f %M) at 2 and 51 levels of D1 (200 teeth): 0.36 MB more per
# level at 1 section, 1.29 MB at 3, 2.46 MB at 6 (D2 at 3 sections: 1.24 MB), i.e. ~2.1 kB per level, tooth and
# section; the estimate takes 2.5 kB. 74-94 MB at 1-2 levels: the base is taken as 100 MB.
_LOAD_BASE_MB = 100.0
_LOAD_PER_LEVEL_TOOTH_SECTION_B = 2.5e3


def estimate_load_mb(levels: int, z_flex: int, sections: int, sweeps: int = 1) -> float:
    """Memory (MB) of a load audit of ``levels`` torque levels at ``sections`` sections; ``sweeps`` of them held at
    once (``--compare`` holds the audit's while it runs the others)."""
    return _LOAD_BASE_MB + _LOAD_PER_LEVEL_TOOTH_SECTION_B * sweeps * levels * z_flex * sections / 1e6


def check_load_budget(
    levels: int,
    z_flex: int,
    sections: int,
    max_memory_mb: float | None = DEFAULT_MAX_MEMORY_MB,
    sweeps: int = 1,
) -> float:
    """Refuse a load audit whose estimated memory exceeds ``max_memory_mb`` (one line naming --torque-nm)."""
    mb = estimate_load_mb(levels, z_flex, sections, sweeps)
    if max_memory_mb is not None and mb > max_memory_mb:
        held = f"{levels} levels x {z_flex} teeth x {sections} sections" + (f" x {sweeps} sweeps" if sweeps > 1 else "")
        raise DesignError(
            "--torque-nm",
            f"{levels} torque levels need about {mb:.0f} MB of solved states ({held} held at once), more than the "
            f"budget of {max_memory_mb:g} MB; fewer levels (a coarser STEP), fewer --sections, or raise "
            "--max-memory-mb",
        )
    return mb


def check_budget(
    est: RunEstimate, max_memory_mb: float | None = DEFAULT_MAX_MEMORY_MB, flag: str = "--max-memory-mb"
) -> RunEstimate:
    """Refuse a run whose estimated memory exceeds ``max_memory_mb`` (None: no limit).

    Raises
    ------
    DesignError
        One line: the estimate, what drives it, the budget and the flag that raises it.
    """
    if max_memory_mb is not None and est.memory_mb > max_memory_mb:
        what = f"{est.outline_vertices} outline vertices"
        if est.audit_samples:
            what += f", {est.audit_samples} audit samples"
        raise DesignError(
            flag,
            f"this run needs about {est.memory_mb:.0f} MB ({what}), more than the budget of "
            f"{max_memory_mb:g} MB; raise {flag}, or coarsen --chord-tol-um / --step-deg, "
            "or reduce the tooth counts",
        )
    return est
