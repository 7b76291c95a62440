"""How much tooth engagement a loaded drive keeps: the radial depth by which the flexspline's tips still reach past the rigid gear's, per wave (docs/models.md 10.6).

Ratcheting (the teeth skipping) needs every tooth of a wave to come out of
engagement: the tooth forces' radial parts push the rim in against the
generator until the deepest flexspline tip of the wave no longer reaches past
the rigid gear's tip circle. The depth here is that of the tips as the loaded
rim carries them (radial displacement ``w`` of the loaded neutral line; the
tooth's tilt ``theta`` moves its tip radially by less than ``theta^2`` times
the tip's half thickness, below 0.01 um on D1). The criterion is an upper
bound: friction and the tips' rounding let a real drive skip somewhat earlier.
"""

from __future__ import annotations

from math import pi

import numpy as np

__all__ = ["engagement_depth"]

_SAMPLES = 720


def engagement_depth(state) -> np.ndarray:
    """``(2,)``: for each wave (major axis at 0 and at pi) the largest depth of engagement over its teeth and the
    drive's sections, mm (negative: the wave has come out of mesh)."""
    d = state.model.drive
    flex, rigid = d.flex, d.rigid
    out = []
    for centre in (0.0, pi):
        phi = centre + np.linspace(-0.5 * pi, 0.5 * pi, _SAMPLES)
        best = -np.inf
        for law in state.laws:
            w = law.state(phi).w
            best = max(best, float(np.max(flex.r_a + law.tooth_offset + w - rigid.r_a)))
        out.append(best)
    return np.array(out)
