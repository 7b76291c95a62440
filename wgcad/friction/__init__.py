"""Friction in the loaded drive: the tooth contacts' Coulomb losses from the elastic model's forces and the placement's
sliding, the wave-generator bearing's Palmgren torque, and from them efficiency, running, starting and backdriving
torque and the wind-up's hysteresis loop (docs/models.md 10.8)."""

from .bearing import BearingFriction, bearing_friction, palmgren_torque, static_rating
from .efficiency import Efficiency, FrictionPoint, backdriving_torque, efficiency_table, friction_point
from .hysteresis import HysteresisLoop, hysteresis_loop
from .teeth import ToothFriction, tooth_friction

__all__ = [
    "BearingFriction",
    "bearing_friction",
    "palmgren_torque",
    "static_rating",
    "ToothFriction",
    "tooth_friction",
    "FrictionPoint",
    "Efficiency",
    "friction_point",
    "efficiency_table",
    "backdriving_torque",
    "HysteresisLoop",
    "hysteresis_loop",
]
