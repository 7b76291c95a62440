"""The elastic model of docs/models.md 4 on a sectored rigid gear: the contact solver's view of its variable-height
teeth, and the loaded drive at the motion law's knots (docs/models.md 2.3, 4.1).

The elastic model (:func:`wgcad.elastic.solve_load`) solves the drive with
the generator at angle 0, a flexspline tooth on the major axis, against the
rigid teeth of its clearance scene. A sectored drive stands like that at the
knots of its motion law (:class:`~wgcad.sector.motion.MotionLaw`: the major
axis on the middle of a rigid space, a flexspline tooth centred in it): there
the sectored rigid gear, turned by ``-phi_h`` into the generator's frame, is
posed for the solver by :class:`SectorContactScene`, and the model of the
plain drive is reused with that scene. Between knots a flexspline tooth is off
the axis, which the model's fixed tooth angles cannot pose: the loaded drive
is sampled at the knots, not followed between them.
"""

from __future__ import annotations

import dataclasses
import time
from math import pi

import numpy as np
import shapely

from ..clearance.distance import Template, signed_clearance
from ..placement import transform

__all__ = ["SectorContactScene", "KnotState", "sector_model", "solve_knot", "OFFSET_MM"]

#: The copies of the distinct tooth outlines stand this far apart in the shape set's frame, mm: far beyond any
#: tooth, so a point near one copy is nowhere near another (see :class:`_ShapeSet`).
OFFSET_MM = 1000.0


def _wrap(a):
    return (np.asarray(a) + pi) % (2.0 * pi) - pi


class _ShapeSet:
    """Every distinct rigid tooth outline in one frame, copy ``k`` moved by ``(k OFFSET_MM, 0)``: what the solver's
    contact geometry reads as the scene's one rigid tooth template (``polygon`` for the points inside, ``local`` for
    the nearest edge and its normal).

    Tooth ``j`` of outline ``k`` is then posed with its shift taking the offset back
    (:class:`SectorContactScene`), so each rigid tooth is measured against its own outline. ``local`` runs through
    the copies one after another, each closed on its first vertex and joined to the next by an edge along +x from
    that vertex, which lies on the body's outer closure: the joining edges run outside every tooth, away from the
    flanks and tips where teeth meet, and the nearest edge to any point near them is an edge of that tooth's own
    outline.
    """

    def __init__(self, outlines: list):
        self.offsets = np.array([[k * OFFSET_MM, 0.0] for k in range(len(outlines))])
        loops = []
        for o, off in zip(outlines, self.offsets):
            o = np.asarray(o, dtype=float)
            loops.append(np.concatenate([o, o[:1]]) + off)
        self.local = np.ascontiguousarray(np.concatenate(loops))
        self.local.setflags(write=False)
        self.polygon = shapely.MultiPolygon(
            [shapely.Polygon(np.asarray(o) + off) for o, off in zip(outlines, self.offsets)]
        )
        shapely.prepare(self.polygon)


class SectorContactScene:
    """What the elastic contact solver reads of a clearance scene (:class:`wgcad.clearance.engine.Scene`), for a
    sectored rigid gear of given tooth heights with the generator at ``phi_h`` (the gear turned by ``-phi_h``).

    Parameters
    ----------
    base : Scene
        The plain drive's scene (the flexspline tooth, the working flank).
    layout : SectorLayout
    teeth : TeethByHeight
    heights : (N,) float
        Every rigid tooth's height, mm.
    phi_h : float
        Generator angle, rad (a knot of the motion law, module docstring).
    """

    def __init__(self, base, layout, teeth, heights, phi_h: float):
        self.drive = base.drive
        self.z_g = base.z_g
        self.flex, self.flex_local, self.flex_tip_local = base.flex, base.flex_local, base.flex_tip_local
        self.working = base.working
        self.external = base.external
        h = np.asarray(heights, dtype=float)
        self.z_b = len(h)
        self.phi_h = float(phi_h)
        self.centres = np.asarray(layout.centres, dtype=float) - self.phi_h
        keys = [round(float(x), 12) for x in h]
        distinct = list(dict.fromkeys(keys))
        outlines = [teeth.gear(k).tooth_polygon() for k in distinct]
        which = np.array([distinct.index(k) for k in keys])
        shapes = [Template(o) for o in outlines]
        self.templates = [shapes[k] for k in which]
        self.rigid = _ShapeSet(outlines)
        self.rigid_rot = self.centres.copy()
        c, s = np.cos(self.rigid_rot), np.sin(self.rigid_rot)
        off = self.rigid.offsets[which]
        # R(rot) (p + off) + shift = R(rot) p: the shape set's copy lands on the tooth
        self.rigid_shift = -np.stack([c * off[:, 0] - s * off[:, 1], s * off[:, 0] + c * off[:, 1]], axis=-1)
        placed = [
            transform(o, np.array([r]), np.zeros((1, 2)))[0]
            for o, r in zip((outlines[k] for k in which), self.rigid_rot)
        ]
        n = max(len(p) for p in placed)
        # one array of every tooth's vertices (a shorter outline repeats its last vertex: a point counted twice)
        self.rigid_pts = np.stack([np.concatenate([p, np.repeat(p[-1:], n - len(p), axis=0)]) for p in placed])
        self.rigid_pts.setflags(write=False)
        self.rigid_geoms = np.array([shapely.Polygon(p) for p in placed], dtype=object)
        shapely.prepare(self.rigid_geoms)
        #: the smallest rigid tip radius (full-height teeth): the solver's radial candidate test is widest with it
        self.r_tip_b = float(np.min([np.hypot(*np.asarray(o).T).min() for o in outlines]))

    def neighbours(self, shift: np.ndarray, rot: np.ndarray):
        """Rigid teeth below and above each placed flexspline tooth (by the angle of its centre line), and the third nearest."""
        r = self.drive.r_m  # a point on the tooth's centre line
        a = np.arctan2(shift[:, 1] + r * np.sin(rot), shift[:, 0] + r * np.cos(rot))
        c = self.centres
        N = len(c)
        base = c[0]
        up = np.searchsorted((c - base) % (2.0 * pi), (a - base) % (2.0 * pi)) % N
        lo = (up - 1) % N
        near_lo = np.abs(_wrap(a - c[lo])) < np.abs(_wrap(a - c[up]))
        third = np.where(near_lo, (lo - 1) % N, (up + 1) % N)
        return lo, up, third

    def exact_gaps(self, rot: np.ndarray, shift: np.ndarray, rigid: np.ndarray) -> np.ndarray:
        """Signed clearance of flexspline teeth at poses ``(rot, shift)`` to rigid teeth ``rigid``, each against its own
        outline by the clearance engine (:func:`wgcad.clearance.distance.signed_clearance`), mm: the check of what the
        solver measured through :class:`_ShapeSet`."""
        out = np.empty(len(rigid))
        for j in np.unique(rigid):
            sel = np.nonzero(rigid == j)[0]
            out[sel] = signed_clearance(
                self.flex,
                rot[sel],
                shift[sel],
                self.templates[j],
                np.full(len(sel), self.rigid_rot[j]),
                np.zeros((len(sel), 2)),
            )
        return out


def sector_model(model, scene: SectorContactScene):
    """The elastic model of the plain drive (:func:`wgcad.elastic.build_model`) with the sectored scene: the ring,
    bearing, tooth compliance and tables are the drive's, the rigid teeth the sectored gear's (a cache of its own:
    the mounted pairs belong to the scene)."""
    return dataclasses.replace(model, scene=scene, cache={})


@dataclasses.dataclass(frozen=True)
class KnotState:
    """The loaded sectored drive near one knot of its motion law (lengths mm, angles rad, forces N).

    Attributes
    ----------
    knot : float
        The knot's generator angle.
    generator_angle : float
        The generator angle of the solved state: the knot plus the rim's rotation, where the loaded flexspline
        stands with a tooth on the major axis (:func:`solve_knot`).
    output_kinematic : float
        The motion law's flexspline rotation at ``generator_angle``.
    output_loaded : float
        The loaded flexspline's rotation there: the law's at the knot plus ``rim_rotation``.
    rim_rotation : float
        Rotation of the toothed rim against the rigid gear under the load, counter-clockwise, from the law's position
        at the knot.
    residual_rotation : float
        The rotation the last solve left (the part the elastic model turned as a rigid body).
    rigid_forces : (N,) float
        Normal force on every rigid tooth (all sections, both flanks).
    flex_teeth : int
        Flexspline teeth that carry load.
    reach : float
        Largest angle from the nearer wave end of a loaded flexspline tooth.
    check_mm : float
        Largest difference between the gaps the solver measured and the clearance engine's, each rigid tooth
        against its own outline, over the pairs the solver measured exactly (0 to round-off: the scene is exact).
    solves : int
    seconds : float
    state : LoadState
    """

    knot: float
    generator_angle: float
    output_kinematic: float
    output_loaded: float
    rim_rotation: float
    residual_rotation: float
    rigid_forces: np.ndarray
    flex_teeth: int
    reach: float
    check_mm: float
    solves: int
    seconds: float
    state: object = dataclasses.field(repr=False, compare=False)


#: :func:`solve_knot` turns the rigid gear again until the rim's own rotation moves a tooth by less than this, mm:
#: the elastic model's position tolerance (wgcad.elastic.state.POSITION_TOL)
SETTLE_TOL = 2e-4
_MAX_SETTLE = 8


def solve_knot(model, gear: dict, heights, motion, knot: float, torque_nm: float, warm=None) -> KnotState:
    """The loaded drive of ``gear`` (:func:`wgcad.sector.built.built_gear`) with rigid teeth of ``heights`` under
    ``torque_nm`` at the motion law's ``knot``, settled so that the elastic model's rigid turn of the rim is small.

    The elastic model turns its deformed rim as a rigid body against the rigid gear (docs/models.md 4.1): right for
    the small wind-up of a plain drive, not for the tenths of a degree a sectored drive's free play can take, where
    the teeth should follow the generator's wave. So the rigid gear is turned by the rotation found and the state
    solved again, until the rotation left moves a tooth by less than :data:`SETTLE_TOL`: the flexspline then stands
    with a tooth on the major axis, as the model poses it, at the generator angle ``knot + rim_rotation``.
    ``warm``: a :class:`KnotState` of a neighbouring knot, whose rim loads start the solve.
    """
    from ..elastic import solve_load
    from ..elastic.rim import loads_on_table, tooth_poses

    t0 = time.perf_counter()
    lay, teeth = gear["layout"], gear["teeth"]
    r_m = model.drive.r_m
    # a neighbouring knot's rim rotation is the first guess of this one's (the free play changes from knot to knot)
    turn, st = (0.0, None) if warm is None else (warm.rim_rotation, warm.state)
    for n in range(_MAX_SETTLE):
        scene = SectorContactScene(model.scene, lay, teeth, heights, knot + turn)
        m = sector_model(model, scene)
        # the warm start keeps the rim's loads and shift; its rotation is now the rigid gear's turn
        start = (
            None if st is None else dataclasses.replace(st, rigid=np.array([st.rigid[0], st.rigid[1], 0.0]), pairs=None)
        )
        st = solve_load(m, float(torque_nm), warm=start)
        rot = float(st.rigid[2])
        turn += rot
        if abs(rot) * r_m < SETTLE_TOL:
            break
    c = st.contacts
    t = np.nonzero(c["kind"] == 1)[0]
    loads = loads_on_table(m.tables, st.laws[0].psi, st.laws[0].loads)
    rot_t, shift = tooth_poses(m, loads, st.rigid)[:2]
    z_g = m.tables.z_g
    k = c["section"][t] * z_g + c["tooth"][t]
    lo, up, _ = scene.neighbours(shift[k], rot_t[k])
    j = np.where(c["flank"][t] == 0, lo, up)
    forces = np.zeros(scene.z_b)
    np.add.at(forces, j, c["force"][t])
    exact = c["gap_exact"][t]
    check = 0.0
    if exact.any():
        e = np.nonzero(exact)[0]
        check = float(np.abs(scene.exact_gaps(rot_t[k[e]], shift[k[e]], j[e]) - c["gap"][t][e]).max())
    loaded = c["force"][t] > 0
    per = 2.0 * pi / model.drive.design.drive.waves
    phi = c["phi"][t][loaded]
    reach = float(np.abs((phi + 0.5 * per) % per - 0.5 * per).max()) if loaded.any() else 0.0
    # the state turned the rigid gear by turn - rot and left rot to the model: the rim stands turn from the law
    return KnotState(
        knot=float(knot),
        generator_angle=float(knot + turn - rot),
        output_kinematic=float(motion(knot + turn - rot)),
        output_loaded=float(motion(knot) + turn),
        rim_rotation=float(turn),
        residual_rotation=rot,
        rigid_forces=forces,
        flex_teeth=int(len(np.unique(c["tooth"][t][loaded]))),
        reach=reach,
        check_mm=check,
        solves=n + 1,
        seconds=time.perf_counter() - t0,
        state=st,
    )
