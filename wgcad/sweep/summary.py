"""A sweep's results as figures: counts and failure reasons, yield against the limits with its confidence interval, distributions, sensitivities, grids.

The yield is the fraction of computed samples (status ``ok``) whose every
limited figure lies within its limits (a NaN figure, e.g. no backlash, is
outside any limit); its interval is Clopper-Pearson's exact binomial one,
conservative at any count. Refused, failed and error samples are counted
apart and also given as the yield that counts them as failures.

Sensitivity: how strongly each random parameter goes with failing, as the
Spearman rank correlation of the parameter with the failure indicator
(phases and installation angles, which act through their sine and cosine:
the circular-linear correlation ``sqrt(r_c^2 + r_s^2)`` of cos and sin), and
per limited figure the rank correlation with the figure itself.
"""

from __future__ import annotations

import collections
import itertools
import math

import numpy as np

__all__ = [
    "MIN_FAILING_TO_RANK",
    "clopper_pearson",
    "failing_samples",
    "few_failing_note",
    "format_summary",
    "passes",
    "summarize",
    "weakest_figure",
    "wilson",
]


def clopper_pearson(k: int, n: int, conf: float = 0.95) -> tuple[float, float]:
    """Exact (Clopper-Pearson) interval of a binomial proportion ``k / n`` at confidence ``conf``."""
    from scipy.stats import beta

    if n <= 0:
        return (0.0, 1.0)
    a = 1.0 - conf
    lo = 0.0 if k == 0 else float(beta.ppf(a / 2, k, n - k + 1))
    hi = 1.0 if k == n else float(beta.ppf(1 - a / 2, k + 1, n - k))
    return lo, hi


def wilson(k: int, n: int, conf: float = 0.95) -> tuple[float, float]:
    """Wilson score interval of ``k / n`` (a second, closed-form interval)."""
    from scipy.stats import norm

    if n <= 0:
        return (0.0, 1.0)
    z = float(norm.ppf(0.5 + conf / 2))
    p = k / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return max(0.0, c - h), min(1.0, c + h)


def passes(cols: dict, limits: dict) -> np.ndarray:
    """Per sample: status ok and every limited figure within its limits."""
    ok = cols["status"] == "ok"
    for name, (lo, hi) in limits.items():
        v = cols[name]
        inside = np.isfinite(v)
        if lo is not None:
            inside &= v >= lo
        if hi is not None:
            inside &= v <= hi
        ok = ok & inside
    return ok


def _rank(x):
    from scipy.stats import rankdata

    return rankdata(x)


def _corr(a, b) -> float:
    a, b = np.asarray(a, float), np.asarray(b, float)
    if len(a) < 3 or np.ptp(a) == 0 or np.ptp(b) == 0:
        return 0.0
    return float(np.corrcoef(a, b)[0, 1])


def _assoc(p, x, y) -> float:
    """Rank association of parameter values ``x`` with ``y`` (signed; circular phases: unsigned magnitude)."""
    if p.phase:
        t = np.deg2rad(x)
        rc, rs = _corr(np.cos(t), _rank(y)), _corr(np.sin(t), _rank(y))
        return float(math.hypot(rc, rs))
    return _corr(_rank(x), _rank(y))


def _stats(v: np.ndarray) -> dict:
    f = v[np.isfinite(v)]
    if f.size == 0:
        return {"n": 0}
    q = np.quantile(f, [0.01, 0.5, 0.99])
    return {
        "n": int(f.size),
        "mean": float(f.mean()),
        "sd": float(f.std(ddof=1)) if f.size > 1 else 0.0,
        "min": float(f.min()),
        "p01": float(q[0]),
        "median": float(q[1]),
        "p99": float(q[2]),
        "max": float(f.max()),
    }


def _finite_or_none(obj):
    """``obj`` with every NaN or infinity replaced by None (strict JSON: a grid point without a valid sample has no
    mean, a constant column no correlation; the counts beside them say why)."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: _finite_or_none(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_finite_or_none(v) for v in obj]
    return obj


def summarize(spec, cols: dict, conf: float = 0.95) -> dict:
    """The summary document (strict JSON: no NaN or infinity) of the samples in ``cols`` (:meth:`Store.read`)."""
    return _finite_or_none(_summarize(spec, cols, conf))


def _summarize(spec, cols: dict, conf: float) -> dict:
    n = len(cols["sample"])
    st = cols["status"]
    ok = st == "ok"
    counts = {
        "total": spec.total,
        "done": n,
        "ok": int(ok.sum()),
        "refused": int((st == "refused").sum()),
        "failed": int((st == "failed").sum()),
        "error": int((st == "error").sum()),
    }
    reasons = collections.Counter(r for r, s in zip(cols["reason"], st) if s != "ok")
    out = {
        "name": spec.name,
        "design": spec.design_path,
        "seed": spec.seed,
        "counts": counts,
        "reasons": [{"reason": r, "samples": c} for r, c in reasons.most_common(8)],
        "figures": {f: _stats(cols[f][ok]) for f in spec.record},
        "limits": {},
        "yield": None,
        "sensitivity": [],
        "grid": None,
        "confidence": conf,
        # a grid of designs is a table, not a distribution: no mean, spread or yield interval over its points
        "kind": (
            "grid"
            if not any(p.random for p in spec.parameters)
            else ("monte carlo" if all(p.random for p in spec.parameters) else "grid with random draws")
        ),
    }
    fail = _limits(spec, cols, ok, n, conf, out) if spec.limits else None
    _sensitivity(spec, cols, ok, fail, out)
    if any(not p.random for p in spec.parameters):
        out["grid"] = _grid(spec, cols, ok, conf)
    return out


def _limits(spec, cols: dict, ok, n: int, conf: float, out: dict):
    """Each limit's pass count and the yield (with its intervals) into ``out``; the failures of the valid samples
    (1.0 where a sample fails a limit) for the sensitivity."""
    pas = passes(cols, spec.limits)
    k, m = int(pas[ok].sum()), int(ok.sum())
    for name, (lo, hi) in spec.limits.items():
        v = cols[name][ok]
        inside = np.isfinite(v) & (v >= (lo if lo is not None else -np.inf)) & (v <= (hi if hi is not None else np.inf))
        out["limits"][name] = {
            "min": lo,
            "max": hi,
            "pass": int(inside.sum()),
            "of": m,
            "fraction": float(inside.mean()) if m else None,
        }
    lo_, hi_ = clopper_pearson(k, m, conf)
    out["yield"] = {
        "pass": k,
        "of": m,
        "fraction": k / m if m else None,
        "ci": [lo_, hi_],
        "method": "Clopper-Pearson",
        "wilson": list(wilson(k, m, conf)),
        "counting_refused_as_failures": k / n if n else None,
    }
    return (~pas[ok]).astype(float)


def _sensitivity(spec, cols: dict, ok, fail, out: dict) -> None:
    """Each random parameter's association with failing and with every figure, strongest first, into ``out``."""
    rand = [p for p in spec.parameters if p.random]
    if not rand or ok.sum() < 3:
        return
    for p in rand:
        x = np.asarray(cols[p.name][ok], dtype=float)
        row = {
            "parameter": p.name,
            "phase": p.phase,
            "failure": _assoc(p, x, fail) if fail is not None and 0 < fail.sum() < len(fail) else None,
            "figures": {},
        }
        for f in spec.limits or spec.record:
            y = cols[f][ok]
            good = np.isfinite(y)
            row["figures"][f] = _assoc(p, x[good], y[good]) if good.sum() >= 3 else None
        out["sensitivity"].append(row)
    key = (
        (lambda r: -abs(r["failure"] or 0.0))
        if fail is not None
        else (lambda r: -max([abs(v) for v in r["figures"].values() if v is not None] or [0.0]))
    )
    out["sensitivity"].sort(key=key)


def _grid(spec, cols: dict, ok, conf: float) -> dict:
    """The grid's surfaces (each figure's mean, smallest and largest per grid point) and yields per point."""
    grid = [p for p in spec.parameters if not p.random]
    shape = tuple(len(p.values) for p in grid)
    G = int(np.prod(shape))
    gp = cols["grid_point"]
    surf = {}
    for f in spec.record:
        v = cols[f]
        sel = ok & np.isfinite(v)
        cnt = np.bincount(gp[sel], minlength=G)
        mean = np.full(G, np.nan)
        has = cnt > 0
        mean[has] = np.bincount(gp[sel], weights=v[sel], minlength=G)[has] / cnt[has]
        lo = np.full(G, np.inf)
        hi = np.full(G, -np.inf)
        np.minimum.at(lo, gp[sel], v[sel])
        np.maximum.at(hi, gp[sel], v[sel])
        lo[~has], hi[~has] = np.nan, np.nan
        surf[f] = {
            "mean": mean.reshape(shape).tolist(),
            "min": lo.reshape(shape).tolist(),
            "max": hi.reshape(shape).tolist(),
        }
    ylds = None
    if spec.limits:
        pas = passes(cols, spec.limits)
        ylds = []
        m_all = np.bincount(gp[ok], minlength=G)
        k_all = np.bincount(gp[ok & pas], minlength=G)
        for g in range(G):
            k, m = int(k_all[g]), int(m_all[g])
            ylds.append({"pass": k, "of": m, "fraction": k / m if m else None, "ci": list(clopper_pearson(k, m, conf))})
    return {
        "parameters": [p.name for p in grid],
        "values": [list(p.values) for p in grid],
        "shape": list(shape),
        "surfaces": surf,
        "yield": ylds,
    }


def _fmt(x, nd=3) -> str:
    return "-" if x is None or (isinstance(x, float) and not math.isfinite(x)) else f"{x:.{nd}g}"


def format_summary(s: dict, info=None) -> str:
    """The summary for people, a few lines."""
    c = s["counts"]
    lines = [
        f"{s['name']}: {c['done']} of {c['total']} samples stored ({c['ok']} computed, {c['refused']} refused by the rules, "
        f"{c['failed']} failed in a model"
        + (f", {c['error']} ERRORS (a bug: please report)" if c["error"] else "")
        + ")"
    ]
    if info is not None:
        lines.append(
            f"  this run: {info.computed} samples computed, {info.skipped} already stored; {info.executor}; "
            f"{info.batch} sample{'' if info.batch == 1 else 's'} per task"
            + (
                f" (measured: {1e3 * info.sample_s:.0f} ms per sample, Dask round trip {1e3 * info.overhead_s:.1f} ms)"
                if info.sample_s
                else ""
            )
            + f"; {info.wall_s:.1f} s"
            + (" - STOPPED EARLY" if info.stopped_early else "")
        )
    for r in s["reasons"][:4]:
        lines.append(f"  not computed ({r['samples']}): {r['reason']}")
    if s.get("kind") == "grid" and s["grid"] is not None:
        # a design study: every grid point as a row (mean, sd, percentiles and a "confidence interval" of designs
        # chosen on a grid mean nothing)
        return "\n".join(lines + _grid_table(s))
    for f, st in s["figures"].items():
        if st.get("n"):
            lines.append(
                f"  {f}: mean {_fmt(st['mean'], 4)}, sd {_fmt(st['sd'])}, 1 %..99 % {_fmt(st['p01'], 4)} .. {_fmt(st['p99'], 4)}, "
                f"range {_fmt(st['min'], 4)} .. {_fmt(st['max'], 4)}"
            )
        else:
            lines.append(f"  {f}: no value")
    y = s["yield"]
    if y is not None and y["of"]:
        lims = ", ".join(
            f"{k} "
            + " and ".join(
                x
                for x in (
                    (f">= {v['min']:g}" if v["min"] is not None else ""),
                    (f"<= {v['max']:g}" if v["max"] is not None else ""),
                )
                if x
            )
            for k, v in s["limits"].items()
        )
        lines.append(
            f"  YIELD {100 * y['fraction']:.2f} % ({y['pass']} of the {y['of']} samples whose every model held), "
            f"{100 * s['confidence']:.0f} % interval {100 * y['ci'][0]:.2f} .. {100 * y['ci'][1]:.2f} % "
            f"(Clopper-Pearson); limits: {lims}"
        )
        if c["refused"] or c["failed"] or c["error"]:
            lines.append(
                f"  counting refused, failed and error samples as failures: {100 * y['counting_refused_as_failures']:.2f} %"
            )
    elif y is not None:
        lines.append(f"  YIELD not defined: no sample's models held ({c['done']} stored: see the reasons above)")
    if s["sensitivity"]:
        top = [r for r in s["sensitivity"] if r["failure"] is not None][:5]
        n_fail = failing_samples(s)
        if top and n_fail < MIN_FAILING_TO_RANK:
            f = weakest_figure(s)
            by_fig = sorted(
                (r for r in s["sensitivity"] if r["figures"].get(f) is not None), key=lambda r: -abs(r["figures"][f])
            )[:5]
            lines.append(
                f"  parameters driving failures: not ranked, {few_failing_note(s)}; rank correlation with {f} instead: "
                + ", ".join(f"{r['parameter']} {r['figures'][f]:+.2f}" for r in by_fig)
            )
        elif top:
            lines.append(
                "  parameters driving failures (rank correlation with failing): "
                + ", ".join(f"{r['parameter']} {r['failure']:+.2f}" for r in top)
            )
    return "\n".join(lines)


#: fewest failing samples from which the parameters are ranked by their correlation with failing: below it one or
#: two samples decide the order (D2's 40-sample sweep ranked eight parameters from its one failure)
MIN_FAILING_TO_RANK = 5


def failing_samples(s: dict) -> int:
    """Samples whose models held but which fail a limit (0 without limits)."""
    y = s.get("yield")
    return 0 if not y or not y.get("of") else int(y["of"] - y["pass"])


def few_failing_note(s: dict) -> str:
    """Why the parameters are not ranked by failing: how many failed, of how many, and the least the ranking needs."""
    n = failing_samples(s)
    of = (s.get("yield") or {}).get("of", 0)
    return f"{n} failing sample{'' if n == 1 else 's'} of {of} (at least {MIN_FAILING_TO_RANK} needed)"


def weakest_figure(s: dict) -> str:
    """The limited figure the fewest samples meet (the one whose margin the parameters are ranked by)."""
    lims = s["limits"]
    return min(lims, key=lambda k: lims[k]["fraction"] if lims[k]["fraction"] is not None else 1.0)


def _grid_table(s: dict) -> list[str]:
    """The grid points of a design study, one row each: the parameters, every recorded figure, and the verdict."""
    g = s["grid"]
    names, values, shape = g["parameters"], g["values"], tuple(g["shape"])
    figs = list(g["surfaces"])
    head = [*names, *figs] + (["meets the limits"] if g["yield"] else [])
    rows = []
    for flat, combo in enumerate(itertools.product(*[range(n) for n in shape])):
        row = [f"{values[i][j]:g}" if not isinstance(values[i][j], str) else values[i][j] for i, j in enumerate(combo)]
        for f in figs:
            v = np.asarray(g["surfaces"][f]["mean"], dtype=object).reshape(shape)[combo]
            row.append(_fmt(None if v is None else float(v), 4))
        if g["yield"]:
            y = g["yield"][flat]
            row.append("-" if not y["of"] else ("yes" if y["pass"] == y["of"] else "NO"))
        rows.append(row)
    width = [max(len(h), *(len(r[k]) for r in rows)) for k, h in enumerate(head)]
    out = [f"  grid of {len(rows)} designs (one sample each):"]
    out.append("    " + "  ".join(h.rjust(w) for h, w in zip(head, width)))
    out += ["    " + "  ".join(c.rjust(w) for c, w in zip(r, width)) for r in rows]
    if g["yield"]:
        good = sum(1 for y in g["yield"] if y["of"] and y["pass"] == y["of"])
        lims = ", ".join(k for k in s["limits"])
        out.append(f"  {good} of {len(rows)} designs meet the limits ({lims})")
    return out
