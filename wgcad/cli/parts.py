"""``wgcad parts``: the parts a shop makes (cup flexspline, generator plug, rigid gear, deformed assembly) as DXF, SVG, STL, 3MF and STEP."""

from __future__ import annotations

import argparse
import time

from ..design import load_design
from ..design.bolting import RULE
from ..design.parts import load_parts
from ..drive import build_drive
from ..export.files.parts import FORMATS, write_part_files
from ..export.formats.json_text import json_text
from ..rating.plate_sizing import sized_parts
from .bounds import bounded
from .common import COMMAND_HELP, EXIT_OK, Progress, angles_deg, epilog, out_dir, want_progress
from .outputs import check_output_dir

__all__ = ["register", "cmd_parts", "FORMATS"]


def formats(text: str) -> list[str]:
    out = []
    for part in text.split(","):
        part = part.strip().lower()
        if part not in FORMATS:
            raise argparse.ArgumentTypeError(f"'{part}' is not a format (choose from {', '.join(FORMATS)})")
        if part not in out:
            out.append(part)
    return out


def cmd_parts(args) -> int:
    t0 = time.perf_counter()

    # the folder is judged before any work, not after the parts are built
    out = check_output_dir(out_dir(args, args.design))
    bar = Progress(want_progress(args.progress) and (args.progress or not args.quiet))
    bar.start("reading the design")
    design = load_design(args.design)
    spec = load_parts(args.design)
    drive = build_drive(design, tol=args.chord_tol_um * 1e-3)
    sizes = sized_parts(spec, drive)  # every fit rule is checked here or while building: before anything is written
    res = write_part_files(
        drive,
        sizes,
        args.design,
        out,
        formats=args.format,
        dxf_style=args.dxf_style,
        generator_angles_deg=args.generator_angle or [],
        progress=bar.set,
    )
    bar.close()
    if args.json:
        print(json_text(res.report))
    elif not args.quiet:
        print(f"{design.drive.name}: {len(res.parts)} parts ({', '.join(p.name for p in res.parts)})")
        for p in res.parts:
            if "kind" in p.info:
                print(f"  {p.name}: {p.info['kind']}")
        if sizes.derived:
            print("  derived sizes (set them in [parts] to change them):")
            print("    " + ", ".join(f"{k} = {sizes.values[k]:g}" for k in sizes.derived))
        by_rule = {}
        for k, rule in sizes.rules.items():
            if k != "diaphragm_thickness":
                by_rule.setdefault(rule, []).append(k.split("_")[0])
            else:
                print(f"  {k}: {rule}")
        for rule, keys in by_rule.items():
            print(f"  {' and '.join(dict.fromkeys(keys))} bolts: {rule}")
        if any(r[:1].isdigit() for r in sizes.rules.values()):
            print(f"    ({RULE})")
        for n in sizes.notes:
            print(f"  WARNING: {n}")
        print(f"\n  wrote {len(res.files)} files to {out}/ in {time.perf_counter() - t0:.2f} s")
    return EXIT_OK


def register(sub) -> None:
    """Add the subcommand to the ``wgcad`` parser's subparsers."""
    g = sub.add_parser(
        "parts",
        help=COMMAND_HELP["parts"],
        epilog=epilog(five="STEP needs build123d: pip install 'wgcad[cad]'"),
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
        type=bounded("parts", "--chord-tol-um"),
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
