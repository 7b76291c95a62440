"""Write tests/baselines/elastic_d1_reference.json: D1 load states from the re-linearised solver as it was before the
precomputed-table rewrite (commit 5dc0539: exact polygon geometry of every tooth pair at every pass).

Kept as the reference the fast solver is compared with (tests/test_elastic_reference.py). Run from the repository root
at that commit:  PYTHONPATH=. python tests/baselines/make_elastic_reference.py
"""

import json
import subprocess
from pathlib import Path

import numpy as np

from wgcad.deformation.elastic import build_model, solve_load
from wgcad.deformation.elastic.mesh import entry_gap
from wgcad.design import load_design
from wgcad.drive import build_drive

ROOT = Path(__file__).resolve().parents[2]
CASES = [("d1_involute", 0.0, 0.0), ("d1_involute", 1000.0, 0.0), ("d1_involute", 3000.0, 0.0),
         ("d1_involute", 1000.0, 40.0), ("d1_cycloidal", 1500.0, 0.0)]
PHI = np.linspace(-np.pi, np.pi, 181)


def main():
    out = {"commit": subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True, cwd=ROOT).stdout.strip(),
           "phi_grid": "linspace(-pi, pi, 181)", "cases": []}
    models = {}
    for name, T, e in CASES:
        if name not in models:
            models[name] = build_model(build_drive(load_design(ROOT / "templates" / f"{name}.toml")), 3)
        m = models[name]
        st = solve_load(m, T, e, 0.0)
        c = st.contacts
        tooth = c["kind"] == 1
        loaded = tooth & (c["force"] > 0)
        case = {"design": name, "torque_nm": T, "cam_offset_um": e, "rigid": st.rigid.tolist(),
                "wind_up": st.wind_up, "residuals": {k: float(v) for k, v in st.residuals.items()},
                "ball_force": c["force"][~tooth].tolist(),
                "tooth_contacts": [[int(s), int(t), int(f), float(F)] for s, t, f, F in
                                   zip(c["section"][loaded], c["tooth"][loaded], c["flank"][loaded], c["force"][loaded])],
                "sections": []}
        for i, law in enumerate(st.laws):
            s = law.state(PHI)
            g = [entry_gap(m.scene, law.shifted(p))[0] for p in (0.0, np.pi)]
            case["sections"].append({"w": s.w.tolist(), "v": s.v.tolist(), "theta": s.theta.tolist(), "entry_gap": g})
        out["cases"].append(case)
        print(name, T, e, st.residuals["iterations"])
    (ROOT / "tests" / "baselines" / "elastic_d1_reference.json").write_text(json.dumps(out) + "\n")


if __name__ == "__main__":
    main()
