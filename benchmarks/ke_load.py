"""Benchmark of the KE under load (wgcad.accuracy.ke_load, docs/models.md 6.3): CPU time per load state and per torque.

Run from the repository root (not part of the test run, ~4 min):

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/ke_load.py

Case: D1 (templates/d1_involute.toml, which has a [bearing]) with run-out,
eccentricity and a stationary cam offset of a few tens of micrometres (the
errors of tests/test_ke_load.py), the default 404 load states over a
flexspline revolution, at 100 and 500 N m, against the no-load KE at the
same angles; and D2 with [S4]'s errors (templates/d2_imperfect.toml) at
[S4]'s 80 and 800 N m, with the rigid gear's installation angle under each
torque (the lever of `wgcad ke --optimize-install-angle --torque-nm`). CPU
time (single-threaded BLAS): the machine's load does not enter it.
"""

from __future__ import annotations

import json
import math
import os
import platform
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from wgcad.accuracy import ke as K  # noqa: E402
from wgcad.accuracy.ke_load import install_lever, loaded_ke  # noqa: E402
from wgcad.design import load_design  # noqa: E402
from wgcad.drive import build_drive  # noqa: E402
from wgcad.elastic import build_model  # noqa: E402
from wgcad.placement.imperfect import Imperfections  # noqa: E402

AS = 180.0 / math.pi * 3600.0


def main() -> None:
    print(
        json.dumps(
            {
                "machine": f"{platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}",
                "load_avg_1_5_15": [round(x, 2) for x in os.getloadavg()],
                "blas_threads": os.environ.get("OPENBLAS_NUM_THREADS"),
            }
        )
    )
    drive = build_drive(load_design(ROOT / "templates" / "d1_involute.toml"))
    imp = Imperfections(
        flex_runout=0.02, flex_runout_phase=math.radians(260), rigid_runout=0.02, cam_fixed=0.01, rigid_ecc=0.01
    )
    t = time.process_time()
    tab = K.contact_table(drive, imp)
    res = K.kinematic_error(drive, imp, table=tab)
    t_nl = time.process_time() - t
    t = time.process_time()
    model = build_model(drive)
    t_model = time.process_time() - t
    for T in (100.0, 500.0):
        t = time.process_time()
        L = loaded_ke(drive, imp, T, model=model)
        cpu = time.process_time() - t
        idx = L.periods * tab.N
        nl = res.ke[idx] - res.ke[idx[0]]
        print(
            json.dumps(
                {
                    "case": "D1 + errors",
                    "torque_nm": T,
                    "states": int(len(L.ke)),
                    "cpu_s": round(cpu, 2),
                    "ms_per_state": round(1e3 * cpu / len(L.ke), 1),
                    "loaded_ke_pp_arcsec": round(L.ke_pp * AS, 3),
                    "no_load_ke_pp_at_samples_arcsec": round(float(nl.max() - nl.min()) * AS, 3),
                    "no_load_ke_pp_arcsec": round(res.ke_pp * AS, 3),
                    "no_load_cpu_s": round(t_nl, 2),
                    "model_build_cpu_s": round(t_model, 3),
                    "teeth_in_contact": [int(L.teeth_in_contact.min()), int(L.teeth_in_contact.max())],
                }
            ),
            flush=True,
        )
    d2 = build_drive(load_design(ROOT / "templates" / "d2_imperfect.toml"))
    imp2 = Imperfections.from_spec(d2.design.imperfections)
    model2 = build_model(d2)
    for T in (80.0, 800.0):
        t = time.process_time()
        L = loaded_ke(d2, imp2, T, model=model2)
        cpu = time.process_time() - t
        t = time.process_time()
        lev = install_lever(d2, imp2, T, model=model2, design=L)
        cpu_lever = time.process_time() - t
        print(
            json.dumps(
                {
                    "case": "D2 [S4]",
                    "torque_nm": T,
                    "states": int(len(L.ke)),
                    "cpu_s": round(cpu, 2),
                    "ms_per_state": round(1e3 * cpu / len(L.ke), 1),
                    "loaded_ke_pp_arcsec": round(L.ke_pp * AS, 3),
                    "wind_up_arcsec": round(L.wind_up * AS, 1),
                    "teeth_in_contact": [int(L.teeth_in_contact.min()), int(L.teeth_in_contact.max())],
                    "lever_cpu_s": round(cpu_lever, 2),
                    "lever_best_deg": round(math.degrees(lev.best_angle), 2),
                    "lever_best_ke_pp_arcsec": round(lev.best.ke_pp * AS, 3),
                    "lever_ratio": round(L.ke_pp / lev.best.ke_pp, 3),
                }
            ),
            flush=True,
        )


if __name__ == "__main__":
    main()
