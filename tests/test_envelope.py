"""The envelope of a flank in its motion (wgcad.envelope): the mating involute of a pair turning about fixed centres
in closed form, the motion's rates against differences, and on D1's law the envelope's tangency checked from the
positions alone (issue 25)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import TEMPLATES

from wgcad.design.files import load_design
from wgcad.drive import build_drive
from wgcad.envelope import LawMotion, RotationMotion, envelope, flank_pieces
from wgcad.profiles.gear import ToothSpec, make_gear


@pytest.mark.parametrize("z1, z2", [(40, 50), (100, 102), (30, 60)])
def test_an_involute_turning_about_fixed_centres_envelopes_the_mating_involute(z1, z2):
    """A pinion of z1 involute teeth inside a ring of z2 at the standard centre distance: every branch of its
    flank's envelope in the ring's frame has polar angle theta0 - inv(arccos(r_b2 / r)), the ring's involute of
    base radius r_b2 = m z2 cos(alpha) / 2. Measured deviation 5e-15 mm (z 40/50); held to 1e-8 mm, a thousandth of
    the issue's 0.01 um; the residual of every point below 1e-9 mm."""
    m, alpha = 1.0, np.deg2rad(20.0)
    pinion = make_gear(ToothSpec(z=z1, module=m, internal=False))
    inv = [p for p in flank_pieces(pinion, +1) if p.kind == "involute"]
    step = 1.2 / 800
    E = envelope(inv, RotationMotion(m * (z2 - z1) / 2.0, z1, z2), np.arange(-0.6, 0.6 + step / 2, step))
    assert len(E.t) > 50
    assert E.residual_mm.max() < 1e-9
    rb2 = m * z2 * np.cos(alpha) / 2.0
    r = np.hypot(*E.points.T)
    keep = r > rb2 * (1 + 1e-9)
    rk = r[keep]
    a = np.arccos(rb2 / rk)
    th = np.arctan2(E.points[keep, 1], E.points[keep, 0])
    # each point's involute phase, for either hand of the ring's involute (a contact beyond the base circle's
    # tangency traces the other hand): the same for every point of one branch, whatever t
    on = np.zeros(len(rk), dtype=bool)
    branches = 0
    for hand in (+1.0, -1.0):
        c = np.mod(th + hand * (np.tan(a) - a), 2 * np.pi)
        o = np.argsort(c)
        for g in np.split(o, np.flatnonzero(np.diff(c[o]) > 1e-9) + 1):
            if len(g) >= 3 and (rk[g] * np.ptp(c[g])).max() < 1e-8:
                on[g] = True
                branches += 1
    assert on.all(), f"{(~on).sum()} envelope points on no involute of base radius {rb2:g}"
    assert branches <= 8  # a few flanks of the ring, not a scatter


def test_the_motions_rates_are_their_derivatives():
    """The closed-form rates against central differences of the poses (h = 1e-6 rad: difference error ~1e-9)."""
    d = build_drive(load_design(TEMPLATES / "d1_involute.toml"))
    t = np.linspace(-1.0, 1.0, 9)
    h = 1e-6
    for mot in (
        LawMotion(d.law, d.r_m, d.design.drive.z_flex, d.design.drive.z_rigid),
        LawMotion(d.law_at(0.0), d.r_m, 200, 202),
        RotationMotion(1.0, 200, 202),
    ):
        r1, s1 = mot.pose(t + h)
        r0, s0 = mot.pose(t - h)
        dr, ds = mot.rate(t)
        assert np.abs((r1 - r0) / (2 * h) - dr).max() < 1e-7
        assert np.abs((s1 - s0) / (2 * h) - ds).max() < 1e-6 * max(1.0, np.abs(ds).max())


def _distance(piece, rot, shift, x):
    """Signed distance from ``x`` to the piece placed at ``(rot, shift)``, on 200 000 samples (chord error ~1e-12
    mm on these curves), with the sign of the flank's normal."""
    s = np.linspace(piece.t0, piece.t1, 200_000)
    p, dp = piece.point(s), piece.deriv(s)
    c, sn = np.cos(rot), np.sin(rot)
    P = np.stack([c * p[:, 0] - sn * p[:, 1], sn * p[:, 0] + c * p[:, 1]], axis=-1) + shift
    n = np.stack([c * dp[:, 1] + sn * dp[:, 0], sn * dp[:, 1] - c * dp[:, 0]], axis=-1)
    i = int(np.argmin(np.hypot(*(P - x).T)))
    return float(np.dot(x - P[i], n[i]) / np.linalg.norm(n[i]))


def test_on_d1s_law_the_envelope_touches_every_position_to_second_order():
    """The envelope of D1's flexspline flank under its four-force law: each point lies on the flank at its own
    parameter (distance below 1e-7 mm on the sampled flank) and the flank's distance from it grows with the
    square of the parameter's change, not linearly: halving the step quarters it (ratio 3.5..4.5), where a point
    that is not on the envelope halves it. Residuals below 1e-9 mm."""
    d = build_drive(load_design(TEMPLATES / "d1_involute.toml"))
    mot = LawMotion(d.law, d.r_m, d.design.drive.z_flex, d.design.drive.z_rigid)
    pieces = flank_pieces(d.flex, +1)
    E = envelope(pieces, mot, np.linspace(-1.2, 1.2, 2001))
    assert len(E.t) > 100 and E.residual_mm.max() < 1e-9
    rng = np.random.default_rng(7)
    for j in rng.choice(len(E.t), 12, replace=False):
        pc, t0, x = pieces[E.piece[j]], E.t[j], E.points[j]
        rot, shift = mot.pose(np.array([t0]))
        assert abs(_distance(pc, rot[0], shift[0], x)) < 1e-7
        dd = []
        for h in (2e-3, 1e-3):
            r2, s2 = mot.pose(np.array([t0 - h, t0 + h]))
            dd.append(abs(_distance(pc, r2[0], s2[0], x)) + abs(_distance(pc, r2[1], s2[1], x)))
        assert 3.5 < dd[0] / dd[1] < 4.5, (j, dd)


@pytest.mark.parametrize("name", ["d1_involute", "d1_cycloidal"])
def test_the_conjugate_flank_is_touched_and_never_crossed_over_the_pass(name):
    """The rigid flank conjugate to D1's flexspline tooth (involute, cycloidal), at the generator's centre
    section: at 6001 positions of tooth 0 over the generator angle -1.4..1.4 rad, its exact pieces (sampled every
    ~0.2 um) never cross the flank by more than the chords' own error (three sagittas, below 0.03 um) and come
    within 1 um of it (the smallest is the contact, 0 to a few nm). The flank's
    points are exact envelope points (residual below 1e-9 mm) joined by chords within 0.01 um of the envelope."""
    from wgcad.envelope.space import conjugate_flank

    d = build_drive(load_design(TEMPLATES / f"{name}.toml"))
    cf = conjugate_flank(d)
    assert len(cf.points) > 50
    assert cf.residual_mm.max() < 1e-9 and cf.sagitta_mm < 1e-5
    r_f = np.hypot(*cf.points.T)
    a_f = np.arctan2(cf.points[:, 1], cf.points[:, 0])
    o = np.argsort(r_f)
    r_f, a_f = r_f[o], a_f[o]
    pts = np.concatenate(
        [p.point(np.linspace(p.t0, p.t1, max(2, int(p.length() / 2e-4)))) for p in flank_pieces(d.flex, +1)]
    )
    t = np.linspace(-1.4, 1.4, 6001)
    rot, shift = cf.motion.pose(t)
    gaps = []
    for k in range(len(t)):
        c, s = np.cos(rot[k]), np.sin(rot[k])
        X = pts @ np.array([[c, s], [-s, c]]) + shift[k]
        r = np.hypot(*X.T)
        inside = (r > r_f[0]) & (r < r_f[-1])
        if not inside.any():
            continue
        a = np.arctan2(X[inside, 1], X[inside, 0])
        gaps.append(float(np.min(r[inside] * (np.interp(r[inside], r_f, a_f) - a))))
    gaps = np.array(gaps)
    # the flank between its exact points is read by interpolating angle against radius: a chord of its own, within
    # about the sagitta of the envelope on either side, so a touching tooth may read up to ~2 sagittas inside
    # (measured: d1_involute -1e-10 mm with sagitta 3e-8; d1_cycloidal -1.0e-5 mm with sagitta 4.7e-6)
    assert gaps.min() > -3.0 * max(cf.sagitta_mm, 1e-7), gaps.min()
    assert gaps.min() < 1e-3


@pytest.mark.parametrize("name", ["d1_involute", "d2"])
def test_the_audit_of_a_conjugate_pair_finds_contact_and_no_interference(name):
    """Issue 25: the design with [rigid] flanks = "conjugate" (its rigid gear made for the flexspline at the
    generator's centre section) audited by the clearance engine over a whole generator turn at that section, 0.5
    deg steps, refined on the exact pieces (the engine rebuilds the drive from the design for its finer polygons,
    so the design itself must say conjugate): no interference, and the smallest clearance is the contact, between
    -0.01 um and 1 um (measured -6e-12 um on D1, 3e-12 on D2); no dead travel: the backlash is nan (the
    engine finds the flanks touching) or below 1e-3 arcmin."""
    import dataclasses

    from wgcad.clearance import AuditSettings, audit

    design = load_design(TEMPLATES / f"{name}.toml")
    own = build_drive(design)
    conj_design = dataclasses.replace(design, rigid=dataclasses.replace(design.rigid, flanks="conjugate"))
    d = build_drive(conj_design)
    assert d.rigid.spec.form == "conjugate" and d.rigid.spec.z == own.rigid.spec.z
    z = design.generator.generator_z if own.coned else None
    st = AuditSettings(angles=np.deg2rad(np.arange(720) * 0.5), sections=[z], interference_tol=1e-3, refine=True)
    res = audit(d, st)
    assert not res.interference
    assert res.findings["min_clearance"].method == "exact"
    assert -1e-5 < res.min_clearance < 1e-3, res.min_clearance
    assert not (abs(np.rad2deg(res.backlash) * 60) > 1e-3)
    # the design's own rigid gear, for contrast, leaves um of play at the same section
    assert audit(own, st).min_clearance > 5e-3


def test_every_command_runs_on_the_conjugate_template(tmp_path, capsys):
    """templates/d1_conjugate.toml (D1 with [rigid] flanks = "conjugate"): generate, audit, the load audit, ke,
    parts and rating all run on it without a traceback. Its audit shows why coned cups need spatial teeth: made
    for the generator's centre line (z = 18 mm), the pair touches there (-6e-12 um), interferes at the open end
    where coning deepens the mesh (z = 0: -39.0 um) and gapes at the inner end (z = 30: 18.4 um)."""
    from wgcad.clearance import AuditSettings, audit
    from wgcad.cli import main

    t = str(TEMPLATES / "d1_conjugate.toml")
    runs = [
        (["generate", t, "--out", str(tmp_path / "g"), "--no-stl", "--quiet"], {0}),
        (["audit", t, "--quiet", "--json", str(tmp_path / "a.json")], {1}),  # interferes at the open end
        (["audit", t, "--torque-nm", "0,500", "--quiet"], {0, 1}),
        (["ke", t, "--per-mesh", "4"], {0}),
        (["parts", t, "--out", str(tmp_path / "p"), "--format", "dxf", "--quiet"], {0}),
    ]
    for args, codes in runs:
        assert main(args) in codes, args
        assert "Traceback" not in capsys.readouterr().err
    # the rigid gear's data block speaks of its flanks, not of a rack form it does not have (it printed the design's
    # profile shift 3.2 and "sampled cycloidal outline" for the conjugate gear)
    import ezdxf

    doc = ezdxf.readfile(tmp_path / "p" / "d1_conjugate_rigid.dxf")
    data = "\n".join(e.dxf.text for e in doc.modelspace().query("TEXT") if e.dxf.layer == "GEAR_DATA")
    assert "profile shift" not in data and "thinning" not in data and "cycloidal" not in data
    assert "conjugate to the flexspline" in data and "sampled conjugate outline" in data
    d = build_drive(load_design(t))
    assert d.rigid.spec.form == "conjugate"
    figs = {}
    for z in (0.0, 18.0, 30.0):
        res = audit(d, AuditSettings(angles=np.deg2rad(np.arange(720) * 0.5), sections=[z], interference_tol=1e-3))
        figs[z] = res.min_clearance
    assert figs[0.0] < -20e-3 and -1e-5 < figs[18.0] < 1e-3 and figs[30.0] > 5e-3


def test_a_conjugate_rigid_gear_is_built_once_per_design_and_tolerance():
    """The envelope is the costly part of building a conjugate drive: a process builds it once per design and chord
    tolerance (drive._CONJUGATES) and a changed design or tolerance gets its own, equal to a fresh build."""
    from wgcad import drive as drive_mod
    from wgcad.design import with_changes

    d = load_design(TEMPLATES / "d1_conjugate.toml")
    drive_mod._CONJUGATES.clear()
    a = build_drive(d)
    assert build_drive(d).rigid is a.rigid  # the same design again: the kept gear
    coarse = build_drive(d, tol=4e-3)
    assert coarse.rigid is not a.rigid and len(coarse.rigid.period) < len(a.rigid.period)
    backed = build_drive(with_changes(d, rigid={"conjugate_clearance_um": 5.0}))
    assert backed.rigid is not a.rigid
    # a kept gear is the gear a fresh build makes
    drive_mod._CONJUGATES.clear()
    fresh = build_drive(d)
    assert fresh.rigid is not a.rigid and np.array_equal(fresh.rigid.period, a.rigid.period)


def test_a_conjugate_drive_sampled_finer_keeps_its_exact_curves():
    """The audit's finer polygons (a flat minimum sorted out at a chord tolerance 8 times smaller) sample the same
    conjugate flank as the drive's own: its exact pieces are kept (not enveloped again at the finer tolerance) and
    every point of them lies within the finer tolerance of the finer polygon."""
    import shapely

    d = build_drive(load_design(TEMPLATES / "d1_conjugate.toml"))
    fine = d.sampled_at(d.tol / 8)
    assert fine.rigid.pieces is d.rigid.pieces and fine.rigid.tol == d.tol / 8
    assert len(fine.rigid.period) > len(d.rigid.period)
    pts = np.vstack([p.point(np.linspace(p.t0, p.t1, 400)) for p in d.rigid.pieces])
    gap = shapely.distance(shapely.LineString(fine.rigid.period), shapely.points(pts))
    # the pieces span a mirrored pitch; the period polygon runs -pi/z .. pi/z: the points on it are within tol / 8
    on = np.abs(np.arctan2(pts[:, 1], pts[:, 0])) <= np.pi / d.rigid.spec.z
    assert on.sum() > 1000 and gap[on].max() <= fine.rigid.tol * (1 + 1e-9)
    assert gap[on].max() > d.tol / 100  # the polygon is a sampling, not the curve: the test sees its chords


def test_a_conjugate_drive_pickles_with_its_sampler():
    """A drive goes to worker processes by pickle: its conjugate rigid gear carries its sampler as a record (a local
    function would not pickle), and the copy samples the same curves."""
    import pickle

    d = build_drive(load_design(TEMPLATES / "d1_conjugate.toml"))
    back = pickle.loads(pickle.dumps(d))
    assert np.array_equal(back.rigid.outline, d.rigid.outline)
    assert np.array_equal(back.sampled_at(d.tol / 8).rigid.period, d.sampled_at(d.tol / 8).rigid.period)


@pytest.mark.parametrize("name", ["d1_conjugate", "d1_double_arc"])
@pytest.mark.parametrize("tol", [1e-6, 5e-8])
def test_a_conjugate_rigid_gear_sampled_finely_is_within_the_tolerance_of_its_flank(name, tol):
    """The conjugate flank is a spline through the envelope's points, ~5e-6 mm of sagitta apart: sampled below that
    (the dense references of the clearance tests, a user's fine chord tolerance) its polygon must take the spline's
    own points between the knots. With the knots alone its chords lay 2.2 (D1 conjugate) and 3.3 (D1 double-arc)
    times 1e-6 mm and 44 and 65 times 5e-8 mm from the flank, the dense references 2-3 nm off the exact figures."""
    from wgcad.clearance.exact import ExactTooth, point_signed_distance

    d = build_drive(load_design(TEMPLATES / f"{name}.toml"))
    fine = d.sampled_at(tol)
    poly = fine.rigid.tooth_polygon()
    exact = ExactTooth(d.rigid, d.rigid.tooth_polygon())
    ends = np.abs(point_signed_distance(exact, poly))
    on = (ends[:-1] < 1e-12) & (ends[1:] < 1e-12)  # chords between points of the curve (not the body's closing edges)
    f = np.linspace(0.0, 1.0, 9)[1:-1]
    a, b = poly[:-1][on], poly[1:][on]
    pts = (a[:, None, :] * (1.0 - f)[None, :, None] + b[:, None, :] * f[None, :, None]).reshape(-1, 2)
    gap = np.abs(point_signed_distance(exact, pts))
    assert on.sum() > 100 and gap.max() <= tol * (1 + 1e-6)
    assert gap.max() > tol / 10  # a sampling at the tolerance, not the curve


@pytest.mark.xfail(
    strict=True,
    reason="known defect, not fixed: built at a chord tolerance of 1e-5 mm, D1 double-arc's flank takes two "
    "envelope points of another branch (generator angle -0.0415 rad, r = 82.930 mm, 0.011 um clear of every sampled "
    "position: inside the boundary test's margin of tol from 2e-5 mm up, outside it at 1e-5) and the spline "
    "bridges the 0.25 mm from them to the flank, the tip circle 82.936 mm instead of 83.182 (Drive.sampled_at, "
    "which the audit's finer polygons use, keeps the drive's own flank and is not affected)",
)
def test_the_conjugate_rigid_tooth_does_not_hang_on_the_chord_tolerance_it_is_enveloped_at():
    d = load_design(TEMPLATES / "d1_double_arc.toml")
    base = build_drive(d).rigid.r_a
    for tol in (1e-4, 2e-5, 1e-5):
        assert abs(build_drive(d, tol=tol).rigid.r_a - base) < 1e-3, tol
