"""Vehicle scene files: a train of tank cars on a track, described in TOML and run with
:func:`railslosh.vehicle.run`.

    >>> from railslosh import scene
    >>> sc = scene.load_scene("examples/scenes/single_car_table1_curve_60kmh.toml")
    >>> res = scene.run_scene(sc)              # the dict of railslosh.vehicle.run
    >>> short = scene.load_scene("examples/scenes/two_car_ecp_braking_rigid.toml", {"train": {"t_end": 0.1}})

A scene has these sections (every key optional unless marked; SI units, names ending in
``_kmh``, ``_ft``, ``_in`` or ``_percent`` say otherwise, see ``docs/frames.md``):

``[track]`` (required): exactly one of

* ``preset = "table1" | "tangent"``: Table 1 of the tank-car paper (seed 000; two opposite
  3-degree curves with 3 in super-elevation and spirals, 2800 ft) or a straight track of
  ``length`` m (default 3000; ``length`` only with ``"tangent"``);
* ``rows = [[s, curvature, superelevation, grade, cant_right, cant_left], ...]`` in SI (m, 1/m,
  m, fraction, rad; 3 to 6 numbers a row, missing trailing columns are 0);
* ``us_rows = [[distance_ft, degree_of_curvature, superelevation_in, grade_percent, cant_right,
  cant_left], ...]`` (arc-definition degrees, positive = curve to the left).

``[train]``: ``cars`` (1-50), ``station`` (m, front tank centre at t = 0), ``speed`` (m/s) or
``speed_kmh``, ``drive`` (``true`` holds the front car to ``speed``, a number to that speed in m/s),
``t_end``, ``step`` (maximum step), ``record_every`` (s), ``wheelset_lateral_offset`` (m),
``coupler_stiffness`` (N/m), ``coupler_damping`` (N s/m).

``[brake]``: ``times`` (s) and ``torques`` (N m per wheelset, against the motion), both required in
the section; ``scope = "all"`` (ECP: every car) or ``"front"``.

``[lading]``: rigid lading per car, ``mass`` (kg) and ``height`` of its centre above the tank axis
(m, negative = below).

``[car]``: overrides of any key of :func:`railslosh.vehicle.tank_car_parameters` except ``dof``
and ``total_mass``, and ``wheel_profile = "s1002" | "aar1b"``.

Every error (unknown section or key, wrong type, value out of range) is a ``ValueError`` that names
the dotted field and what is allowed, e.g. ``invalid parameter `train.speed` = 250.0: allowed 0 to
70 m/s``.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import os
import re
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from railslosh import rail, vehicle

__all__ = ["PRESETS", "Scene", "load_scene", "run_scene", "scene_from_dict"]

FOOT = 0.3048
INCH = 0.0254
ARC_DEGREE_RADIUS_FT = 5729.577951308232
PRESETS = ("table1", "tangent")
"""Names accepted by ``[track] preset``."""

# Seed 000, Table 1: distance (ft), degree of curvature, super-elevation (in), grade (%), rail cant
# right / left (rad).
_TABLE1_US = [
    [0.0, 0.0, 0.0, 0.0, 0.025, -0.025],
    [100.0, 0.0, 0.0, 0.0, 0.025, -0.025],
    [300.0, 3.0, 3.0, 0.0, 0.025, -0.025],
    [600.0, 3.0, 3.0, 0.0, 0.025, -0.025],
    [800.0, 0.0, 0.0, 0.0, 0.025, -0.025],
    [1000.0, 0.0, 0.0, 0.0, 0.025, -0.025],
    [1200.0, -3.0, -3.0, 0.0, 0.025, -0.025],
    [1500.0, -3.0, -3.0, 0.0, 0.025, -0.025],
    [1700.0, 0.0, 0.0, 0.0, 0.025, -0.025],
    [2800.0, 0.0, 0.0, 0.0, 0.025, -0.025],
]

# Allowed ranges of the track columns: (name, low, high, unit).
_SI_COLUMNS = (
    ("s", -1e6, 1e6, "m"),
    ("curvature", -0.02, 0.02, "1/m (radius >= 50 m)"),
    ("superelevation", -0.2, 0.2, "m"),
    ("grade", -0.05, 0.05, "(rise over run)"),
    ("cant_right", -0.1, 0.1, "rad"),
    ("cant_left", -0.1, 0.1, "rad"),
)
_US_COLUMNS = (
    ("distance_ft", -3e6, 3e6, "ft"),
    ("degree_of_curvature", -30.0, 30.0, "degrees"),
    ("superelevation_in", -8.0, 8.0, "in"),
    ("grade_percent", -5.0, 5.0, "%"),
    ("cant_right", -0.1, 0.1, "rad"),
    ("cant_left", -0.1, 0.1, "rad"),
)
_MAX_ROWS = 10_000
_SECTIONS = ("track", "train", "brake", "lading", "car")
_WHEEL_PROFILES = ("s1002", "aar1b")
_BRAKE_SCOPES = ("all", "front")
_MAX_SPEED = 70.0  # m/s (252 km/h)


def _fail(fieldname: str, value: Any, allowed: str) -> ValueError:
    return ValueError(f"invalid parameter `{fieldname}` = {value!r}: allowed {allowed}")


def _number(value: Any, fieldname: str, lo: float, hi: float, unit: str = "", *, open_lo: bool = False) -> float:
    """A real number (TOML integer or float, not a boolean) in ``[lo, hi]`` (``(lo, hi]``)."""
    unit_s = f" {unit}" if unit else ""
    rng = f"{f'more than {lo:g} up' if open_lo else f'{lo:g}'} to {hi:g}{unit_s}"
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise _fail(fieldname, value, f"a number, {rng}")
    try:
        x = float(value)
    except OverflowError:  # a TOML integer beyond the float range
        x = math.inf
    if not math.isfinite(x) or x < lo or x > hi or (open_lo and x <= lo):
        raise _fail(fieldname, value, rng)
    return x


def _integer(value: Any, fieldname: str, lo: int, hi: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise _fail(fieldname, value, f"an integer, {lo} to {hi}")
    if not lo <= value <= hi:
        raise _fail(fieldname, value, f"{lo} to {hi}")
    return int(value)


def _choice(value: Any, fieldname: str, allowed: tuple[str, ...]) -> str:
    if not isinstance(value, str) or value not in allowed:
        raise _fail(fieldname, value, f"one of {', '.join(repr(a) for a in allowed)}")
    return value


def _table(value: Any, fieldname: str) -> Mapping[str, Any]:
    if not isinstance(value, Mapping):
        raise _fail(fieldname, value, "a table (section) of keys")
    for k in value:
        if not isinstance(k, str):
            raise _fail(fieldname, k, "string keys")
    return value


def _check_keys(section: Mapping[str, Any], name: str, allowed: tuple[str, ...] | list[str]) -> None:
    for k in section:
        if k not in allowed:
            raise ValueError(
                f"invalid parameter `{name}.{k}`: unknown key; allowed one of {', '.join(sorted(allowed))}"
            )


def _number_list(value: Any, fieldname: str, lo: float, hi: float, unit: str, *, min_len: int = 1) -> list[float]:
    if not isinstance(value, list | tuple) or not min_len <= len(value) <= _MAX_ROWS:
        raise _fail(fieldname, value, f"a list of {min_len} to {_MAX_ROWS} numbers")
    return [_number(x, f"{fieldname}[{i}]", lo, hi, unit) for i, x in enumerate(value)]


def _increasing(xs: list[float], name: Any) -> None:
    """Checks ``xs`` strictly increasing; ``name(i)`` is the dotted field of entry ``i``."""
    for i in range(1, len(xs)):
        if xs[i] <= xs[i - 1]:
            raise _fail(name(i), xs[i], f"strictly increasing, > {xs[i - 1]!r}")


@functools.cache
def _car_defaults() -> dict[str, float]:
    p = vehicle.tank_car_parameters()
    return {k: float(v) for k, v in p.items() if k not in ("dof", "total_mass")}


def _car_range(key: str, default: float) -> tuple[float, float]:
    """Allowed range of a car parameter: friction in [0, 1]; stiffness and damping from 0 (switched
    off) to 10 times the default; every other quantity 0.1 to 10 times its default."""
    if key == "friction":
        return 0.0, 1.0
    if re.search(r"_[kc][xyz]?$", key) or key.endswith(("stiffness", "damping")):
        return 0.0, 10.0 * max(default, 1.0)
    return 0.1 * default, 10.0 * default


@dataclass(frozen=True)
class Scene:
    """A validated vehicle scene; every field is in SI units. :meth:`run_kwargs` gives the
    arguments of :func:`railslosh.vehicle.run`."""

    track_rows: tuple[tuple[float, ...], ...]
    """Track segment table in SI units, rows ``(s, curvature, superelevation, grade, cant_right,
    cant_left)``."""
    track_source: str = "rows"
    """Where the table came from: ``"preset:table1"``, ``"preset:tangent"``, ``"rows"`` or ``"us_rows"``."""
    cars: int = 1
    station: float = 50.0
    speed: float = 0.0
    drive: bool | float = False
    t_end: float = 1.0
    step: float = 1e-3
    record_every: float = 0.01
    wheelset_lateral_offset: float = 0.0
    coupler_stiffness: float | None = None
    coupler_damping: float | None = None
    brake_times: tuple[float, ...] | None = None
    brake_torques: tuple[float, ...] | None = None
    brake_scope: str = "all"
    lading_mass: float = 0.0
    lading_height: float = 0.0
    car: Mapping[str, float] = field(default_factory=dict)
    wheel_profile: str = "s1002"

    def track(self) -> rail.Track:
        """The track as a :class:`railslosh.rail.Track`."""
        return rail.Track.from_table(np.asarray(self.track_rows, dtype=float))

    def run_kwargs(self) -> dict[str, Any]:
        """Keyword arguments of :func:`railslosh.vehicle.run` (after the track)."""
        brake = None
        if self.brake_times is not None and self.brake_torques is not None:
            brake = (list(self.brake_times), list(self.brake_torques))
        return {
            "cars": self.cars,
            "station": self.station,
            "speed": self.speed,
            "t_end": self.t_end,
            "step": self.step,
            "record_every": self.record_every,
            "drive": self.drive,
            "brake": brake,
            "brake_scope": self.brake_scope,
            "lading_mass": self.lading_mass,
            "lading_height": self.lading_height,
            "wheel_profile": self.wheel_profile,
            "wheelset_lateral_offset": self.wheelset_lateral_offset,
            "coupler_stiffness": self.coupler_stiffness,
            "coupler_damping": self.coupler_damping,
            "car": dict(self.car) or None,
        }

    def replace(self, **changes: Any) -> Scene:
        """A copy with fields changed, validated again (e.g. ``scene.replace(t_end=0.1)``)."""
        new = scene_from_dict(_to_dict(dataclasses.replace(self, **changes)))
        return dataclasses.replace(new, track_source=self.track_source)


def _to_dict(sc: Scene) -> dict[str, Any]:
    train: dict[str, Any] = {
        "cars": sc.cars,
        "station": sc.station,
        "speed": sc.speed,
        "drive": sc.drive,
        "t_end": sc.t_end,
        "step": sc.step,
        "record_every": sc.record_every,
        "wheelset_lateral_offset": sc.wheelset_lateral_offset,
    }
    if sc.coupler_stiffness is not None:
        train["coupler_stiffness"] = sc.coupler_stiffness
    if sc.coupler_damping is not None:
        train["coupler_damping"] = sc.coupler_damping
    d: dict[str, Any] = {"track": {"rows": [list(r) for r in sc.track_rows]}, "train": train}
    if sc.brake_times is not None and sc.brake_torques is not None:
        d["brake"] = {"times": list(sc.brake_times), "torques": list(sc.brake_torques), "scope": sc.brake_scope}
    if sc.lading_mass or sc.lading_height:
        d["lading"] = {"mass": sc.lading_mass, "height": sc.lading_height}
    d["car"] = {**sc.car, "wheel_profile": sc.wheel_profile}
    return d


def _rows(value: Any, fieldname: str, columns: tuple[tuple[str, float, float, str], ...]) -> list[list[float]]:
    if not isinstance(value, list | tuple) or not 2 <= len(value) <= _MAX_ROWS:
        raise _fail(fieldname, value, f"a list of 2 to {_MAX_ROWS} rows [{', '.join(c[0] for c in columns)}]")
    out = []
    for i, row in enumerate(value):
        if not isinstance(row, list | tuple) or not 3 <= len(row) <= 6:
            raise _fail(f"{fieldname}[{i}]", row, f"a row of 3 to 6 numbers [{', '.join(c[0] for c in columns)}]")
        r = [_number(x, f"{fieldname}[{i}][{j}] ({columns[j][0]})", *columns[j][1:]) for j, x in enumerate(row)]
        out.append(r + [0.0] * (6 - len(r)))
    _increasing([r[0] for r in out], lambda i: f"{fieldname}[{i}][0] ({columns[0][0]})")
    return out


def _us_to_si(rows: list[list[float]]) -> list[list[float]]:
    return [
        [d * FOOT, deg / (ARC_DEGREE_RADIUS_FT * FOOT), e * INCH, g / 100.0, cr, cl] for d, deg, e, g, cr, cl in rows
    ]


def _track(sec: Mapping[str, Any]) -> tuple[list[list[float]], str]:
    _check_keys(sec, "track", ("preset", "rows", "us_rows", "length"))
    given = [k for k in ("preset", "rows", "us_rows") if k in sec]
    if len(given) != 1:
        raise _fail("track", sorted(sec), "exactly one of `track.preset`, `track.rows`, `track.us_rows`")
    kind = given[0]
    preset = _choice(sec["preset"], "track.preset", PRESETS) if kind == "preset" else None
    if "length" in sec and preset != "tangent":
        raise _fail("track.length", sec["length"], 'only with preset = "tangent"')
    if kind == "preset":
        if preset == "table1":
            return _us_to_si(_TABLE1_US), "preset:table1"
        length = _number(sec.get("length", 3000.0), "track.length", 100.0, 1e6, "m")
        return [[0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [length, 0.0, 0.0, 0.0, 0.0, 0.0]], "preset:tangent"
    if kind == "rows":
        return _rows(sec["rows"], "track.rows", _SI_COLUMNS), "rows"
    return _us_to_si(_rows(sec["us_rows"], "track.us_rows", _US_COLUMNS)), "us_rows"


_TRAIN_KEYS = (
    "cars",
    "station",
    "speed",
    "speed_kmh",
    "drive",
    "t_end",
    "step",
    "record_every",
    "wheelset_lateral_offset",
    "coupler_stiffness",
    "coupler_damping",
)


def scene_from_dict(data: Mapping[str, Any]) -> Scene:
    """Validates a parsed scene (the dict a TOML file gives) and returns the :class:`Scene`."""
    data = _table(data, "scene")
    for k in data:
        if k not in _SECTIONS:
            raise ValueError(f"invalid parameter `{k}`: unknown section; allowed one of {', '.join(sorted(_SECTIONS))}")
    if "track" not in data:
        raise _fail("track", None, "a [track] section (preset, rows or us_rows)")
    rows, source = _track(_table(data["track"], "track"))

    # [car] first: the train and lading checks use its geometry.
    defaults = _car_defaults()
    car_sec = _table(data.get("car", {}), "car")
    _check_keys(car_sec, "car", [*defaults, "wheel_profile"])
    wheel_profile = _choice(car_sec.get("wheel_profile", "s1002"), "car.wheel_profile", _WHEEL_PROFILES)
    car: dict[str, float] = {}
    for k, v in car_sec.items():
        if k == "wheel_profile":
            continue
        lo, hi = _car_range(k, defaults[k])
        car[k] = _number(v, f"car.{k}", lo, hi)
    if car or wheel_profile != "s1002":
        try:
            vehicle.tank_car_parameters(car or None, wheel_profile)
        except Exception as exc:  # any rejection by the model is a bad [car] section
            msg = re.sub(r"invalid parameter `([^`]+)`", r"invalid parameter `car.\1`", str(exc))
            raise ValueError(msg if msg.startswith("invalid parameter") else f"invalid parameter `car`: {msg}") from exc
    params = {**defaults, **car}

    tr = _table(data.get("train", {}), "train")
    _check_keys(tr, "train", _TRAIN_KEYS)
    cars = _integer(tr.get("cars", 1), "train.cars", 1, 50)
    if "speed" in tr and "speed_kmh" in tr:
        raise _fail("train.speed", tr["speed"], "either `train.speed` (m/s) or `train.speed_kmh`, not both")
    if "speed_kmh" in tr:
        speed = _number(tr["speed_kmh"], "train.speed_kmh", 0.0, _MAX_SPEED * 3.6, "km/h") / 3.6
    else:
        speed = _number(tr.get("speed", 0.0), "train.speed", 0.0, _MAX_SPEED, "m/s")
    drive_v = tr.get("drive", False)
    drive: bool | float
    if isinstance(drive_v, bool):
        drive = drive_v
    else:
        drive = _number(drive_v, "train.drive", 0.0, _MAX_SPEED, "m/s (or true / false)")
    t_end = _number(tr.get("t_end", 1.0), "train.t_end", 0.0, 600.0, "s", open_lo=True)
    step = _number(tr.get("step", 1e-3), "train.step", 1e-6, 0.01, "s")
    record_every = _number(tr.get("record_every", 0.01), "train.record_every", step, 10.0, "s (>= train.step)")
    offset = _number(tr.get("wheelset_lateral_offset", 0.0), "train.wheelset_lateral_offset", -0.0099, 0.0099, "m")
    k_c = tr.get("coupler_stiffness")
    coupler_k = None if k_c is None else _number(k_c, "train.coupler_stiffness", 1e3, 1e10, "N/m")
    c_c = tr.get("coupler_damping")
    coupler_c = None if c_c is None else _number(c_c, "train.coupler_damping", 0.0, 1e9, "N s/m")

    # The train must fit on the track: front and rear couplers inside the table for the whole run.
    reach = params["coupler_reach"]
    pitch = 2.0 * reach + 1.0
    travel = max(speed, drive if not isinstance(drive, bool) else 0.0) * t_end
    s_first, s_last = rows[0][0], rows[-1][0]
    lo = s_first + (cars - 1) * pitch + reach
    hi = s_last - reach - travel
    station = _number(tr.get("station", 50.0), "train.station", -1e6, 1e6, "m")
    if not lo <= station <= hi:
        raise _fail(
            "train.station",
            tr.get("station", 50.0),
            f"{lo:.3f} to {hi:.3f} m (all {cars} car(s) on the track for the whole run)",
        )

    br = _table(data.get("brake", {}), "brake")
    _check_keys(br, "brake", ("times", "torques", "scope"))
    brake_times = brake_torques = None
    scope = _choice(br.get("scope", "all"), "brake.scope", _BRAKE_SCOPES)
    if br and ("times" not in br or "torques" not in br):
        missing = "brake.times" if "times" not in br else "brake.torques"
        raise _fail(missing, None, "both `brake.times` and `brake.torques` in a [brake] section")
    if "times" in br:
        times = _number_list(br["times"], "brake.times", 0.0, 1e4, "s")
        _increasing(times, lambda i: f"brake.times[{i}]")
        torques = _number_list(br["torques"], "brake.torques", 0.0, 1e5, "N m")
        if len(torques) != len(times):
            raise _fail("brake.torques", br["torques"], f"{len(times)} numbers, one per entry of `brake.times`")
        brake_times, brake_torques = tuple(times), tuple(torques)

    ld = _table(data.get("lading", {}), "lading")
    _check_keys(ld, "lading", ("mass", "height"))
    lading_mass = _number(ld.get("mass", 0.0), "lading.mass", 0.0, 150_000.0, "kg")
    radius = params["tank_radius"]
    lading_height = _number(ld.get("height", 0.0), "lading.height", -radius, radius, "m (within the tank radius)")

    return Scene(
        track_rows=tuple(tuple(r) for r in rows),
        track_source=source,
        cars=cars,
        station=station,
        speed=speed,
        drive=drive,
        t_end=t_end,
        step=step,
        record_every=record_every,
        wheelset_lateral_offset=offset,
        coupler_stiffness=coupler_k,
        coupler_damping=coupler_c,
        brake_times=brake_times,
        brake_torques=brake_torques,
        brake_scope=scope,
        lading_mass=lading_mass,
        lading_height=lading_height,
        car=car,
        wheel_profile=wheel_profile,
    )


def _merge(base: Mapping[str, Any], over: Mapping[str, Any]) -> dict[str, Any]:
    out = dict(base)
    for k, v in over.items():
        if v is None:  # TOML has no null: None removes the key
            out.pop(k, None)
        elif isinstance(v, Mapping) and isinstance(out.get(k), Mapping):
            out[k] = _merge(out[k], v)
        else:
            out[k] = v
    return out


def load_scene(source: str | os.PathLike[str] | Mapping[str, Any], overrides: Mapping[str, Any] | None = None) -> Scene:
    """Loads and validates a scene from a TOML file (path), TOML text or an already parsed dict.

    ``overrides`` is merged into the parsed scene section by section before validation, e.g.
    ``{"train": {"t_end": 0.1}}``; a value ``None`` removes that key. A string is read as a file
    path when it names an existing file or ends in ``.toml`` (a missing file raises
    ``FileNotFoundError``), otherwise as TOML text.
    Raises ``ValueError`` naming the dotted field for every schema error (TOML syntax included).
    """
    if isinstance(source, Mapping):
        data: Mapping[str, Any] = source
    else:
        is_path = isinstance(source, os.PathLike) or (
            isinstance(source, str) and "\n" not in source and (source.endswith(".toml") or Path(source).is_file())
        )
        text = Path(source).read_text(encoding="utf-8") if is_path else str(source)
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise ValueError(f"invalid scene TOML{f' in {source}' if is_path else ''}: {exc}") from exc
    if overrides is not None:
        data = _merge(_table(data, "scene"), _table(overrides, "overrides"))
    return scene_from_dict(data)


def run_scene(scene: Scene | str | os.PathLike[str] | Mapping[str, Any]) -> dict[str, Any]:
    """Runs a scene (a :class:`Scene`, or anything :func:`load_scene` takes) with
    :func:`railslosh.vehicle.run`; returns its dict of arrays with ``"scene"`` added.

    Raises :class:`railslosh.slosh.SimulationError` when the run stops early."""
    sc = scene if isinstance(scene, Scene) else load_scene(scene)
    res = vehicle.run(np.asarray(sc.track_rows, dtype=float), **sc.run_kwargs())
    res["scene"] = sc
    return res
