"""The design search: optuna chooses the free keys, :mod:`wgcad.synthesis.evaluate` judges each candidate, Dask runs
them side by side, a journal file makes it resumable (docs/models.md 14).

- Sampler: optuna's TPE with constraints (one objective) or NSGA-II with constraints (two objectives: a Pareto
  front); when every free key is a whole number and the grid of their values is no larger than the trial budget,
  every combination is enqueued (exhaustive: nothing left to chance).
- Constraints: each :class:`~wgcad.synthesis.evaluate.Evaluation` margin, negated, set on the trial
  (``Trial.set_constraint``: <= 0 is met); a constraint a candidate never reached counts as violated by 1.
- Evaluation: in this process with one worker, else on a Dask cluster (the sweep's local cluster of single-threaded
  processes, or ``--scheduler``), ``workers`` candidates at a time, asked of the sampler together.
- Resumable: the study lives in ``<out>/study.journal``; a second run with the same output folder continues it, and
  the trials already done count toward the budget.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from itertools import product

from ..design import load_design
from ..errors import WgcadError
from ..extras import require
from ..sweep.runner import close_cluster, local_cluster
from .evaluate import PEAK, RATED, STAGES, Evaluation, evaluate
from .requirements import OBJECTIVES, Requirements

__all__ = ["SearchResult", "run_search", "constraint_names"]


def constraint_names(req: Requirements) -> list[str]:
    """The constraints of a requirements file, in a fixed order (the optuna constraint vector)."""
    names = []
    if req.ratio is not None:
        names.append("ratio")
    names.append("design rules")
    if req.max_outside_diameter_mm is not None:
        names.append("outside diameter")
    if req.max_length_mm is not None:
        names.append("length")
    names.append("clearance")
    if req.max_backlash_arcmin is not None:
        names.append("backlash")
    if req.rated_torque_nm is not None:
        names += [f"{k} at rated torque" for k in RATED]
    if req.peak_torque_nm is not None:
        names += [f"{k} at peak torque" for k in PEAK]
    if req.lost_motion_arcmin is not None:
        names.append("lost motion")
    if req.entry_gap_closes_below_nm is not None:
        names.append("entry gap closes below")
    if req.ke_max_arcsec is not None:
        names.append("ke budget")
    return names


@dataclass(slots=True)
class SearchResult:
    """Every candidate judged (resumed ones included), the feasible ones ranked, and how the search ran."""

    req: Requirements
    evaluations: list
    ranked: list
    pareto: list
    constraints: list
    executor: str
    sampler: str
    seconds: float
    resumed: int = 0
    notes: list = field(default_factory=list)
    #: for each free key of the best design, what holds it where it is (:func:`_what_holds`)
    held: dict = field(default_factory=dict)

    @property
    def best(self) -> Evaluation | None:
        return self.ranked[0] if self.ranked else None

    def never_met(self) -> list[str]:
        """Constraints no candidate met (of those some candidate reached)."""
        out = []
        for c in self.constraints:
            seen = [ev.margins[c] for ev in self.evaluations if ev.margins.get(c) is not None]
            if seen and max(seen) < 0:
                out.append(c)
        return out

    def closest(self) -> Evaluation | None:
        """The candidate nearest to feasible: the furthest stage reached, then the largest smallest margin."""
        if not self.evaluations:
            return None

        def key(ev):
            reached = STAGES.index(ev.stage) if ev.stage in STAGES else len(STAGES)
            worst = ev.worst
            return (reached, -math.inf if worst is None else worst[1])

        return max(self.evaluations, key=key)


def _sense(name: str) -> float:
    return 1.0 if OBJECTIVES[name][0] == "max" else -1.0


def _rank(req: Requirements, feasible: list) -> tuple[list, list]:
    """Feasible candidates best first (by the first objective), and the non-dominated ones (two objectives)."""
    objs = req.objectives

    def score(ev, o):
        v = ev.objectives.get(o)
        return -math.inf if v is None else _sense(o) * v

    ranked = sorted(feasible, key=lambda ev: tuple(-score(ev, o) for o in objs))
    if len(objs) < 2:
        return ranked, ranked[:1]
    front = []
    for ev in ranked:
        s = [score(ev, o) for o in objs]
        dominated = any(
            all(score(o2, o) >= v for o, v in zip(objs, s)) and any(score(o2, o) > v for o, v in zip(objs, s))
            for o2 in ranked
        )
        if not dominated:
            front.append(ev)
    return ranked, front


def _sampler(req: Requirements):
    import optuna

    n_grid = grid_size(req)
    if n_grid is not None and n_grid <= req.trials:
        # every combination enqueued (run_search): the sampler only stands by
        return optuna.samplers.RandomSampler(seed=req.seed), f"grid (all {n_grid} combinations)", n_grid

    if len(req.objectives) == 1:
        startup = min(10, max(4, req.trials // 4))
        s = optuna.samplers.TPESampler(seed=req.seed, multivariate=True, n_startup_trials=startup)
        return s, f"optuna TPE with constraints ({startup} random trials first)", None
    pop = max(4, min(20, req.trials // 3))
    s = optuna.samplers.NSGAIISampler(seed=req.seed, population_size=pop)
    return s, f"optuna NSGA-II with constraints (population {pop})", None


def _distributions(req: Requirements) -> dict:
    from optuna.distributions import FloatDistribution, IntDistribution

    return {
        fk.name: IntDistribution(int(fk.low), int(fk.high)) if fk.integer else FloatDistribution(fk.low, fk.high)
        for fk in req.free
    }


def _from_trial(ft) -> Evaluation | None:
    a = ft.user_attrs
    if "stage" not in a:
        return None
    return Evaluation(
        values=dict(ft.params),
        margins=dict(a.get("margins", {})),
        objectives=dict(a.get("objectives", {})),
        stage=a["stage"],
        feasible=bool(a.get("feasible")),
        message=a.get("message", ""),
        seconds=float(a.get("seconds", 0.0)),
        stage_seconds=dict(a.get("stage_seconds", {})),  # a journal of an earlier release has none
    )


def _tell(study, trial, ev: Evaluation, req: Requirements, names: list) -> None:
    for c in names:  # optuna: <= 0 is met; a constraint the candidate never reached counts as violated by 1
        trial.set_constraint(c, -ev.margins[c] if ev.margins.get(c) is not None else 1.0)
    for k in ("margins", "objectives", "stage", "feasible", "message", "seconds", "stage_seconds"):
        trial.set_user_attr(k, getattr(ev, k))
    # an objective a candidate never reached: the worst value any candidate can have (constraints rank it anyway)
    vals = [ev.objectives.get(o, -1e30 if OBJECTIVES[o][0] == "max" else 1e30) for o in req.objectives]
    study.tell(trial, vals if len(vals) > 1 else vals[0])


def _client(workers: int, scheduler):
    """``(client, cluster, description)``: None for ``workers`` 0, in this process (the rule of ``sweep`` too)."""
    if scheduler is None and workers == 0:
        return None, None, "this process"
    from distributed import Client

    if scheduler is not None:
        try:
            return Client(scheduler, timeout="20s"), None, f"Dask scheduler {scheduler}"
        except (OSError, TimeoutError) as e:
            raise WgcadError(f"--scheduler {scheduler}: cannot reach the Dask scheduler ({e})") from None

    cluster = local_cluster(workers)
    return Client(cluster), cluster, f"Dask LocalCluster, {workers} processes on loopback"


def run_search(
    req: Requirements, out_dir=None, workers: int = 0, scheduler=None, progress=None, explain: bool = True
) -> SearchResult:
    """Search the free keys of ``req`` (module docstring); ``progress(done, total)`` after every candidate.

    ``explain``: judge the best candidate's neighbours too, to say what holds each chosen key
    (:func:`_what_holds`: two more candidates per key, not counted in the budget)."""
    require("design")
    if scheduler is not None or workers >= 1:
        require("sweep", what="--workers" if scheduler is None else "--scheduler")
    import optuna

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    t0 = time.perf_counter()
    base = load_design(req.base)
    names = constraint_names(req)
    sampler, sampler_text, n_grid = _sampler(req)
    budget = req.trials if n_grid is None else min(req.trials, n_grid)
    storage = None
    if out_dir is not None:
        from optuna.storages import JournalStorage
        from optuna.storages.journal import JournalFileBackend

        storage = JournalStorage(JournalFileBackend(str(out_dir / "study.journal")))
    directions = ["maximize" if OBJECTIVES[o][0] == "max" else "minimize" for o in req.objectives]
    study = optuna.create_study(
        study_name="wgcad-design", storage=storage, load_if_exists=True, directions=directions, sampler=sampler
    )
    done = [t for t in study.trials if t.state == optuna.trial.TrialState.COMPLETE]
    evaluations = [ev for ev in map(_from_trial, done) if ev is not None]
    resumed = len(evaluations)
    dist = _distributions(req)
    if n_grid is not None:
        seen = {tuple(ev.values[fk.name] for fk in req.free) for ev in evaluations}
        ranges = [range(int(fk.low), int(fk.high) + 1) for fk in req.free]
        for combo in product(*ranges):
            if combo not in seen:
                study.enqueue_trial({fk.name: v for fk, v in zip(req.free, combo)})
    client, cluster, executor = _client(workers, scheduler)

    def judge(cands: list) -> list:
        if client is None:
            return [evaluate(base, req.free, c, req) for c in cands]
        n = len(cands)
        return _results(client, client.map(evaluate, [base] * n, [req.free] * n, cands, [req] * n, pure=False))

    interrupted = False
    try:
        while len(evaluations) < budget:
            n = min(max(1, workers), budget - len(evaluations))
            trials = [study.ask(dist) for _ in range(n)]
            for t, ev in zip(trials, judge([dict(t.params) for t in trials])):
                _tell(study, t, ev, req, names)
                evaluations.append(ev)
                if progress is not None:
                    progress(len(evaluations), budget)
        ranked, front = _rank(req, [ev for ev in evaluations if ev.feasible])
        held = _what_holds(req, ranked[0], judge) if ranked and explain else {}
    except KeyboardInterrupt:  # Ctrl-C, or SIGTERM / SIGHUP as the CLI raises them
        interrupted = True
        raise
    finally:
        if client is not None:
            client.close()
        if cluster is not None:
            close_cluster(cluster, interrupted)
    return SearchResult(
        req=req,
        evaluations=evaluations,
        ranked=ranked,
        pareto=front,
        constraints=names,
        executor=executor,
        sampler=sampler_text,
        seconds=time.perf_counter() - t0,
        resumed=resumed,
        held=held,
    )


def _results(client, futures: list) -> list:
    """The futures' results in their order, each taken as it finishes (as a sweep's chunks are,
    :func:`wgcad.sweep.runner._collect`); on an interruption (Ctrl-C, SIGTERM) or a failed task the futures still
    pending are cancelled before the exception goes on. ``Client.gather`` instead leaves its waiting coroutines on
    the client's event loop, and closing the client then logs each one's traceback ("Task exception was never
    retrieved")."""
    from distributed import as_completed

    index = {f.key: k for k, f in enumerate(futures)}
    out = [None] * len(futures)
    try:
        for f in as_completed(futures):
            out[index[f.key]] = f.result()
    except BaseException:
        for f in futures:
            f.cancel()
        raise
    return out


def _what_holds(req: Requirements, best: Evaluation, judge) -> dict:
    """For each free key of the best candidate, the constraint that holds it there: the key is moved by a twentieth
    of its range (one, for whole numbers) each way it can go, the other keys kept, the moved candidates judged; the
    constraint with the smallest margin among them (a violated one first) is what stops the key moving, and its
    margin there is given. A key whose moves violate nothing is held by the objective alone."""
    moves = []
    for fk in req.free:
        step = 1.0 if fk.integer else 0.05 * (fk.high - fk.low)
        for sgn in (-1.0, 1.0):
            v = best.values[fk.name] + sgn * step
            if fk.low - 1e-12 <= v <= fk.high + 1e-12:
                moves.append((fk, sgn, v, {**best.values, fk.name: v}))
    evs = judge([m[3] for m in moves])
    out = {}
    for fk in req.free:
        tried = [(m, ev) for m, ev in zip(moves, evs) if m[0] is fk]
        worst = None
        for (_, sgn, v, _), ev in tried:
            for c, margin in ev.margins.items():
                if margin is not None and (worst is None or margin < worst[2]):
                    worst = (c, sgn, margin, v)
        if worst is None:
            out[fk.name] = {"constraint": None, "note": "at both ends of its range: no move tried"}
        elif worst[2] >= 0:
            out[fk.name] = {"constraint": None, "note": "moving it violates nothing: the objective holds it"}
        else:
            out[fk.name] = {
                "constraint": worst[0],
                "direction": "up" if worst[1] > 0 else "down",
                "value_tried": worst[3],
                "margin_there": worst[2],
            }
    return out


def grid_size(req: Requirements) -> int | None:
    """Combinations of the whole-number free keys, or None when some key is real-valued."""
    if not all(fk.integer for fk in req.free):
        return None
    return math.prod(int(fk.high) - int(fk.low) + 1 for fk in req.free)
