"""``wgcad sector``: the sectored rigid gear of a discrete-motion drive: heights both ways, motion law, audit, DXF/STL."""

from __future__ import annotations

from pathlib import Path

from .common import EXIT_INTERFERENCE, EXIT_OK, add_memory_flag, epilog, out_dir, positive_float

__all__ = ["register", "cmd_sector"]


def _deg(x):
    import numpy as np

    return None if x is None or not np.isfinite(x) else round(float(np.rad2deg(x)), 6)


def _phases_json(law) -> list:
    import numpy as np

    out = []
    for p in law.phases():
        out.append(
            {
                "kind": p.kind,
                "start_deg": _deg(p.start),
                "end_deg": _deg(p.end),
                "length_deg": _deg(p.length),
                "output_step_deg": round(float(np.rad2deg(p.output_step)), 9),
                "ratio": None if not np.isfinite(p.ratio) else round(float(p.ratio), 9),
            }
        )
    return out


def _runs_json(law) -> list:
    import numpy as np

    return [
        {
            "kind": p.kind,
            "start_deg": _deg(p.start),
            "end_deg": _deg(p.end),
            "length_deg": _deg(p.length),
            "output_step_deg": round(float(np.rad2deg(p.output_step)), 9),
            "mean_ratio": None if not np.isfinite(p.ratio) else round(float(p.ratio), 9),
        }
        for p in law.runs()
    ]


def summary_json(res: dict) -> dict:
    """The figures of :func:`run_sector` as JSON-ready data (angles deg, lengths mm, clearances um)."""
    import numpy as np

    lay, cf, sim = res["layout"], res["closed_form"], res["simulated"]
    cs = lay.coupling_sector_teeth()
    law = res["motion"]
    return {
        "closed_form_parameters": {
            "r_fix_mm": round(cf.r_fix, 6),
            "r_cr_mm": round(cf.r_cr, 6),
            "h_s_mm": round(cf.h_s, 6),
            "W0_mm": round(cf.w0, 6),
            "beta_deg": _deg(cf.beta),
            "full_height_mm": round(cf.full, 6),
            "generator_angle_rule": cf.rule,
        },
        "heights_built": res["mode"],
        "tip_clearance_um": round(1e3 * res["tip_clearance"], 4),
        "first_coupling_sector": {
            "teeth": [int(i) for i in cs],
            "closed_form_mm": [round(float(x), 6) for x in cf.heights[cs]],
            "closed_form_boundary_mm": [round(float(x), 6) for x in res["closed_form_boundary"].heights[cs]],
            "simulated_mm": [round(float(x), 6) for x in sim.heights[cs]],
            "difference_um": [round(1e3 * float(x), 4) for x in sim.heights[cs] - cf.heights[cs]],
        },
        "transmission_teeth_lowered": [
            int(i) for i in np.nonzero(~lay.coupling & (res["built"] < res["full"] - 1e-12))[0]
        ],
        "motion_law": {
            "phases": _phases_json(law),
            "runs": _runs_json(law),
            "output_per_turn_deg": round(float(np.rad2deg(law.advance)), 9),
        },
        "audit_full_height": res["audit_full"].to_json(),
        "audit_built": res["audit_built"].to_json(),
        "timing_s": {"closed_form": round(cf.elapsed_s, 4), "simulated": round(sim.elapsed_s, 4)},
    }


def cmd_sector(args) -> int:
    import io
    import json

    import numpy as np

    from ..atomic import atomic_batch, check_writable_dir
    from ..design import load_design
    from ..design.budget import check_sector_budget
    from ..sector.scene import DEFAULT_STEP_DEG

    design = load_design(args.design)
    check_sector_budget(
        design.drive.z_flex, DEFAULT_STEP_DEG if args.step_deg is None else args.step_deg, args.max_memory_mb
    )
    out = out_dir(args, args.design)
    check_writable_dir(out)
    from .common import Progress, want_progress

    bar = Progress(want_progress(args.progress))
    bar.start("heights")
    from ..sector.run import run_sector

    res = run_sector(
        design, args.heights, args.assign, args.step_deg, args.tip_clearance_um, progress=lambda f, st: bar.set(f, st)
    )
    lay, cf, cfb, sim, built = (
        res["layout"],
        res["closed_form"],
        res["closed_form_boundary"],
        res["simulated"],
        res["built"],
    )
    drive, law = res["drive"], res["motion"]
    stem = Path(args.design).stem
    summ = summary_json(res)

    # heights table: every tooth
    cols = [
        "tooth",
        "sector",
        "kind",
        "index_in_sector",
        "centre_deg",
        "from_boundary_deg",
        "closed_form_mm",
        "assigned_generator_angle_deg",
        "tooth_angle_from_axis_deg",
        "w_mm",
        "closed_form_boundary_mm",
        "simulated_mm",
        "simulated_minus_closed_um",
        "built_mm",
    ]
    rows = []
    for i in range(lay.n_teeth):
        rows.append(
            [
                str(i),
                str(int(lay.sector[i])),
                lay.kinds[lay.sector[i]],
                str(int(lay.index[i])),
                f"{np.rad2deg(lay.centres[i]):.6f}",
                f"{np.rad2deg(lay.delta[i]):.6f}",
                f"{cf.heights[i]:.7f}",
                "" if not np.isfinite(cf.phi_h[i]) else f"{np.rad2deg(cf.phi_h[i]):.4f}",
                "" if not np.isfinite(cf.phi[i]) else f"{np.rad2deg(cf.phi[i]):.4f}",
                "" if not np.isfinite(cf.w[i]) else f"{cf.w[i]:.7f}",
                f"{cfb.heights[i]:.7f}",
                f"{sim.heights[i]:.7f}",
                f"{1e3 * (sim.heights[i] - cf.heights[i]):.4f}",
                f"{built[i]:.7f}",
            ]
        )
    heights_csv = ",".join(cols) + "\n" + "\n".join(",".join(r) for r in rows) + "\n"
    # motion law over a full turn
    phi_h = np.linspace(0.0, 2.0 * np.pi, 3601)
    phi_g = law(phi_h)
    phases = _phases_json(law)
    kind = np.full(len(phi_h), "move", dtype=object)
    for p in law.phases():
        if p.kind == "dwell":
            for shift in (0.0, 2 * np.pi, -2 * np.pi):
                kind[(phi_h >= p.start + shift - 1e-12) & (phi_h <= p.end + shift + 1e-12)] = "dwell"
    buf = io.StringIO()
    buf.write("generator_angle_deg,output_rotation_deg,phase\n")
    for a, g, k in zip(np.rad2deg(phi_h), np.rad2deg(phi_g), kind):
        buf.write(f"{a:.4f},{g:.9f},{k}\n")
    motion_csv = buf.getvalue()

    from ..export import sector_figures as sf

    bounds = np.rad2deg(lay.bounds)
    name = design.drive.name
    png_h = sf.heights_png(
        f"{name}: tooth heights (theory 2.3), both ways",
        np.rad2deg(lay.centres),
        bounds,
        lay.kinds,
        res["full"],
        cf.heights,
        sim.heights,
        built,
        boundary_mm=cfb.heights if cfb is not cf else None,
        tip_clearance_um=1e3 * res["tip_clearance"],
    )
    # motion phases for the plot over 0..360
    ph = []
    for p in phases:
        for shift in (-360.0, 0.0, 360.0):
            s, e = p["start_deg"] + shift, p["end_deg"] + shift
            if e > 0 and s < 360:
                ph.append({**p, "start_deg": max(s, 0.0), "end_deg": min(e, 360.0)})
    png_m = sf.motion_png(
        f"{name}: motion law (rigid gear fixed), {summ['motion_law']['output_per_turn_deg']:.4f} deg per generator turn",
        np.rad2deg(phi_h),
        np.rad2deg(phi_g),
        ph,
        list(bounds),
        lay.kinds,
    )
    curves = {
        "full height": 1e3 * res["audit_full"].per_tooth_tip,
        f"built ({res['mode']})": 1e3 * res["audit_built"].per_tooth_tip,
    }
    png_a = sf.audit_png(
        f"{name}: sectored audit over the cycle ({res['step_deg']:g} deg steps)",
        np.rad2deg(lay.centres),
        bounds,
        lay.kinds,
        curves,
        1e3 * res["audit_built"].interference_tol,
    )

    layers = None
    mesh = None
    from ..export.dxf import DxfLayer, write_dxf

    layers = [
        DxfLayer("RIGID_SECTORED", outlines=(res["outline"],), color=1),
        DxfLayer("RIGID_RIM", circles=((0.0, 0.0, drive.rigid_rim_radius),), color=1),
    ]
    if not args.no_stl:
        from ..export.stl import ring_solid, write_stl
        from .common import circle

        rim = circle(drive.rigid_rim_radius, drive.tol)
        mesh = ring_solid(rim, [res["outline"]], design.drive.face_width)
    with atomic_batch() as batch:
        Path(batch.temp_path(out / f"{stem}_heights.csv")).write_text(heights_csv)
        Path(batch.temp_path(out / f"{stem}_heights.png")).write_bytes(png_h)
        Path(batch.temp_path(out / f"{stem}_motion.csv")).write_text(motion_csv)
        Path(batch.temp_path(out / f"{stem}_motion.png")).write_bytes(png_m)
        Path(batch.temp_path(out / f"{stem}_sector_audit.png")).write_bytes(png_a)
        write_dxf(batch.temp_path(out / f"{stem}_sector_rigid.dxf"), layers)
        if mesh is not None:
            write_stl(batch.temp_path(out / f"{stem}_sector_rigid.stl"), mesh)
        Path(batch.temp_path(out / f"{stem}_sector.json")).write_text(
            json.dumps(summ, allow_nan=False, indent=2) + "\n"
        )
    bar.set(1.0, "done")
    bar.close()
    if args.json:
        print(json.dumps(summ, allow_nan=False, indent=2))
    else:
        _print_summary(name, res, summ, out)
    return EXIT_INTERFERENCE if res["audit_built"].has_tip_to_tip else EXIT_OK


def _print_summary(name, res, summ, out) -> None:

    p = summ["closed_form_parameters"]
    fc = summ["first_coupling_sector"]
    print(f"{name}: sectored rigid gear, {res['layout'].n_teeth} teeth in sectors {', '.join(res['layout'].kinds)}")
    print(
        f"  closed form h_i = r_fix - (r_cr + w(phi_i) + h_s): r_fix {p['r_fix_mm']:.4f} mm, r_cr {p['r_cr_mm']:.4f} mm, "
        f"h_s {p['h_s_mm']:.4f} mm, W0 {p['W0_mm']:.4f} mm, beta {p['beta_deg']} deg, full height {p['full_height_mm']:.4f} mm"
    )
    print(f"    phi_i: {p['generator_angle_rule']}")
    print("  first coupling sector, tooth heights (um): closed form | simulated | difference")
    for k, (a, b, dd) in enumerate(zip(fc["closed_form_mm"], fc["simulated_mm"], fc["difference_um"])):
        print(f"    {k:3d}  {1e3 * a:8.2f}  {1e3 * b:8.2f}  {dd:+8.2f}")
    if summ["transmission_teeth_lowered"]:
        print(f"  transmission teeth also lowered (joint teeth out of register): {summ['transmission_teeth_lowered']}")
    print(f"  motion law: {summ['motion_law']['output_per_turn_deg']:.6f} deg of output per generator turn")
    for r in summ["motion_law"]["runs"][:4]:
        ratio = (
            "output still"
            if r["mean_ratio"] is None
            else f"output {r['output_step_deg']:+.6f} deg, mean u = {r['mean_ratio']:.4f}"
        )
        print(
            f"    {r['kind']:5s} {r['start_deg']:9.4f} .. {r['end_deg']:9.4f} deg ({r['length_deg']:.4f} deg): {ratio}"
        )
    pieces = [p for p in summ["motion_law"]["phases"] if p["kind"] == "move"]
    seen, parts = set(), []
    for p_ in pieces:
        if p_["ratio"] not in seen:
            seen.add(p_["ratio"])
            parts.append(f"u = {p_['ratio']:.4g} over {p_['length_deg']:.4f} deg")
    print(f"    speed ratio in the move pieces (d phi_h / d phi_g): {'; '.join(parts)}")
    for key, label in (("audit_full", "full-height teeth"), ("audit_built", f"built heights ({res['mode']})")):
        a = res[key]
        where = ""
        if a.has_tip_to_tip:
            kinds = sorted({x["sector_kind"] for x in a.tip_to_tip})
            d = [x["rigid_tooth_from_boundary_deg"] for x in a.tip_to_tip]
            where = f" on {len(a.tip_to_tip)} teeth ({', '.join(kinds)}; {min(d):.2f} to {max(d):.2f} deg from a sector boundary)"
        tip = "TIP-TO-TIP" + where if a.has_tip_to_tip else "no tip-to-tip contact"
        print(
            f"  audit, {label}: {tip}; smallest tip clearance {1e3 * a.min_tip_clearance:.2f} um, "
            f"smallest flank clearance {1e3 * a.min_flank_clearance:.2f} um{' (flank interference)' if a.flank_interference else ''}"
        )
    print(
        f"  heights: closed form {res['closed_form'].elapsed_s:.2f} s, simulated {res['simulated'].elapsed_s:.2f} s; "
        f"sweep {res['step_deg']:g} deg over half a turn (identical waves; no mesh period)"
    )
    print(f"  wrote heights, motion (CSV, PNG), sector audit PNG, sectored rigid gear DXF/STL and JSON to {out}/")


def register(sub) -> None:
    """Add the subcommand to the ``wgcad`` parser's subparsers."""
    import argparse

    s = sub.add_parser(
        "sector",
        help="discrete-motion drive: sectored rigid gear, variable tooth heights, motion law, audit",
        epilog=epilog(one="teeth still meet tip to tip with the built heights"),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    s.add_argument("design", help="design file (TOML) with a [sectors] table, e.g. templates/d4_sectored.toml")
    s.add_argument("--out", help="output folder (default: output/<design name>)")
    s.add_argument("--progress", action="store_true", help="show the progress bar even when stderr is not a terminal")
    s.add_argument(
        "--heights",
        choices=("closed_form", "simulated", "full", "list"),
        default=None,
        help="which heights are built (default: [sectors] heights)",
    )
    s.add_argument(
        "--assign",
        choices=("register", "boundary"),
        default=None,
        help="closed form: how each tooth's generator angle is chosen (default: [sectors] assign)",
    )
    s.add_argument(
        "--step-deg",
        type=positive_float(0.0, 5.0, "deg"),
        default=None,
        help="generator-angle step of the sweeps (default 0.1)",
    )
    s.add_argument(
        "--tip-clearance-um",
        type=positive_float(-1e-12, 999.0, "um"),
        default=None,
        help="tip clearance the simulated heights keep (default: [sectors] tip_clearance_um)",
    )
    s.add_argument("--no-stl", action="store_true", help="skip the STL solid")
    s.add_argument("--json", action="store_true", help="print the summary as JSON")
    add_memory_flag(s)
    s.set_defaults(func=cmd_sector)
