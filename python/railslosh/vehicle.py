"""Rail vehicles: the freight tank car of the crude-oil paper (seed 000 §8.1, 68 DOF) and trains
of such cars joined by couplers, run on a track with rigid lading.

    >>> from railslosh import rail, vehicle
    >>> track = rail.Track([0, 5000], curvature=[1 / 1000] * 2, superelevation=[0.0425] * 2)
    >>> res = vehicle.run(track, speed=60 / 3.6, drive=True, t_end=2.0, lading_mass=36e3, lading_height=-0.5)
    >>> res["wheel_vertical"].shape   # (samples, wheelsets, [left, right]), N
    >>> res["l_over_v"], res["unloading"], res["coupler_force"]

Every car parameter has a documented default (``tank_car_parameters()`` lists them with the
DOF count; sources in the Rust docs of ``rail_mbs::vehicle::TankCarParams``) and can be
overridden with ``car={"wheelbase": 1.778, ...}``. Units are SI; wheel arrays are ordered front to
rear over all cars, ``[left, right]`` looking forward; lateral forces are positive to the track's
left; coupler forces are positive in tension.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from railslosh import _core
from railslosh.slosh import SimulationError

__all__ = ["run", "tank_car_parameters"]


def tank_car_parameters(car: dict[str, float] | None = None, wheel_profile: str = "s1002") -> dict[str, float]:
    """Default (or overridden) scalar parameters of the tank car, its total mass and DOF count."""
    return dict(_core.tank_car_parameters(car, wheel_profile))


def _table(track: Any) -> list[list[float]]:
    if hasattr(track, "table"):
        rows = np.asarray(track.table() if callable(track.table) else track.table, dtype=float)
    else:
        rows = np.asarray(track, dtype=float)
    if rows.ndim != 2 or rows.shape[1] != 6:
        raise ValueError(
            "invalid parameter `track`: allowed a rail.Track or rows (s, curvature, superelevation, grade, "
            f"cant_right, cant_left), got shape {rows.shape}"
        )
    return rows.tolist()


def run(
    track: Any,
    *,
    cars: int = 1,
    station: float = 50.0,
    speed: float = 0.0,
    t_end: float = 1.0,
    step: float = 1e-3,
    record_every: float = 0.01,
    drive: bool | float = False,
    brake: tuple[Sequence[float], Sequence[float]] | None = None,
    brake_scope: str = "all",
    lading_mass: float = 0.0,
    lading_height: float = 0.0,
    wheel_profile: str = "s1002",
    wheelset_lateral_offset: float = 0.0,
    coupler_stiffness: float | None = None,
    coupler_damping: float | None = None,
    car: dict[str, float] | None = None,
) -> dict[str, Any]:
    """Run ``cars`` coupled tank cars on ``track`` and return arrays of wheel loads ``Q``
    (``wheel_vertical``), lateral wheel forces ``Y``, ``l_over_v``, the wheel ``unloading`` ratio
    ``(Q0 - Q)/Q0``, ``coupler_force``, tank stations and speeds, and solver statistics.

    ``drive=True`` holds the front car to ``speed`` with the trajectory constraint (a number gives
    another speed); ``brake=(times, torques)`` applies that torque (N m) to every wheelset of the
    braked cars (``brake_scope`` ``"all"`` = ECP, ``"front"`` = front car only).

    Raises ``ValueError`` naming a bad field, and :class:`railslosh.slosh.SimulationError` (with
    ``.results`` up to the failure) when the run stops early.
    """
    drive_speed = None
    if drive is True:
        drive_speed = float(speed)
    elif drive is not False:
        drive_speed = float(drive)
    times, torques = (None, None) if brake is None else (list(map(float, brake[0])), list(map(float, brake[1])))
    res = dict(
        _core.run_train(
            _table(track),
            cars=cars,
            station=station,
            speed=speed,
            t_end=t_end,
            step=step,
            record_every=record_every,
            drive_speed=drive_speed,
            brake_times=times,
            brake_torques=torques,
            brake_scope=brake_scope,
            lading_mass=lading_mass,
            lading_height=lading_height,
            wheel_profile=wheel_profile,
            wheelset_lateral_offset=wheelset_lateral_offset,
            coupler_stiffness=coupler_stiffness,
            coupler_damping=coupler_damping,
            car=car,
        )
    )
    if "error" in res:
        t_last = res["t"][-1] if len(res["t"]) else 0.0
        raise SimulationError(f"vehicle run stopped at t = {t_last:.4f} s: {res['error']}", res)
    return res
