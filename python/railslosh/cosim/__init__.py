"""Co-simulation of the slosh model with vehicle codes (issue 6; seed 003).

* :mod:`~railslosh.cosim.protocol` — participant protocols and seed 003's motion interface;
* :mod:`~railslosh.cosim.interp` — interpolation/extrapolation over the last three samples;
* :mod:`~railslosh.cosim.emulators` — vehicle emulators (tank on springs, centrifuge arm) and the
  equivalent-pendulum slosh emulator with parameters from the tank geometry;
* :mod:`~railslosh.cosim.masters` — explicit serial, Aitken and IQN-ILS coupling, added-mass splitting;
* :mod:`~railslosh.cosim.monolithic` — the emulator pair as one ODE (reference);
* :mod:`~railslosh.cosim.centrifuge` — seed 003 §4.2: the added-mass instability and its threshold.

See docs/cosim.md.
"""

from railslosh.cosim.emulators import (
    CentrifugeArm,
    PendulumSlosh,
    SloshParameters,
    TankOnSprings,
    cylinder_lambda,
    horizontal_cylinder,
    rectangular_tank,
)
from railslosh.cosim.interp import ThreeSampleHistory
from railslosh.cosim.masters import CouplingResult, couple
from railslosh.cosim.protocol import MOTION_KEYS, SloshParticipant, VehicleParticipant

__all__ = [
    "MOTION_KEYS",
    "CentrifugeArm",
    "CouplingResult",
    "PendulumSlosh",
    "SloshParameters",
    "SloshParticipant",
    "TankOnSprings",
    "ThreeSampleHistory",
    "VehicleParticipant",
    "couple",
    "cylinder_lambda",
    "horizontal_cylinder",
    "rectangular_tank",
]
