"""Benchmark of the exporters on D1: time and size of every format, against today's polyline DXF / STL export in the same run.

Run from the repository root (not part of the test run):

    .venv/bin/python benchmarks/export.py                 # D1 involute and D1 cycloidal
    .venv/bin/python benchmarks/export.py --no-step       # skip STEP
    .venv/bin/python benchmarks/export.py --step-parts    # also STEP of the whole part set (slow: OCCT writes and reads)

Prints a Markdown table and writes it with the raw figures to
output/bench/export.{md,json}. Times are wall-clock best-of-N (N = 3, STEP
1) in one process after a warm-up; sizes are the bytes written; the arc
deviation is measured along every written arc (64 points per arc, foot on
the exact curve by Newton), not at the vertices.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from _timing import best_of  # noqa: E402

from wgcad.design import load_design  # noqa: E402
from wgcad.design.parts import load_parts, part_sizes  # noqa: E402
from wgcad.drive import build_drive  # noqa: E402

OUT = ROOT / "output" / "bench"


def bench(design_path: Path, step: bool, tmp: Path, parts_step: bool = False) -> list[dict]:
    from wgcad.cli.common import circle
    from wgcad.export.formats.arcs import arc_deviation, fit_gear, fit_pieces
    from wgcad.export.formats.dxf import DxfLayer, write_dxf
    from wgcad.export.formats.stl import ring_solid, write_stl
    from wgcad.export.formats.svg import write_svg
    from wgcad.export.formats.threemf import write_3mf
    from wgcad.export.parts import build_parts
    from wgcad.profiles.band import gear_band_outline

    design = load_design(design_path)
    drive = build_drive(design, tol=1e-3)
    stem = design_path.stem
    rows = []
    bw = design.drive.face_width

    def row(fmt, what, seconds, path, **kw):
        rows.append(
            {
                "design": stem,
                "format": fmt,
                "what": what,
                "seconds": seconds,
                "bytes": path.stat().st_size if path else None,
                **kw,
            }
        )

    for which, gear, rim in (
        ("flexspline", drive.flex, drive.flex_rim_radius),
        ("rigid", drive.rigid, drive.rigid_rim_radius),
    ):
        # generate's export: one LWPOLYLINE of the 1 um symmetric band, STL prism of it (building the
        # band is part of the time)
        p = tmp / f"{stem}_{which}_poly.dxf"
        t_b, band = best_of(lambda: gear_band_outline(gear))
        t, _ = best_of(lambda: write_dxf(p, [DxfLayer("G", outlines=(band,))]))
        row("dxf polyline (band)", which, t_b + t, p, vertices=len(band), arcs=0, max_dev_um=None, band_seconds=t_b)
        pieces = list(gear.pieces)
        t_fit, path = best_of(lambda: fit_gear(gear, 1e-3))
        p = tmp / f"{stem}_{which}_arcs.dxf"
        t_w, _ = best_of(lambda: write_dxf(p, [DxfLayer("G", paths=(path,))]))
        dev = arc_deviation(fit_pieces(pieces, 1e-3, closed=False), pieces, n_per_arc=256).max()
        dev_all = arc_deviation(path, pieces, n_per_arc=64).max()
        row(
            "dxf arcs",
            which,
            t_fit + t_w,
            p,
            vertices=len(path.vertices),
            arcs=path.n_arcs,
            max_dev_um=1e3 * max(dev, dev_all),
            fit_seconds=t_fit,
        )
        rim_c = circle(rim, 1e-3)
        mk = (
            (lambda: ring_solid(band, [rim_c], bw))
            if rim < min(gear.r_a, gear.r_f)
            else (lambda: ring_solid(rim_c, [band], bw))
        )
        t_m, mesh = best_of(mk)
        p = tmp / f"{stem}_{which}.stl"
        t_s, _ = best_of(lambda: write_stl(p, mesh))
        row("stl", which + " ring", t_m + t_s, p, triangles=len(mesh.faces))
    sizes = part_sizes(load_parts(design_path), drive)
    t_b, parts = best_of(lambda: build_parts(drive, sizes, tol=1e-3), n=1)
    for prt in parts:
        p = tmp / f"{stem}_{prt.name}.svg"
        t, _ = best_of(lambda: write_svg(p, prt.layers, prt.name))
        row("svg", prt.name, t, p)
        p = tmp / f"{stem}_{prt.name}_part.dxf"
        t, _ = best_of(lambda: write_dxf(p, prt.layers))
        row("dxf part (arcs + gear data)", prt.name, t, p)
        t_m, mesh = best_of(lambda: prt.mesh(), n=1)
        p = tmp / f"{stem}_{prt.name}_part.stl"
        t_s, _ = best_of(lambda: write_stl(p, mesh))
        row("stl part", prt.name, t_m + t_s, p, triangles=len(mesh.faces))
    p = tmp / f"{stem}_parts.3mf"
    t, _ = best_of(lambda: write_3mf(p, {q.name: q.mesh() for q in parts}))
    row("3mf", "3 parts", t, p)
    if step:
        from wgcad.export.formats.step import read_step, solid_props, write_step
        from wgcad.export.parts import kernel, recipe
        from wgcad.profiles.band import gear_band_outline

        # the two toothed rings as prisms of their arc outlines (the gears alone)
        for which, gear, rim in (
            ("flexspline", drive.flex, drive.flex_rim_radius),
            ("rigid", drive.rigid, drive.rigid_rim_radius),
        ):
            path = fit_gear(gear, 1e-3)

            def ring():
                teeth = recipe.path_loop(path, gear_band_outline(gear), "teeth")
                circle = recipe.circle_loop(rim, 1e-3, "rim")
                if rim < min(gear.r_a, gear.r_f):
                    return kernel.solid(recipe.prism(teeth, [circle], 0.0, bw), which)
                return kernel.solid(recipe.prism(circle, [teeth], 0.0, bw), which)

            t_sol, solid = best_of(ring, n=1)
            p = tmp / f"{stem}_{which}_ring.step"
            t_w, _ = best_of(lambda: write_step(p, solid), n=1)
            t_r, back = best_of(lambda: read_step(p), n=1)
            t_c, props = best_of(lambda: solid_props(back[0]), n=1)
            from wgcad.export.formats.arcs import path_area

            vol = abs(path_area(path) - np.pi * rim * rim) * bw
            row(
                "step",
                which + " ring",
                t_sol + t_w,
                p,
                read_seconds=t_r,
                check_seconds=t_c,
                valid=props["valid"],
                volume_rel_err=props["volume"] / vol - 1.0,
                faces=sum(props["faces"].values()),
            )
    if step and parts_step:
        from wgcad.export.formats.step import read_step, solid_props, write_step

        for prt in parts:
            t_sol, solid = best_of(lambda: prt.solid(), n=1)
            p = tmp / f"{stem}_{prt.name}.step"
            t_w, _ = best_of(lambda: write_step(p, solid), n=1)
            t_r, back = best_of(lambda: read_step(p), n=1)
            t_c, props = best_of(lambda: solid_props(back[0]), n=1)
            row(
                "step",
                prt.name,
                t_sol + t_w,
                p,
                read_seconds=t_r,
                check_seconds=t_c,
                valid=props["valid"],
                volume_rel_err=props["volume"] / prt.volume_mm3 - 1.0,
                faces=sum(props["faces"].values()),
            )
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--no-step", action="store_true", help="skip STEP")
    ap.add_argument(
        "--step-parts",
        action="store_true",
        help="also STEP of the whole part set (cup, plug, flanged rigid gear): slow",
    )
    ap.add_argument("--designs", default="d1_involute,d1_cycloidal")
    args = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as d:
        for name in args.designs.split(","):
            rows += bench(ROOT / "templates" / f"{name}.toml", not args.no_step, Path(d), args.step_parts)
    OUT.mkdir(parents=True, exist_ok=True)
    head = "| design | format | part | time s | size kB | vertices | arcs | max dev um | notes |\n|---|---|---|---|---|---|---|---|---|"
    lines = [head]
    for r in rows:
        notes = []
        if "valid" in r:
            notes.append(
                f"valid={r['valid']} vol err {r['volume_rel_err']:.1e} faces {r['faces']} read {r['read_seconds']:.1f} s check {r['check_seconds']:.1f} s"
            )
        if "triangles" in r:
            notes.append(f"{r['triangles']} triangles")
        if "fit_seconds" in r:
            notes.append(f"fit {r['fit_seconds']:.3f} s")
        dev = "" if r.get("max_dev_um") is None else f"{r['max_dev_um']:.3f}"
        lines.append(
            f"| {r['design']} | {r['format']} | {r['what']} | {r['seconds']:.3f} | "
            f"{(r['bytes'] or 0) / 1e3:.0f} | {r.get('vertices', '')} | {r.get('arcs', '')} | {dev} | {'; '.join(notes)} |"
        )
    md = "\n".join(lines)
    print(md)
    (OUT / "export.md").write_text(md + "\n")
    (OUT / "export.json").write_text(json.dumps(rows, indent=2, default=float) + "\n")


if __name__ == "__main__":
    main()
