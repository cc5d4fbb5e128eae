"""Choosing the cheapest fluid model that answers a vehicle scene's question (issue 7).

A vehicle scene with liquid cargo (a ``[fluid]`` section) can run its liquid as

* ``"rigid"``: rigid lading (the liquid's mass at its rest centroid), :func:`railslosh.vehicle.run`;
* ``"pendulum"``: the equivalent mechanical model, one slosh mass per compartment along one axis
  (``rail_mbs::vehicle::equivalent``), :func:`railslosh.vehicle.run_equivalent`;
* ``"ancf"``: the ANCF continuum, solved with the cars, :func:`railslosh.vehicle.run_fluid`.

``[fluid] slosh_model = "auto"`` (the default) applies this deterministic rule, in order:

1. a model other than ``"auto"`` is used as requested;
2. ``"ancf"`` if the outputs need the fluid's shape (``[outputs] snapshot_every > 0``: mesh
   snapshots for ParaView);
3. ``"ancf"`` on irregular track whose alignment or cross-level is not zero (a generated spectrum
   with those channels, a file, or a twist defect): it excites the liquid laterally and in roll
   over a broad band, and on FRA class 5 track the liquid moves the largest wheel unloading, L/V
   and load transfer ratio by up to −47 % and +84 % against rigid lading (docs/user-guide.md,
   "Bogie model"); the vertical profile alone leaves the rule below;
4. the excitations are estimated: longitudinal, the deceleration of the designed or tabulated brake
   torque ``a_x = n_braked 4 T_max / (r_wheel m_car cars)`` (0 for a train at rest); lateral, the
   largest unbalanced acceleration ``|v^2 kappa - g e / B|`` (``B`` = 1.5 m cant base) on the track
   the train covers during the run, at the train's (or driven) speed. An axis is excited when its
   estimate exceeds :data:`EXCITATION_THRESHOLD` (0.1 m/s^2);
5. ``"rigid"`` if neither axis is excited (no brake, tangent track, or curving within 0.1 m/s^2 of
   the balance speed);
6. ``"ancf"`` if both are (braking in a curve: the equivalent model represents one axis only);
7. ``"ancf"`` if the linear free-surface rise ``DYNAMIC_FACTOR (L/2) a / g`` exceeds
   :data:`RISE_LIMIT_FRACTION` of ``min(h, 2R - h)`` (the surface would reach the bottom or the
   top of the tank: nonlinear sloshing). ``L`` is the longest compartment's equivalent length
   (longitudinal) or the free-surface width ``2 w`` (lateral); ``DYNAMIC_FACTOR`` = 2 covers the
   dynamic overshoot of a suddenly applied acceleration;
8. otherwise ``"pendulum"`` on the excited axis.

The choice and its reason are recorded in the results (xarray attributes ``fluid_model`` and
``fluid_model_reason``) and printed by ``railslosh run``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from railslosh import rail, vehicle
from railslosh.constants import GRAVITY

__all__ = [
    "DYNAMIC_FACTOR",
    "EXCITATION_THRESHOLD",
    "FLUID_MODELS",
    "RISE_LIMIT_FRACTION",
    "SLOSH_MODELS",
    "FluidModelChoice",
    "choose_fluid_model",
    "decide",
]

SLOSH_MODELS = ("auto", "ancf", "pendulum", "rigid")
"""Values of ``[fluid] slosh_model`` (the model of the liquid in a vehicle run)."""
FLUID_MODELS = SLOSH_MODELS
"""Deprecated alias of :data:`SLOSH_MODELS` (one release)."""
EXCITATION_THRESHOLD = 0.1
"""m/s^2: an axis whose estimated acceleration is at most this is not excited."""
DYNAMIC_FACTOR = 2.0
"""Overshoot of the free-surface rise under a suddenly applied acceleration over its static value."""
RISE_LIMIT_FRACTION = 0.5
"""Largest linear free-surface rise, as a fraction of ``min(h, 2R - h)``, left to the pendulum model."""
CANT_BASE = rail.DEFAULT_CANT_BASE
G = GRAVITY


@dataclass(frozen=True)
class FluidModelChoice:
    """The fluid model of a scene and why (see the module docs)."""

    model: str
    """``"ancf"``, ``"pendulum"`` or ``"rigid"``."""
    reason: str
    axis: str | None
    """``"longitudinal"`` or ``"lateral"`` for the pendulum model, else ``None``."""
    accel_x: float
    """Estimated longitudinal (brake) deceleration, m/s^2."""
    accel_y: float
    """Estimated largest unbalanced lateral acceleration, m/s^2."""
    rise_ratio: float
    """Linear free-surface rise of the excited axis over its limit (0 if none excited)."""


def _brake_deceleration(sc: Any, params: dict[str, float], liquid_mass: float) -> float:
    if sc.brake_torques is None or not sc.brake_torques or sc.speed <= 0.0:
        return 0.0
    t_max = max(sc.brake_torques)
    factors = list(sc.brake_factors or [])
    factors += [1.0] * (sc.cars - len(factors))
    braked = sum(factors) if sc.brake_scope == "all" else factors[0]
    m_car = params["total_mass"] + sc.lading_mass + liquid_mass
    return braked * 4.0 * t_max / (params["wheel_radius"] * m_car * sc.cars)


def _lateral_acceleration(sc: Any, params: dict[str, float]) -> float:
    rows = np.asarray(sc.track_rows, dtype=float)
    speed = float(sc.drive) if not isinstance(sc.drive, bool) else sc.speed
    reach = params["coupler_reach"]
    rear = sc.station - (sc.cars - 1) * (2.0 * reach + 1.0) - reach
    front = sc.station + speed * sc.t_end + reach
    s = np.linspace(max(rear, rows[0, 0]), min(front, rows[-1, 0]), 2001)
    kappa = np.interp(s, rows[:, 0], rows[:, 1])
    e = np.interp(s, rows[:, 0], rows[:, 2])
    return float(np.max(np.abs(speed**2 * kappa - G * e / CANT_BASE)))


def _lateral_irregularity(sc: Any) -> list[str]:
    """The channels among alignment and cross-level that the scene's track irregularity has
    (not zero somewhere)."""
    irr = sc.track_irregularity()
    if irr is None:
        return []
    return [c for c in ("alignment", "cross_level") if np.any(getattr(irr, c) != 0.0)]


def decide(sc: Any) -> FluidModelChoice:
    """The fluid model of a vehicle scene (:class:`railslosh.scene.Scene`) by the rule of the module
    docs. A scene without ``[fluid]`` is ``"rigid"`` (its lading, if any, is rigid)."""
    f = sc.fluid
    if f is None:
        return FluidModelChoice("rigid", "no [fluid] section: rigid lading", None, 0.0, 0.0, 0.0)
    params = vehicle.tank_car_parameters(dict(sc.car) or None, sc.wheel_profile)
    geo = vehicle.equivalent_model(f.fill, bulkheads=list(f.bulkheads) or None, car=dict(sc.car) or None)
    r, h = params["tank_radius"], geo["depth"]
    liquid = f.mass(params)
    ax = _brake_deceleration(sc, params, liquid)
    ay = _lateral_acceleration(sc, params)
    limit = RISE_LIMIT_FRACTION * min(h, 2.0 * r - h)
    half_length = 0.5 * max(m["compartment_length"] for m in geo["modes"])
    half_width = math.sqrt(max(h * (2.0 * r - h), 0.0))
    rises = {
        "longitudinal": DYNAMIC_FACTOR * half_length * ax / G,
        "lateral": DYNAMIC_FACTOR * half_width * ay / G,
    }
    excited = [a for a, acc in (("longitudinal", ax), ("lateral", ay)) if acc > EXCITATION_THRESHOLD]
    axis = max(rises, key=lambda k: rises[k]) if rises["longitudinal"] != rises["lateral"] else "longitudinal"
    if len(excited) == 1:
        axis = excited[0]
    ratio = rises[axis] / limit if excited else 0.0
    est = f"a_x = {ax:.3g} m/s^2, a_y = {ay:.3g} m/s^2"

    def choice(model: str, reason: str) -> FluidModelChoice:
        return FluidModelChoice(model, reason, axis if model == "pendulum" else None, ax, ay, ratio)

    requested = getattr(f, "slosh_model", "auto")
    if requested != "auto":
        tail = f" ({axis} axis)" if requested == "pendulum" else ""
        return choice(requested, f'requested: [fluid] slosh_model = "{requested}"{tail}; {est}')
    if sc.outputs.snapshot_every > 0:
        return choice("ancf", "the outputs need the fluid shape (outputs.snapshot_every > 0)")
    lateral = _lateral_irregularity(sc)
    if lateral:
        return choice(
            "ancf",
            f"irregular track with {' and '.join(c.replace('_', '-') for c in lateral)}: the liquid moves the "
            "wheel-unloading, L/V and load-transfer extremes by up to 84 % against rigid lading "
            f'(docs/user-guide.md, "Bogie model"); {est}',
        )
    if not excited:
        return choice("rigid", f"no axis excited above {EXCITATION_THRESHOLD:g} m/s^2 ({est})")
    if len(excited) == 2:
        return choice("ancf", f"both axes excited ({est}): the pendulum model represents one axis")
    rise = rises[axis]
    if rise > limit:
        return choice(
            "ancf",
            f"{axis} free-surface rise {rise:.3g} m (x{DYNAMIC_FACTOR:g} dynamic) exceeds "
            f"{RISE_LIMIT_FRACTION:g} min(h, 2R - h) = {limit:.3g} m: nonlinear sloshing ({est})",
        )
    return choice(
        "pendulum",
        f"only the {axis} axis is excited ({est}); free-surface rise {rise:.3g} m within {limit:.3g} m",
    )


def choose_fluid_model(sc: Any) -> tuple[str, str]:
    """``(model, reason)`` of :func:`decide`."""
    c = decide(sc)
    return c.model, c.reason
