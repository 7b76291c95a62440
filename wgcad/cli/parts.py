"""``wgcad parts``: the parts a shop makes (cup flexspline, generator plug, rigid gear, deformed assembly) as DXF, SVG, STL, 3MF and STEP."""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from .common import EXIT_OK, angles_deg, epilog, out_dir, positive_float

__all__ = ["register", "cmd_parts", "FORMATS"]

FORMATS = ("dxf", "svg", "stl", "3mf", "step")


def formats(text: str) -> list[str]:
    out = []
    for part in text.split(","):
        part = part.strip().lower()
        if part not in FORMATS:
            raise argparse.ArgumentTypeError(f"'{part}' is not a format (choose from {', '.join(FORMATS)})")
        if part not in out:
            out.append(part)
    return out


def _jsonable(v):
    if isinstance(v, dict):
        return {
            k: _jsonable(x) for k, x in v.items() if k not in ("plug_outline", "neutral_line", "meshes", "build_meshes")
        }
    if isinstance(v, float):
        return round(v, 6)
    return v


def cmd_parts(args) -> int:
    t0 = time.perf_counter()
    from ..atomic import atomic_batch, check_writable_dir
    from ..design import load_design
    from ..design.parts import load_parts, part_sizes
    from ..drive import build_drive
    from ..errors import GeometryError
    from ..export.parts import build_parts
    from .common import Progress, want_progress

    bar = Progress(want_progress(args.progress) and (args.progress or not args.quiet))
    bar.start("reading the design")
    design = load_design(args.design)
    spec = load_parts(args.design)
    tol = args.chord_tol_um * 1e-3
    drive = build_drive(design, tol=tol)
    sizes = part_sizes(spec, drive)  # every fit rule is checked here or while building: before anything is written
    parts = build_parts(drive, sizes, style=args.dxf_style, tol=tol, generator_angles_deg=args.generator_angle or [])
    fmts = args.format
    out = out_dir(args, args.design)
    stem = Path(args.design).stem
    # the bar's steps weighted by what they cost (D1: a mesh ~0.2 s, a STEP solid ~0.8 s and its file ~0.9 s,
    # a DXF/SVG/STL file ~0.05 s; OCP's import ~0.5 s on the first solid): it moves with the work
    step_parts = [p for p in parts if not p.name.startswith("assembly")] if "step" in fmts else []
    n_mesh = len(parts) if {"stl", "3mf"} & set(fmts) else 0
    total = 1.0 + 1.0 * n_mesh + 4.0 * len(step_parts) + 0.5 * len(parts) + 4.0 * len(step_parts)
    done = 1.0
    bar.set(done / total, "meshes" if n_mesh else "solids")
    # build everything before the output folder is touched
    meshes = {}
    if n_mesh:
        for p in parts:
            bar.set(done / total, f"mesh: {p.name}")
            m = p.mesh()
            if not m.is_watertight:
                raise GeometryError(f"{p.name}: mesh is not watertight")
            meshes[p.name] = m
            done += 1.0
    solids = {}
    for p in step_parts:
        bar.set(done / total, f"STEP solid: {p.name}")
        solids[p.name] = p.solid()
        done += 4.0
    check_writable_dir(out)
    files = []
    report = {
        "design": str(args.design),
        "chord_tol_mm": tol,
        "dxf_style": args.dxf_style,
        "formats": fmts,
        # only the sizes of parts this drive has (an external drive has no cup and no flange)
        "sizes_mm": _jsonable({k: sizes.values[k] for k in sizes.used if sizes.values.get(k) is not None}),
        "derived_from_gear_size": list(sizes.derived),
        "size_rules": dict(sizes.rules),
        "warnings": list(sizes.notes),
        "parts": {},
    }
    with atomic_batch() as batch:

        def target(name):
            path = out / name
            files.append(path)
            return batch.temp_path(path)

        for p in parts:
            bar.set(done / total, f"files: {p.name}")
            entry = {"volume_mm3": round(p.volume_mm3, 4), **_jsonable(p.info)}
            report["parts"][p.name] = entry
            if p.layers and "dxf" in fmts:
                from ..export.dxf import write_dxf

                write_dxf(target(f"{stem}_{p.name}.dxf"), p.layers)
            if p.layers and "svg" in fmts:
                from ..export.svg import write_svg

                write_svg(target(f"{stem}_{p.name}.svg"), p.layers, f"{design.drive.name}: {p.name}")
            if "stl" in fmts:
                from ..export.stl import write_stl

                write_stl(target(f"{stem}_{p.name}.stl"), meshes[p.name])
            if "step" in fmts and p.name in solids:
                from ..export.step import write_step

                bar.set(done / total, f"STEP file: {p.name}")
                write_step(target(f"{stem}_{p.name}.step"), {p.name: solids[p.name]})
                done += 4.0
            done += 0.5
        if "3mf" in fmts:
            from ..export.threemf import exploded, write_3mf

            # the parts side by side (issue 23: assembled at the origin they shared 1234 mm^3, which a slicer takes
            # for intersecting objects); the deformed assemblies below stay assembled: that is what they show
            own = {p.name: meshes[p.name] for p in parts if not p.name.startswith("assembly")}
            write_3mf(target(f"{stem}_parts.3mf"), own, exploded(own))
            for p in parts:
                if p.name.startswith("assembly"):
                    write_3mf(target(f"{stem}_{p.name}.3mf"), {f"{p.name}_{k}": m for k, m in p.info["meshes"].items()})
        # named by the design, as every other file here: two designs can share a folder
        report["files"] = [f.name for f in files] + [f"{stem}_parts.json"]
        Path(target(f"{stem}_parts.json")).write_text(json.dumps(report, allow_nan=False, indent=2) + "\n")
        files.pop()
    bar.set(1.0, "done")
    bar.close()
    if args.json:
        print(json.dumps(report, allow_nan=False, indent=2))
    elif not args.quiet:
        print(f"{design.drive.name}: {len(parts)} parts ({', '.join(p.name for p in parts)})")
        for p in parts:
            if "kind" in p.info:
                print(f"  {p.name}: {p.info['kind']}")
        if sizes.derived:
            print("  derived sizes (set them in [parts] to change them):")
            print("    " + ", ".join(f"{k} = {sizes.values[k]:g}" for k in sizes.derived))
        by_rule = {}
        for k, rule in sizes.rules.items():
            by_rule.setdefault(rule, []).append(k.split("_")[0])
        for rule, keys in by_rule.items():
            print(f"  {' and '.join(dict.fromkeys(keys))} bolts: {rule}")
        if any(r[:1].isdigit() for r in sizes.rules.values()):
            from ..design.bolting import RULE

            print(f"    ({RULE})")
        for n in sizes.notes:
            print(f"  WARNING: {n}")
        print(f"\n  wrote {len(files) + 1} files to {out}/ in {time.perf_counter() - t0:.2f} s")
    return EXIT_OK


def register(sub) -> None:
    """Add the subcommand to the ``wgcad`` parser's subparsers."""
    g = sub.add_parser(
        "parts",
        help="write the parts a shop makes: cup flexspline, generator plug, rigid gear (DXF, SVG, STL, 3MF, STEP)",
        epilog=epilog(),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    g.add_argument("design", help="design file (TOML); sizes of the parts from its optional [parts] table")
    g.add_argument("--out", help="output folder (default: output/<design name>)")
    g.add_argument(
        "--format",
        type=formats,
        default=list(FORMATS),
        metavar="FMT[,FMT...]",
        help=f"file formats to write (default all: {','.join(FORMATS)})",
    )
    g.add_argument(
        "--dxf-style",
        choices=("arcs", "polyline"),
        default="arcs",
        help="tooth outlines in DXF/SVG as tangent arcs (default) or straight segments",
    )
    g.add_argument(
        "--chord-tol-um",
        type=positive_float(0.0, 100.0, "um"),
        default=1.0,
        help="largest distance between written geometry and exact curve, um (default 1)",
    )
    g.add_argument(
        "--generator-angle",
        type=angles_deg,
        metavar="DEG[,DEG...]",
        help="also write the deformed assembly (STL/3MF meshes) at these generator angles, degrees",
    )
    g.add_argument("--json", action="store_true", help="print DESIGN_parts.json to stdout instead of the summary")
    g.add_argument("--quiet", action="store_true", help="print nothing on success")
    g.add_argument("--progress", action="store_true", help="show the progress bar even when stderr is not a terminal")
    g.set_defaults(func=cmd_parts)
