"""``[maneuver]`` of slosh scenes: the validated table of one maneuver and its prescribed
:class:`railslosh.slosh.Motion`. Lane changes and bumps come from the one maneuver library,
``rail_mbs::maneuvers`` (defaults and motions), shared with the co-simulation."""

from __future__ import annotations

import functools
from collections.abc import Mapping
from typing import Any

from railslosh import _core
from railslosh.constants import INCH, MPH
from railslosh.limits import Limit, invalid, missing
from railslosh.scene.schema import MANEUVERS, MAX_ROWS, Section, increasing, maneuver_defaults, variant_keys
from railslosh.slosh import Motion

_SPEED_KEYS = ("speed", "speed_mph", "speed_kmh")
_SPEED_SCALE = {"speed": 1.0, "speed_mph": MPH, "speed_kmh": 1 / 3.6}
_SAMPLE_TIME = Limit(0.0, 1e4, "s", "a time")
_SAMPLE_ACCELERATION = Limit(-50.0, 50.0, "m/s^2", "an acceleration")


def _speed(sec: Section, kind: str) -> float:
    given = [k for k in _SPEED_KEYS if k in sec]
    one = "exactly one of `maneuver.speed` (m/s), `maneuver.speed_mph`, `maneuver.speed_kmh`"
    if not given:
        raise missing("maneuver.speed", one)
    if len(given) > 1:
        raise invalid(f"maneuver.{given[0]}", sec.values[given[0]], f"{one} (`maneuver.{given[1]}` is given too)")
    k = given[0]
    return sec.get(k, variant=kind) * _SPEED_SCALE[k]


def _bump(sec: Section, out: dict[str, Any]) -> None:
    out["speed"] = _speed(sec, "bump")
    out["shape"] = sec.get("shape", variant="bump")
    if ("height" in sec) == ("height_in" in sec):
        raise invalid("maneuver.height", sec.values.get("height"), "exactly one of `height` (m) or `height_in`")
    h = sec.get("height", variant="bump") if "height" in sec else sec.get("height_in", variant="bump") * INCH
    out["height"] = h
    for k in ("suspension_frequency", "suspension_damping", "wheelbase", "wheel_radius"):
        out[k] = sec.get(k, variant="bump")
    if out["shape"] == "trapezoid":
        for k, f in maneuver_defaults()["trapezoid"].items():
            out[k] = sec.get(k, f * h, variant="bump")
    else:
        sec.only_with(("ramp_up", "top", "ramp_down"), 'with shape = "trapezoid"')


def _samples(sec: Section, out: dict[str, Any]) -> None:
    for ax in ("x", "y", "z"):
        if ax not in sec:
            continue
        rows = sec.values[ax]
        if not isinstance(rows, list | tuple) or not 2 <= len(rows) <= MAX_ROWS:
            raise invalid(f"maneuver.{ax}", rows, f"a list of 2 to {MAX_ROWS} pairs [t, a]")
        pts = []
        for i, r in enumerate(rows):
            if not isinstance(r, list | tuple) or len(r) != 2:
                raise invalid(f"maneuver.{ax}[{i}]", r, "a pair [t (s), a (m/s^2)]")
            t = _SAMPLE_TIME.check(r[0], f"maneuver.{ax}[{i}][0] (t)")
            pts.append((t, _SAMPLE_ACCELERATION.check(r[1], f"maneuver.{ax}[{i}][1] (a)")))
        increasing([p[0] for p in pts], functools.partial("maneuver.{}[{}][0] (t)".format, ax))
        out[ax] = pts


def maneuver(doc: Mapping[str, Any], t_end: float) -> dict[str, Any]:
    """The validated ``[maneuver]`` table (SI units, defaults filled in) of a slosh scene that
    runs ``t_end`` s."""
    sec = Section("slosh", "maneuver", doc)
    if "type" not in sec:
        raise missing("maneuver.type", "one of " + ", ".join(repr(m) for m in MANEUVERS))
    kind = sec.get("type")
    allowed = variant_keys("slosh", "maneuver", kind)
    for k, v in sec.values.items():
        if k not in ("type", "t0") and k not in allowed:
            raise invalid(
                f"maneuver.{k}", v, f"no `maneuver.{k}` with type = {kind!r} (its keys: {', '.join(allowed)})"
            )
    out: dict[str, Any] = {"type": kind, "t0": sec.get("t0")}
    if kind == "lane_change":
        out["speed"] = _speed(sec, kind)
        for k in ("offset", "length", "hold"):
            out[k] = sec.get(k, variant=kind)
        out["double"] = sec.get("double", variant=kind)
    elif kind == "bump":
        _bump(sec, out)
    elif kind == "pulse":
        out["axis"] = sec.get("axis", variant=kind)
        out["acceleration"] = sec.get("acceleration", variant=kind)
        out["ramp"] = sec.get("ramp", variant=kind)
        lo = out["t0"] + 2 * out["ramp"]
        out["t1"] = sec.get("t1", t_end, variant=kind, lo=lo, note=" (after t0 + 2 ramp)")
    else:
        _samples(sec, out)
    return out


def motion(m: Mapping[str, Any], t_end: float) -> Motion:
    """The :class:`railslosh.slosh.Motion` of a validated maneuver table, up to ``t_end``."""
    mo = Motion()
    if m["type"] in ("lane_change", "bump"):
        # one definition (rail_mbs::maneuvers), shared with the co-simulation: accelerations
        # and the rotation (heading of a lane change, pitch over a bump) sampled every 1 ms
        d = _core.maneuver_motion(m, m["t0"], t_end)
        mo.acceleration = {ax: [(float(t), float(a)) for t, a in pts] for ax, pts in d["acceleration"].items()}
        if d["rotation_axis"] is not None:
            x, y, z = (float(c) for c in d["rotation_axis"])
            mo.rotation_axis = (x, y, z)
            mo.angular_acceleration = [(float(t), float(a)) for t, a in d["angular_acceleration"]]
    elif m["type"] == "pulse":
        mo.pulse(m["axis"], m["acceleration"], m["t0"], m["t1"], ramp=m["ramp"])
    else:
        for ax in ("x", "y", "z"):
            if ax in m:
                mo.acceleration[ax] = [(float(t), float(a)) for t, a in m[ax]]
    return mo
