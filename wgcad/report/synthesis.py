"""A design search in words and JSON, and the chosen design as a commented design file (``wgcad design``)."""

from __future__ import annotations

import json
import math
import re

from ..synthesis.evaluate import STAGES
from ..synthesis.requirements import OBJECTIVES

__all__ = ["search_json", "summary_lines", "design_name", "design_text", "trial_rows"]


def _r(x, nd=4):
    return None if x is None or (isinstance(x, float) and not math.isfinite(x)) else round(float(x), nd)


def _candidate(ev) -> dict:
    return {
        "values": {k: _r(v, 6) for k, v in ev.values.items()},
        "stage": ev.stage,
        "feasible": ev.feasible,
        "margins": {k: _r(v) for k, v in ev.margins.items()},
        "objectives": {k: _r(v) for k, v in ev.objectives.items()},
        "message": ev.message,
        "seconds": _r(ev.seconds, 2),
        "stage_seconds": {k: _r(v, 3) for k, v in ev.stage_seconds.items()},
    }


def _stage_times(evaluations) -> dict:
    """Per working stage: how many candidates ran it, its wall seconds over all of them, and the mean per candidate
    (the candidates resumed from a journal count with the times they were measured with; one of an earlier release
    has none)."""
    out = {}
    for st in STAGES:
        ts = [ev.stage_seconds[st] for ev in evaluations if st in ev.stage_seconds]
        if ts:
            out[st] = {"candidates": len(ts), "total_s": _r(sum(ts), 2), "mean_s": _r(sum(ts) / len(ts), 3)}
    return out


def _binding(ev, n: int = 3) -> list:
    known = sorted((v, k) for k, v in ev.margins.items() if v is not None and k not in ("ratio", "design rules"))
    return [{"constraint": k, "margin": _r(v)} for v, k in known[:n]]


def search_json(res) -> dict:
    """The search's document: what was asked, how it ran, the best and the Pareto front, or why nothing was feasible."""
    req = res.req
    doc = {
        "requirements": req.source,
        "name": req.name,
        "base_design": str(req.base),
        "free": {fk.name: [fk.low, fk.high] for fk in req.free},
        "objectives": {o: OBJECTIVES[o][0] + " " + OBJECTIVES[o][1] for o in req.objectives},
        "constraints": res.constraints,
        "sampler": res.sampler,
        "executor": res.executor,
        "trials": len(res.evaluations),
        "resumed_trials": res.resumed,
        "feasible": len(res.ranked),
        "seconds": _r(res.seconds, 2),
        "stage_seconds": _stage_times(res.evaluations),
        "best": None
        if res.best is None
        else {**_candidate(res.best), "binding": _binding(res.best), "held_by": res.held},
        "pareto": [_candidate(ev) for ev in res.pareto] if len(req.objectives) > 1 else None,
    }
    if res.best is None:
        close = res.closest()
        doc["never_met"] = res.never_met()
        doc["closest"] = None if close is None else _candidate(close)
    doc["not_checked"] = [
        "kinematic error and its yield under tolerances (run wgcad sweep on the chosen design)",
        "the design's [imperfections]: candidates are judged as perfect drives",
    ]
    return doc


def summary_lines(res) -> list[str]:
    """The search's summary for people."""
    req = res.req
    out = [
        f"{req.name}: design search over {', '.join(fk.name for fk in req.free)} "
        f"({len(res.evaluations)} candidates, {res.resumed} resumed; {res.sampler}; {res.executor}; "
        f"{res.seconds:.1f} s)"
    ]
    by_stage = dict.fromkeys(STAGES, 0)
    for ev in res.evaluations:
        if not ev.feasible:
            by_stage[ev.stage] = by_stage.get(ev.stage, 0) + 1
    stopped = ", ".join(f"{n} at {s}" for s, n in by_stage.items() if n)
    out.append(f"  feasible: {len(res.ranked)}" + (f"; stopped: {stopped}" if stopped else ""))
    best = res.best
    if best is None:
        out.append("  NO FEASIBLE DESIGN")
        never = res.never_met()
        if never:
            out.append(f"  no candidate met: {', '.join(never)}")
        close = res.closest()
        if close is not None:
            vals = ", ".join(f"{k} = {v:g}" for k, v in close.values.items())
            margins = ", ".join(f"{k} {v:+.3f}" for k, v in close.margins.items() if v is not None)
            out.append(f"  closest candidate: {vals} (stopped at {close.stage}: {close.message}); margins {margins}")
        return out
    vals = ", ".join(f"{k} = {v:g}" for k, v in best.values.items())
    objs = ", ".join(f"{o} {best.objectives.get(o, float('nan')):.6g}" for o in req.objectives)
    out.append(f"  best: {vals}: {objs}")
    bind = _binding(best)
    if bind:
        out.append("  binding: " + ", ".join(f"{b['constraint']} (margin {b['margin']:+.3f})" for b in bind))
    rest = sorted((v, k) for k, v in best.margins.items() if v is not None and k not in ("ratio", "design rules"))
    if len(rest) > len(bind):
        out.append("  the others keep: " + ", ".join(f"{k} {v:+.3f}" for v, k in rest[len(bind) :]))
    for name, h in res.held.items():
        out.append(f"  {name}: " + _held(h, "no margin measured"))
    if len(req.objectives) > 1:
        out.append(f"  Pareto front: {len(res.pareto)} designs")
    return out


def _set_key(text: str, table: str, key: str, value: str, comment: str) -> str:
    """``text`` with ``key`` of ``[table]`` set to ``value`` (added at the table's end if absent), comment kept beside."""
    lines = text.splitlines()
    out, in_table, done = [], False, False
    line_new = f"{key} = {value}  # {comment}"
    for line in lines:
        m = re.match(r"\s*\[([A-Za-z_]+)\]\s*(#.*)?$", line)
        if m:
            if in_table and not done:
                out.append(line_new)
                done = True
            in_table = m.group(1) == table
        elif in_table and re.match(rf"\s*{re.escape(key)}\s*=", line):
            out.append(line_new)
            done = True
            continue
        out.append(line)
    if not done:
        if not in_table:
            out.append(f"\n[{table}]")
        out.append(line_new)
    return "\n".join(out) + "\n"


def _held(h: dict | None, why: str) -> str:
    """What a key's comment says holds it: the constraint its moves violate, else the objective, else the margins."""
    if not h:
        return why
    if h.get("constraint") is None:
        return h["note"]
    return (
        f"held by {h['constraint']} (moved {h['direction']} to {h['value_tried']:g}: margin {h['margin_there']:+.3f})"
    )


def design_text(base_text: str, res, ev, label: str = "best") -> str:
    """The base design's text with the free keys set to ``ev``'s values, each commented with the constraint that
    binds hardest, and a header saying where the file came from."""
    req = res.req
    bind = _binding(ev)
    why = ", ".join(f"{b['constraint']} margin {b['margin']:+.3f}" for b in bind) or "no margin measured"
    head = [
        f"# {label} design of `wgcad design {req.source}` ({req.name}): the base design {req.base.name} with the keys",
        f"# the search chose ({len(res.evaluations)} candidates, {res.sampler}). Objectives: "
        + ", ".join(f"{o} {ev.objectives.get(o, float('nan')):.6g}" for o in req.objectives)
        + ".",
        f"# Margins that bind hardest: {why} (0: just met; docs/models.md 14).",
        "# The comments further down are the base design's; the chosen keys say so on their own lines.",
        "",
    ]
    text = base_text
    held = res.held if ev is res.best else {}
    for fk in req.free:
        v = ev.values[fk.name]
        value = str(int(round(v))) if fk.integer else repr(round(float(v), 6))
        text = _set_key(
            text,
            fk.table,
            fk.key,
            value,
            f"chosen by wgcad design in [{fk.low:g}, {fk.high:g}]; " + _held(held.get(fk.name), why),
        )
    # its own name, so its audits and pages are not labelled as the base design's
    base = ((req.base_data or {}).get("drive") or {}).get("name") or req.base.stem
    trial = next((i for i, e in enumerate(res.evaluations) if e is ev), None)
    name = design_name(base, label, trial)
    text = _set_key(
        text, "drive", "name", json.dumps(name), f"named by wgcad design; the base design's: {json.dumps(base)}"
    )
    return "\n".join(head) + text


def design_name(base: str, label: str, trial: int | None) -> str:
    """A chosen design's ``[drive] name``: the base's, what the search made of it and the trial (the CSV's row);
    the base's cut short where the whole would pass the schema's 200 characters."""
    tail = f" - design {label}" + ("" if trial is None else f", trial {trial}")
    return base[: 200 - len(tail)] + tail


def trial_rows(res) -> tuple[list, list]:
    """``(header, rows)`` of every candidate for CSV: the free keys, the stage, feasibility, objectives, margins."""
    req = res.req
    keys = [fk.name for fk in req.free]
    header = ["trial", *keys, "stage", "feasible", *req.objectives, *[f"margin: {c}" for c in res.constraints]]
    rows = []
    for i, ev in enumerate(res.evaluations):
        rows.append(
            [
                i,
                *[ev.values.get(k) for k in keys],
                ev.stage,
                ev.feasible,
                *[_r(ev.objectives.get(o), 6) for o in req.objectives],
                *[_r(ev.margins.get(c), 6) for c in res.constraints],
            ]
        )
    return header, rows
