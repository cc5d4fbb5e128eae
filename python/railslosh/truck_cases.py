"""Validation case ``three-piece-twist`` (issue 20): the warp-capable three-piece truck
(``[car] truck = "three_piece"``, ``rail_mbs::vehicle::TruckModel::ThreePiece``) against seed
000's rigid bogie frame on a cross-level twist of the track.

The loaded tank car (36 t of rigid lading 0.5 m below the tank axis) runs at constant speed onto a
cross-level ramp (a twist defect, ``railslosh.irregularity``):

* **static**: the three-piece truck's wheel loads at t = 0 are the car's weight share within 1e-4,
  and the two trucks' agree within 1e-4 (same masses and preloads);
* **quasi-static**, 9 mm over 9 m (the truck centres) at 5 km/h, held. The rigid frame takes the
  1.8 mm twist within each bogie on its 20 MN/m primary springs; the three-piece truck's side frames
  warp, and only the twist between the two trucks reaches its wheels, through the load springs'
  roll stiffness k = 2 k_z d² per truck (k_z the secondary vertical stiffness, d the side frames'
  half span). The rigid car body rolls to the mean of the two trucks, each truck's springs carry
  M = k (φ_f − φ_r)/2 with φ_f − φ_r = 9 mm / 1.5 m at most, and each of its four wheels
  ΔQ = M / (4 · 0.75 m). Checks: the three-piece truck's largest |ΔQ|/Q₀ within 0.5–1.2 times
  that estimate, the rigid frame's above 3 times it;
* **a twist that lifts a wheel**, 30 mm over 3 m at 10 km/h, held: the rigid frame stops with
  the typed ``wheel_off_rail`` error, the three-piece truck runs to its end with every wheel
  carrying at least 0.75 of its static load, and its leading wheelset's wheels differing by more
  than 10 kN at the end (the twist reaches them).

The quick and full forms are the same (about 15 s).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from railslosh.records import record

#: Lateral distance of the two wheels' contact points, m (the estimate's lever arm).
_CONTACT_SPAN = 1.5
#: Rigid lading of the loaded car, kg (0.5 m below the tank axis).
_LADING = 36000.0


def twist_run(truck: str, twist: dict[str, Any], speed: float, t_end: float, step: float) -> dict[str, Any]:
    """The loaded car on ``truck`` over a twist defect whose ``start`` is relative to the leading
    wheelset (m); raises :class:`railslosh.slosh.SimulationError` when the run stops."""
    from railslosh import irregularity, vehicle

    lead = float(vehicle.wheelset_stations(cars=1, station=50.0)[0])
    twist = {**twist, "start": lead + twist["start"]}
    irr = irregularity.with_defects([twist], start=0.0, end=lead + 60.0, step=0.05)
    rows = [[0, 0, 0, 0, 0.025, -0.025], [3000, 0, 0, 0, 0.025, -0.025]]
    return vehicle.run(
        rows,
        cars=1,
        station=50.0,
        speed=speed,
        t_end=t_end,
        step=step,
        record_every=0.01 if t_end < 5 else 0.05,
        drive=True,
        lading_mass=_LADING,
        lading_height=-0.5,
        irregularity=irr,
        car={"truck": truck},
    )


def static_wheel_load() -> float:
    """The loaded car's static wheel load, N: its weight with the lading over its eight wheels."""
    from railslosh import vehicle
    from railslosh.constants import GRAVITY

    return (vehicle.tank_car_parameters()["total_mass"] + _LADING) * GRAVITY / 8.0


def load_spring_estimate() -> float:
    """The three-piece truck's largest |ΔQ|/Q₀ on the 9 mm / 9 m twist, from the load springs'
    roll stiffness (module docs), with the car's static wheel load."""
    from railslosh import vehicle

    p = vehicle.tank_car_parameters()
    k = 2.0 * p["secondary_kz"] * p["journal_half_span"] ** 2
    return k * 0.5 * (0.009 / _CONTACT_SPAN) / (2.0 * _CONTACT_SPAN) / static_wheel_load()


def three_piece_twist(quick: bool) -> list[dict]:
    from railslosh.slosh import SimulationError

    case = "three-piece-twist"
    estimate = load_spring_estimate()
    ramp = {"type": "twist", "start": 1.5, "base": 9.0, "cross_level": 0.009, "hold": 30.0}
    worst, static = {}, {}
    for truck in ("rigid_frame", "three_piece"):
        q = np.asarray(twist_run(truck, ramp, 5 / 3.6, 8.0, 5e-3)["wheel_vertical"])
        worst[truck] = float(np.abs(q / q[0] - 1.0).max())
        static[truck] = q[0]
    spread = float(np.abs(static["three_piece"] / static["rigid_frame"] - 1.0).max())
    q0 = static_wheel_load()
    weight = float(np.abs(static["three_piece"] / q0 - 1.0).max())
    out = [
        record(
            case,
            f"static wheel loads at t = 0, three-piece truck: largest relative difference from the car's weight "
            f"share (M + lading) g / 8 = {q0:.1f} N",
            weight,
            0.0,
            1e-4,
            weight <= 1e-4,
        ),
        record(
            case,
            "static wheel loads at t = 0, three-piece truck against rigid frame: largest relative difference "
            "(same masses and preloads)",
            spread,
            0.0,
            1e-4,
            spread <= 1e-4,
        ),
        record(
            case,
            "9 mm / 9 m twist at 5 km/h, three-piece truck: largest |dQ|/Q0 against the load springs' estimate "
            "(within 0.5 to 1.2 times it)",
            worst["three_piece"],
            estimate,
            0.7 * estimate,
            0.5 * estimate < worst["three_piece"] < 1.2 * estimate,
        ),
        record(
            case,
            "9 mm / 9 m twist at 5 km/h, rigid frame: largest |dQ|/Q0 (above 3 times the three-piece estimate)",
            worst["rigid_frame"],
            3.0 * estimate,
            0.0,
            worst["rigid_frame"] > 3.0 * estimate,
        ),
    ]
    lift = {"type": "twist", "start": 3.0, "base": 3.0, "cross_level": 0.03, "hold": 30.0}
    try:
        twist_run("rigid_frame", lift, 10 / 3.6, 3.0, 2e-3)
        cause = ""
    except SimulationError as exc:
        cause = exc.cause
    out.append(
        record(
            case,
            f"30 mm / 3 m twist at 10 km/h, rigid frame: stops with wheel_off_rail (1 = yes; stopped by {cause!r})",
            float(cause == "wheel_off_rail"),
            1.0,
            0.0,
            cause == "wheel_off_rail",
        )
    )
    try:
        res = twist_run("three_piece", lift, 10 / 3.6, 3.0, 2e-3)
        q = np.asarray(res["wheel_vertical"])
        lightest, t_reached = float(q.min() / q[0].min()), float(res["t"][-1])
        # the twist reached the car: its leading wheelset's wheels carry different loads at the end
        across = float(abs(q[-1, 0, 0] - q[-1, 0, 1]))
    except SimulationError as exc:
        lightest, t_reached, across = 0.0, float(exc.results["t"][-1]), 0.0
    out.append(
        record(
            case,
            f"30 mm / 3 m twist at 10 km/h, three-piece truck: lightest wheel / static load (at least 0.75; "
            f"run reached {t_reached:g} s of 3 s)",
            lightest,
            0.75,
            0.0,
            lightest >= 0.75 and abs(t_reached - 3.0) < 1e-9,
        )
    )
    out.append(
        record(
            case,
            "30 mm / 3 m twist at 10 km/h, three-piece truck: leading wheelset's left - right load at the end (N), "
            "above 10 kN (the twist reaches the wheels)",
            across,
            1e4,
            0.0,
            across > 1e4,
        )
    )
    return out


TRUCK_CASES = {
    "three-piece-twist": (
        "the three-piece truck against the rigid bogie frame on a cross-level twist: quasi-static 9 mm / 9 m "
        "(three-piece |dQ|/Q0 within 0.5-1.2 x the load springs' estimate, rigid frame above 3 x), and 30 mm / 3 m "
        "(rigid frame stops with wheel_off_rail, three-piece runs to its end with every wheel >= 0.75 Q0)",
        three_piece_twist,
    )
}
