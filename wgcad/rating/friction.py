"""The datasheet's friction rows: efficiency against torque and speed, no-load running, starting and backdriving
torque, and the wind-up's hysteresis loop with friction, from the datasheet's own loaded states (docs/models.md 10.8)."""

from __future__ import annotations

from dataclasses import dataclass

from wgcad.friction import Efficiency, HysteresisLoop, efficiency_table, hysteresis_loop
from wgcad.friction.efficiency import FrictionSetup, friction_point

__all__ = ["FrictionRows", "friction_rows", "ASSUMPTIONS", "SPEEDS_RPM"]

#: the speeds the efficiency is tabulated at (the datasheet's own speed added)
SPEEDS_RPM = (500.0, 1000.0, 2000.0, 3500.0)

#: what the friction rows assume, in the order the datasheet states them
ASSUMPTIONS = (
    "first order in the friction: the losses are taken at the frictionless model's contact forces",
    "one state per torque stands for its whole mesh period (the model solves the generator at whole mesh periods)",
    "Coulomb friction in the tooth contacts with one coefficient, sliding and at rest ([load] tooth_friction)",
    "the bearing: Palmgren's load and viscous terms, its ball loads summed into the radial load of a rigid bearing "
    "with the same total (Stribeck's zero-clearance distribution); the seals' drag as [bearing] seal_torque_nmm "
    "gives it; no cage, no churning",
    "not in the losses: the flexspline bore sliding on the bearing's outer ring, the lubricant's churning in the "
    "teeth, the flexspline's material damping, the output bearing",
    "starting and backdriving torque: at creep speed (Palmgren's viscous term at its low-speed limit); "
    "backdriving with the input free",
    "hysteresis: the generator held, every contact slides as soon as the kinematics asks it to (no stick), "
    "negative torques mirror the positive ones",
)


@dataclass(frozen=True, slots=True)
class FrictionRows:
    """The friction of one datasheet: the coefficients, the efficiency table, the loop."""

    setup: FrictionSetup
    efficiency: Efficiency
    loop: HysteresisLoop
    rated: object  # the FrictionPoint of the rated torque


def friction_rows(model, dm_mm: float, speed_rpm: float, states, curve_states, rated_state) -> FrictionRows:
    """The rows from the datasheet's states: ``states`` for the efficiency (the unloaded one among them, torques up
    to the rated one), ``curve_states`` the wind-up from no load to the rated torque for the loop."""
    setup = FrictionSetup.of(model, dm_mm, speed_rpm)
    speeds = tuple(sorted(set(SPEEDS_RPM) | {float(speed_rpm)}))
    eff = efficiency_table(states, setup, speeds)
    loop = hysteresis_loop(curve_states, setup.mu)
    return FrictionRows(setup, eff, loop, friction_point(rated_state, setup))
