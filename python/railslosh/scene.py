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
``t_end``, ``step`` (maximum step), ``record_every`` (s), ``load_filter`` (``"hat_mean"``, default: loads
recorded as their anti-aliased hat-weighted mean over the steps, or ``"sample"``: point values; see
:func:`railslosh.vehicle.run`), ``wheelset_lateral_offset`` (m),
``coupler_stiffness`` (N/m), ``coupler_damping`` (N s/m).

``[brake]``: ``times`` (s) and ``torques`` (N m per wheelset, against the motion), both required in
the section; ``scope = "all"`` (ECP: every car) or ``"front"``.

``[lading]``: rigid lading per car, ``mass`` (kg) and ``height`` of its centre above the tank axis
(m, negative = below).

``[car]``: overrides of any key of :func:`railslosh.vehicle.tank_car_parameters` except ``dof``
and ``total_mass``, and ``wheel_profile = "s1002" | "aar1b"``.

``[brake]`` may instead say ``design = true``: the torque table of
:func:`railslosh.vehicle.design_brake_torque` that slows the loaded car (liquid included) from the
train speed to ``design_v1_kmh`` (default 5) in ``design_duration`` s (default 10), the design of
seed 000 §8.2; ``factors`` (one per car, 0 to 10) scale it per car (fluid scenes only).

**Liquid cargo (ANCF fluid in every tank, run with** :func:`railslosh.vehicle.run_fluid` **).**
A ``[fluid]`` section turns a vehicle scene into a coupled car-oil scene:

``[fluid]``: ``oil = "light" | "medium" | "heavy" | "water" | "custom"`` (seed 000 Table 2 crude oils,
Oldroyd model); ``fill`` (liquid volume as a fraction of the tank volume, 0.1 to 0.9); for ``"custom"``: ``model``
(``"newtonian"``, ``"bingham"``, ``"herschel-bulkley"``, ``"oldroyd"``, ``"casson"``), ``density``
(kg/m^3), ``viscosity`` (Pa s), ``yield_stress`` (Pa), ``consistency``, ``power_index``,
``elastic_modulus`` (Pa), ``bulk_penalty`` (Pa, default 1000 rho g depth) and ``bulk_damping``.
``[mesh]``: ``counts = [n_length, n_width, n_height]`` fluid elements (1-40, 2-20, 1-10).
``[tank]``: ``bulkheads = [[x, thickness], ...]`` in the tank frame (m; full-height plates; each
compartment needs at least one element along the length); ``wall_damping_ratio`` (0 to 10, default
0.1): damping ratio of the liquid column on the penalty wall; 1 removes most of the wall ringing
from the loads after a wave hits a head (docs/validation.md, "Wall damping").
``[outputs]``: ``snapshot_every`` (s, fluid mesh snapshots for ParaView; 0 = none), ``netcdf``,
``vtu``, ``plots`` (booleans, what ``railslosh run`` writes). Rigid lading, coupler overrides and
wheelset offsets are not available with liquid cargo.
``[fluid] slosh_model = "auto" | "ancf" | "pendulum" | "rigid"`` (default ``"auto"``) picks how the
liquid is modelled: the ANCF continuum, the equivalent spring-mass / pendulum model
(:func:`railslosh.vehicle.run_equivalent`) or rigid lading; ``"auto"`` applies the rule of
:mod:`railslosh.fluid_model`. (The key is not ``model``: that names the rheology of a custom oil.)

**Prescribed-motion slosh scenes** (a ``[maneuver]`` section; run with
:func:`railslosh.slosh.run`): see :class:`SloshScene`.

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
from railslosh.constants import ARC_DEGREE_RADIUS_FT, FOOT, GRAVITY, INCH, MPH
from railslosh.fluid_model import SLOSH_MODELS

__all__ = [
    "OILS",
    "PRESETS",
    "FluidSpec",
    "Outputs",
    "Scene",
    "SloshScene",
    "load_scene",
    "run_scene",
    "scene_from_dict",
]

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
_SECTIONS = ("track", "train", "brake", "lading", "car", "scene", "fluid", "mesh", "tank", "outputs")
OILS = ("light", "medium", "heavy", "water", "custom")
"""Names accepted by ``[fluid] oil``."""
_RHEOLOGIES = ("newtonian", "bingham", "herschel-bulkley", "oldroyd", "casson")
"""Values of ``[fluid] slosh_model`` (see :mod:`railslosh.fluid_model`)."""
_WHEEL_PROFILES = ("s1002", "aar1b")
_BRAKE_SCOPES = ("all", "front")
STEPPERS = ("implicit", "explicit", "auto")
"""Values of ``[solver] stepper`` of slosh scenes."""
LOAD_FILTERS = ("hat_mean", "sample")
"""Values of ``[train] load_filter``."""
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
class Outputs:
    """What ``railslosh run`` writes (``[outputs]``)."""

    netcdf: bool = True
    """``results.nc``: the time series as an xarray Dataset."""
    vtu: bool = True
    """``fluid/*.vtu`` and ``fluid.pvd``: fluid mesh snapshots for ParaView (needs ``snapshot_every``)."""
    plots: bool = True
    """PNG plots of the main time series."""
    snapshot_every: float = 0.0
    """Interval of fluid mesh snapshots, s (0 = none)."""

    def to_section(self) -> dict[str, Any]:
        """The ``[outputs]`` table."""
        return dataclasses.asdict(self)


@dataclass(frozen=True)
class FluidSpec:
    """The liquid of a scene: ``[fluid]``, ``[mesh]`` and the bulkheads of ``[tank]``."""

    oil: str = "light"
    fill: float = 0.5
    counts: tuple[int, int, int] = (6, 4, 2)
    bulkheads: tuple[tuple[float, float], ...] = ()
    custom: Mapping[str, Any] = field(default_factory=dict)
    """Constructor arguments of :class:`railslosh.Fluid` when ``oil = "custom"``."""
    slosh_model: str = "auto"
    """``[fluid] slosh_model``: ``"auto"``, ``"ancf"``, ``"pendulum"`` or ``"rigid"``."""
    wall_damping_ratio: float = vehicle.WALL_DAMPING_RATIO
    """``[tank] wall_damping_ratio``: damping ratio of the liquid column on the penalty wall (0 to 10;
    1 removes most wall ringing from the loads: :func:`railslosh.vehicle.run_fluid`)."""

    def make_fluid(self, depth: float, element_height: float | None = None) -> Any:
        """The :class:`railslosh.Fluid` for a liquid ``depth`` m deep: penalty ``k = 1000 rho g depth``
        and, when ``element_height`` is given, bulk damping ``0.2 sqrt(k rho) element_height`` (the
        defaults of the slosh validation cases) unless the scene sets them."""
        from railslosh import fluids

        rho = self.density()
        k = float(self.custom.get("bulk_penalty", fluids.default_bulk_penalty(rho, depth)))
        c = 0.0 if element_height is None else fluids.default_bulk_damping(k, rho, element_height)
        c = float(self.custom.get("bulk_damping", c))
        if self.oil == "custom":
            args = {key: v for key, v in self.custom.items() if key not in ("density", "model")}
            args |= {"bulk_penalty": k, "bulk_damping": c}
            try:
                return fluids.Fluid(rho, self.custom["model"], **args)
            except ValueError as exc:
                msg = re.sub(r"invalid parameter `([^`]+)`", r"invalid parameter `fluid.\1`", str(exc))
                raise ValueError(
                    msg if msg.startswith("invalid parameter") else f"invalid parameter `fluid`: {msg}"
                ) from exc
        if self.oil == "water":
            _, mu, _ = fluids.LIQUIDS["water"]
            return fluids.newtonian(rho, mu, bulk_penalty=k, bulk_damping=c)
        _, mu, tau0 = fluids.CRUDE_OILS[self.oil]
        return fluids.oldroyd(rho, mu, tau0, bulk_penalty=k, bulk_damping=c)

    def density(self) -> float:
        """Liquid density, kg/m^3."""
        if self.oil == "custom":
            return float(self.custom["density"])
        from railslosh import fluids

        return fluids.LIQUIDS[self.oil][0]

    def mass(self, params: Mapping[str, float]) -> float:
        """Liquid mass per car, kg (density times the exact liquid volume of the car's tank)."""
        from railslosh import mesh

        m = mesh.cylinder_tank(
            length=params["tank_length"] - 1.0,
            radius=params["tank_radius"],
            head_depth=0.5,
            fill=self.fill,
            n_length=2,
            n_width=2,
            n_height=2,
        )
        return self.density() * m.exact_volume

    def to_sections(self) -> dict[str, Any]:
        """The ``[fluid]``, ``[mesh]`` and ``[tank]`` tables of this liquid."""
        fl: dict[str, Any] = {"oil": self.oil, "fill": self.fill, **self.custom}
        if self.slosh_model != "auto":
            fl["slosh_model"] = self.slosh_model
        d: dict[str, Any] = {"fluid": fl, "mesh": {"counts": list(self.counts)}}
        if self.bulkheads:
            d["tank"] = {"bulkheads": [list(b) for b in self.bulkheads]}
        if self.wall_damping_ratio != vehicle.WALL_DAMPING_RATIO:
            d.setdefault("tank", {})["wall_damping_ratio"] = self.wall_damping_ratio
        return d


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
    load_filter: str = "hat_mean"
    """How load channels are recorded: ``"hat_mean"`` (anti-aliased) or ``"sample"``."""
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
    name: str = ""
    """Title of the scene (``[scene] name``)."""
    description: str = ""
    fluid: FluidSpec | None = None
    """Liquid cargo (``[fluid]``, ``[mesh]``, ``[tank]``); ``None`` = rigid lading only."""
    brake_factors: tuple[float, ...] | None = None
    brake_design: Mapping[str, float] | None = None
    """``{"v1": m/s, "duration": s}`` when ``[brake] design = true`` (times/torques then computed)."""
    outputs: Outputs = field(default_factory=lambda: Outputs())

    @property
    def kind(self) -> str:
        """``"vehicle"`` (rigid lading) or ``"fluid_vehicle"`` (ANCF liquid in the tanks)."""
        return "vehicle" if self.fluid is None else "fluid_vehicle"

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
            "load_filter": self.load_filter,
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

    def fluid_kwargs(self) -> dict[str, Any]:
        """Keyword arguments of :func:`railslosh.vehicle.run_fluid` (after the track)."""
        if self.fluid is None:
            raise ValueError("invalid parameter `fluid` = None: allowed a scene with a [fluid] section")
        kw = self.run_kwargs()
        for k in ("lading_mass", "lading_height", "wheelset_lateral_offset", "coupler_stiffness", "coupler_damping"):
            kw.pop(k)
        f = self.fluid
        kw |= {
            "oil": f.oil if f.oil != "custom" else "light",
            "fluid": f.make_fluid(2.0 * self.tank_radius() * f.fill) if f.oil == "custom" else None,
            "counts": f.counts,
            "fill": f.fill,
            "bulkheads": [tuple(b) for b in f.bulkheads] or None,
            "snapshot_every": self.outputs.snapshot_every,
            "brake_factors": None if self.brake_factors is None else list(self.brake_factors),
            "wall_damping_ratio": f.wall_damping_ratio,
        }
        return kw

    def equivalent_kwargs(self, slosh_axis: str) -> dict[str, Any]:
        """Keyword arguments of :func:`railslosh.vehicle.run_equivalent` (after the track): the liquid
        as its equivalent slosh model along ``slosh_axis``."""
        kw = self.fluid_kwargs()
        for k in ("counts", "snapshot_every", "wall_damping_ratio"):
            kw.pop(k)
        kw["slosh_axis"] = slosh_axis
        return kw

    def rigid_kwargs(self) -> dict[str, Any]:
        """Keyword arguments of :func:`railslosh.vehicle.run` (after the track) with the liquid as rigid
        lading: its mass at its rest centroid height."""
        if self.fluid is None:
            return self.run_kwargs()
        f = self.fluid
        geo = vehicle.equivalent_model(f.fill, bulkheads=list(f.bulkheads) or None, car=dict(self.car) or None)
        kw = self.run_kwargs()
        kw["lading_mass"] = f.mass({**_car_defaults(), **self.car})
        kw["lading_height"] = float(geo["centroid"][2])
        return kw

    def tank_radius(self) -> float:
        """Tank radius of the car, m (default or ``[car] tank_radius``)."""
        return float({**_car_defaults(), **self.car}["tank_radius"])

    def replace(self, **changes: Any) -> Scene:
        """A copy with fields changed, validated again (e.g. ``scene.replace(t_end=0.1)``)."""
        new = scene_from_dict(_to_dict(dataclasses.replace(self, **changes)))
        return dataclasses.replace(new, track_source=self.track_source)

    def to_dict(self) -> dict[str, Any]:
        """The scene as a TOML-like dict (SI units) that :func:`load_scene` reads back."""
        return _to_dict(self)


def _to_dict(sc: Scene) -> dict[str, Any]:
    train: dict[str, Any] = {
        "cars": sc.cars,
        "station": sc.station,
        "speed": sc.speed,
        "drive": sc.drive,
        "t_end": sc.t_end,
        "step": sc.step,
        "record_every": sc.record_every,
        "load_filter": sc.load_filter,
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
    if sc.brake_design is not None:
        d["brake"] = {
            "design": True,
            "design_v1_kmh": sc.brake_design["v1"] * 3.6,
            "design_duration": sc.brake_design["duration"],
            "scope": sc.brake_scope,
        }
    if sc.brake_factors is not None:
        d.setdefault("brake", {})["factors"] = list(sc.brake_factors)
    if sc.name or sc.description:
        d["scene"] = {"name": sc.name, "description": sc.description}
    if sc.fluid is not None:
        d |= sc.fluid.to_sections()
    d["outputs"] = sc.outputs.to_section()
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
    "load_filter",
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
    load_filter = _choice(tr.get("load_filter", "hat_mean"), "train.load_filter", LOAD_FILTERS)
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
    _check_keys(br, "brake", ("times", "torques", "scope", "design", "design_v1_kmh", "design_duration", "factors"))
    brake_times = brake_torques = None
    scope = _choice(br.get("scope", "all"), "brake.scope", _BRAKE_SCOPES)
    design = br.get("design", False)
    if not isinstance(design, bool):
        raise _fail("brake.design", design, "true or false")
    brake_design = None
    if design:
        if "times" in br or "torques" in br:
            raise _fail("brake.design", design, "either `brake.design = true` or `brake.times`/`brake.torques`")
        v1 = _number(br.get("design_v1_kmh", 5.0), "brake.design_v1_kmh", 0.0, speed * 3.6, "km/h (<= train speed)")
        duration = _number(br.get("design_duration", 10.0), "brake.design_duration", 1.0, 600.0, "s")
        if speed <= v1 / 3.6:
            raise _fail("train.speed", speed, "> brake.design_v1_kmh for a designed brake")
        brake_design = {"v1": v1 / 3.6, "duration": duration}
    else:
        for k in ("design_v1_kmh", "design_duration"):
            if k in br:
                raise _fail(f"brake.{k}", br[k], "only with `brake.design = true`")
    factors = None
    if "factors" in br:
        factors = tuple(_number_list(br["factors"], "brake.factors", 0.0, 10.0, ""))
        if len(factors) > cars:
            raise _fail("brake.factors", br["factors"], f"at most {cars} numbers, one per car")
    if br and not design and ("times" not in br or "torques" not in br) and ("times" in br or "torques" in br):
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

    name, description = _meta(data)
    fluid = None
    if "fluid" in data:
        fluid = _fluid_spec(data, params)
        for sec, key, val in (
            ("lading", "mass", lading_mass),
            ("train", "wheelset_lateral_offset", offset),
            ("train", "coupler_stiffness", coupler_k),
            ("train", "coupler_damping", coupler_c),
        ):
            if val:
                raise _fail(f"{sec}.{key}", val, "not set in a scene with liquid cargo ([fluid])")
    else:
        for sec in ("mesh", "tank"):
            if sec in data:
                raise _fail(sec, data[sec], "only with a [fluid] section (liquid cargo)")
        if factors is not None:
            raise _fail("brake.factors", list(factors), "only with a [fluid] section (liquid cargo)")
    outputs = _outputs(data, fluid is not None, record_every)
    if brake_design is not None:
        mass = _car_parameters_total(car, wheel_profile) + lading_mass
        if fluid is not None:
            mass += fluid.mass(params)
        times, torques = vehicle.design_brake_torque(mass, speed, brake_design["v1"], brake_design["duration"])
        brake_times, brake_torques = tuple(times), tuple(torques)

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
        load_filter=load_filter,
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
        name=name,
        description=description,
        fluid=fluid,
        brake_factors=factors,
        brake_design=brake_design,
        outputs=outputs,
    )


def _car_parameters_total(car: Mapping[str, float], wheel_profile: str) -> float:
    return float(vehicle.tank_car_parameters(dict(car) or None, wheel_profile)["total_mass"])


def _meta(data: Mapping[str, Any]) -> tuple[str, str]:
    sec = _table(data.get("scene", {}), "scene")
    _check_keys(sec, "scene", ("name", "description"))
    out = []
    for k in ("name", "description"):
        v = sec.get(k, "")
        if not isinstance(v, str) or len(v) > 2000:
            raise _fail(f"scene.{k}", v, "a string of at most 2000 characters")
        out.append(v)
    return out[0], out[1]


_CUSTOM_KEYS = {
    "density": (100.0, 20_000.0, "kg/m^3"),
    "viscosity": (0.0, 1e5, "Pa s"),
    "yield_stress": (0.0, 1e5, "Pa"),
    "consistency": (0.0, 1e5, "Pa s^n"),
    "power_index": (0.05, 3.0, ""),
    "elastic_modulus": (1e-3, 1e9, "Pa"),
    "bulk_penalty": (1.0, 1e10, "Pa"),
    "bulk_damping": (0.0, 1e8, "Pa s"),
}


def _fluid_section(fl: Mapping[str, Any]) -> tuple[str, dict[str, Any]]:
    """``oil`` and the custom-fluid constructor arguments of a ``[fluid]`` table."""
    oil = _choice(fl.get("oil", "light"), "fluid.oil", OILS)
    custom: dict[str, Any] = {}
    if oil == "custom":
        if "model" not in fl or "density" not in fl:
            raise _fail("fluid.model" if "model" not in fl else "fluid.density", None, 'given with oil = "custom"')
        custom["model"] = _choice(fl["model"], "fluid.model", _RHEOLOGIES)
        for k, (lo, hi, unit) in _CUSTOM_KEYS.items():
            if k in fl:
                custom[k] = _number(fl[k], f"fluid.{k}", lo, hi, unit)
    else:
        for k in ("model", *_CUSTOM_KEYS):
            if k in fl:
                raise _fail(f"fluid.{k}", fl[k], 'only with oil = "custom"')
    return oil, custom


def _counts(value: Any, fieldname: str, limits: tuple[tuple[int, int], ...]) -> tuple[int, int, int]:
    if not isinstance(value, list | tuple) or len(value) != 3:
        raise _fail(fieldname, value, "three integers [n_length, n_width, n_height]")
    c = [_integer(x, f"{fieldname}[{i}]", *limits[i]) for i, x in enumerate(value)]
    return c[0], c[1], c[2]


def _bulkheads(value: Any, fieldname: str, half_length: float, n_length: int) -> tuple[tuple[float, float], ...]:
    """Bulkheads ``[[x, thickness], ...]``: inside the shell, increasing, not overlapping, and every
    compartment gets at least one element along the length."""
    if not isinstance(value, list | tuple) or len(value) > 10:
        raise _fail(fieldname, value, "a list of at most 10 [x, thickness] pairs")
    out: list[tuple[float, float]] = []
    for i, b in enumerate(value):
        if not isinstance(b, list | tuple) or len(b) != 2:
            raise _fail(f"{fieldname}[{i}]", b, "a pair [x (m), thickness (m)]")
        th = _number(b[1], f"{fieldname}[{i}][1] (thickness)", 0.001, 0.5, "m", open_lo=False)
        lim = half_length - th / 2 - 0.05
        x = _number(b[0], f"{fieldname}[{i}][0] (x)", -lim, lim, "m (inside the cylindrical shell)")
        if out and x - th / 2 <= out[-1][0] + out[-1][1] / 2:
            raise _fail(
                f"{fieldname}[{i}][0] (x)", x, f"increasing and clear of the previous bulkhead (> {out[-1][0]:g})"
            )
        out.append((x, th))
    if len(out) + 1 > n_length:
        raise _fail("mesh.counts[0]", n_length, f">= {len(out) + 1} (one element per compartment at least)")
    return tuple(out)


def _wall_damping_ratio(tk: Mapping[str, Any]) -> float:
    """``[tank] wall_damping_ratio`` (vehicle and slosh scenes), default the library's."""
    return _number(tk.get("wall_damping_ratio", vehicle.WALL_DAMPING_RATIO), "tank.wall_damping_ratio", 0.0, 10.0)


def _fluid_spec(data: Mapping[str, Any], params: Mapping[str, float]) -> FluidSpec:
    fl = _table(data["fluid"], "fluid")
    _check_keys(fl, "fluid", ("oil", "fill", "model", "slosh_model", *_CUSTOM_KEYS))
    oil, custom = _fluid_section(fl)
    fill = _number(fl.get("fill", 0.5), "fluid.fill", 0.1, 0.9, "(volume fraction)")
    slosh_model = _choice(fl.get("slosh_model", "auto"), "fluid.slosh_model", SLOSH_MODELS)
    ms = _table(data.get("mesh", {}), "mesh")
    _check_keys(ms, "mesh", ("counts",))
    counts = _counts(ms.get("counts", [6, 4, 2]), "mesh.counts", ((1, 40), (2, 20), (1, 10)))
    tk = _table(data.get("tank", {}), "tank")
    _check_keys(tk, "tank", ("bulkheads", "wall_damping_ratio"))
    half = 0.5 * (params["tank_length"] - 1.0)
    bulkheads = _bulkheads(tk.get("bulkheads", []), "tank.bulkheads", half, counts[0])
    zeta = _wall_damping_ratio(tk)
    spec = FluidSpec(
        oil=oil,
        fill=fill,
        counts=counts,
        bulkheads=bulkheads,
        custom=custom,
        slosh_model=slosh_model,
        wall_damping_ratio=zeta,
    )
    if oil == "custom":
        spec.make_fluid(2.0 * params["tank_radius"] * fill)  # validates the custom fluid now
    return spec


def _outputs(data: Mapping[str, Any], has_snapshots: bool, record_every: float) -> Outputs:
    out = _table(data.get("outputs", {}), "outputs")
    _check_keys(out, "outputs", ("netcdf", "vtu", "plots", "snapshot_every"))
    flags = {}
    for k in ("netcdf", "vtu", "plots"):
        v = out.get(k, True)
        if not isinstance(v, bool):
            raise _fail(f"outputs.{k}", v, "true or false")
        flags[k] = v
    snap = _number(out.get("snapshot_every", 0.0), "outputs.snapshot_every", 0.0, 600.0, "s")
    if 0.0 < snap < record_every:
        raise _fail("outputs.snapshot_every", snap, f"0 (none) or >= the recording interval {record_every:g} s")
    if snap > 0 and not has_snapshots:
        raise _fail("outputs.snapshot_every", snap, "0 in a scene without fluid mesh snapshots")
    return Outputs(snapshot_every=snap, **flags)


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


# --- prescribed-motion slosh scenes -------------------------------------------------------------

TANK_SHAPES = ("elliptic", "cylinder", "box")
MANEUVERS = ("lane_change", "bump", "pulse", "samples")
"""Names accepted by ``[maneuver] type``."""
_SLOSH_SECTIONS = ("scene", "tank", "fluid", "mesh", "maneuver", "solver", "outputs")


@dataclass(frozen=True)
class SloshScene:
    """A validated prescribed-motion slosh scene: a rigid tank moved by a maneuver, the liquid an
    ANCF fluid mesh (run with :func:`railslosh.slosh.run`). Sections:

    ``[tank]``: ``shape = "elliptic"`` (flat-ended cylinder of elliptical section; ``length``,
    ``semi_axis_y``, ``semi_axis_z``; defaults: the SwRI tank of seed 003), ``"cylinder"`` (``length``
    of the shell, ``radius``, ``head_depth``; defaults: the crude-oil tank car) or ``"box"`` (``lower``,
    ``upper`` corners); ``bulkheads`` as in vehicle scenes (cylinder only); ``wall_damping_ratio`` as in
    vehicle scenes (damping ratio of the liquid column on the penalty wall, 0 to 10, default 0.1).
    ``[fluid]``: as in vehicle scenes (``oil``, ``fill`` as a volume fraction, custom
    fluids). ``[mesh]``: ``counts``; ``viscous_points`` and ``penalty_points`` (Gauss points per
    direction of the viscous stress, 3-6, and of the volumetric penalty, 2-6; default 3) and
    ``contact_points_per_edge`` (wall-contact points per face edge, 2-6, default 3): coarse meshes
    under violent maneuvers need more (the SwRI scenes use 4, 4, 5: docs/validation.md, "Run-time
    invariants"). ``[solver]``:
    ``t_end`` (s), ``step`` (s), ``frame`` (``"inertial"`` or ``"tank"``), ``contact_stiffness_factor``
    (wall stiffness as a multiple of the default penalty law, 0.1 to 1000), ``stepper``
    (``"implicit"``, default; ``"explicit"``; ``"auto"``: see :func:`railslosh.slosh.run`).
    ``[outputs]``: ``netcdf``, ``plots``.
    ``[maneuver]``: ``type`` =

    Lane changes and bumps are built by the one maneuver library, ``rail_mbs::maneuvers`` (the
    co-simulation's seed 003 maneuvers are the same motions; its docs give the formulas):

    * ``"lane_change"``: lateral (y) displacement ``offset`` (m, default 3.66 = 12 ft) over ``length``
      (m, default 30.5 = 100 ft) at ``speed`` (m/s) or ``speed_mph``/``speed_kmh``; acceleration
      ``a(t) = 2 pi offset / T^2 sin(2 pi (t - t0) / T)``, ``T = length / speed`` (zero velocity at both
      ends); ``double = true`` (default) returns to the original lane after ``hold`` m (default 15.2);
      the tank heading (yaw about z) follows the path;
    * ``"bump"``: ``shape = "half_round" | "trapezoid"`` of ``height`` (m) or ``height_in``, crossed at
      ``speed`` by a two-axle vehicle (``wheelbase`` m, default 3.9; ``wheel_radius`` m, default 0.53,
      rolling over a half-round bump) with a quarter-car suspension per axle
      (``suspension_frequency`` Hz, default 2.0; ``suspension_damping`` ratio, default 0.3); the tank,
      midway between the axles, heaves and pitches; a trapezoid has ``ramp_up``, ``top`` and
      ``ramp_down`` lengths (m; defaults 4, 2 and 1 times the height: asymmetric, steep exit);
    * ``"pulse"``: ``axis``, ``acceleration`` (m/s^2), ``t0``, ``t1``, ``ramp`` (s);
    * ``"samples"``: ``x``, ``y``, ``z`` = ``[[t, a], ...]`` piecewise-linear accelerations.

    Every maneuver starts at ``t0`` (s, default 0.2).
    """

    tank: Any
    """The :class:`railslosh.slosh.TankGeometry`."""
    fluid: FluidSpec
    maneuver: Mapping[str, Any]
    """The validated ``[maneuver]`` table, SI units."""
    t_end: float = 2.0
    step: float = 0.01
    frame: str = "inertial"
    contact_stiffness_factor: float = 1.0
    """Wall stiffness as a multiple of the default penalty law (damping ratio kept)."""
    viscous_points: int = 3
    """Gauss points per direction of the viscous stress (3 to 6)."""
    penalty_points: int = 3
    """Gauss points per direction of the volumetric penalty (2 to 6)."""
    contact_points_per_edge: int = 3
    """Wall-contact Gauss points per boundary-face edge (2 to 6)."""
    stepper: str = "implicit"
    """``"implicit"``, ``"explicit"`` or ``"auto"`` (:func:`railslosh.slosh.run`)."""
    name: str = ""
    description: str = ""
    outputs: Outputs = field(default_factory=lambda: Outputs(vtu=False))
    raw: Mapping[str, Any] = field(default_factory=dict, compare=False, repr=False)

    kind = "slosh"

    def mesh(self) -> Any:
        """The fluid mesh (reference configuration, tank frame)."""
        from railslosh import mesh

        d, (nl, nw, nh), fill = self.tank.dims, self.fluid.counts, self.fluid.fill
        if self.tank.shape == "elliptic":
            return mesh.elliptic_cylinder(
                length=d[0],
                semi_axis_y=d[1],
                semi_axis_z=d[2],
                fill=fill,
                n_length=nl,
                n_width=nw,
                n_height=nh,
            )
        if self.tank.shape == "cylinder":
            return mesh.cylinder_tank(
                length=d[0],
                radius=d[1],
                head_depth=d[2],
                fill=fill,
                n_length=nl,
                n_width=nw,
                n_height=nh,
            )
        lo, hi = d[:3], d[3:]
        size = (hi[0] - lo[0], hi[1] - lo[1], fill * (hi[2] - lo[2]))
        return mesh.box(size, (nl, nw, nh), origin=lo)

    def depth(self) -> float:
        """Liquid depth of the mesh at rest, m."""
        m = self.mesh()
        return float(m.free_surface_z - m.nodes[:, 2].min())

    def motion(self) -> Any:
        """The :class:`railslosh.slosh.Motion` of the maneuver."""
        return _motion(self.maneuver, self.t_end)

    def peak_load_factor(self) -> float:
        """Largest ``|g - a| / g`` of the maneuver (apparent gravity of the liquid, in g)."""
        mo = self.motion()
        times = sorted({t for pts in mo.acceleration.values() for t, _ in pts if t <= self.t_end} | {0.0})
        acc = np.zeros((len(times), 3))
        for i, ax in enumerate(("x", "y", "z")):
            pts = mo.acceleration.get(ax)
            if pts:
                acc[:, i] = np.interp(times, [p[0] for p in pts], [p[1] for p in pts])
        g = np.array([0.0, 0.0, -GRAVITY])
        return float(np.linalg.norm(g - acc, axis=1).max() / GRAVITY)

    def run_args(self) -> tuple[tuple[Any, ...], dict[str, Any]]:
        """Positional and keyword arguments of :func:`railslosh.slosh.run`. Unless the scene sets
        ``fluid.bulk_penalty``, the penalty limits the volume strain to 1e-3 under the largest
        apparent gravity of the maneuver (``k = 1000 rho g depth`` times :meth:`peak_load_factor`),
        so that hard bumps stay within the run's volume-error guard."""
        depth = self.depth()
        spec = self.fluid
        if "bulk_penalty" not in spec.custom:
            from railslosh import fluids

            k = fluids.default_bulk_penalty(spec.density(), depth) * max(1.0, self.peak_load_factor())
            spec = dataclasses.replace(spec, custom={**spec.custom, "bulk_penalty": k})
        fluid = spec.make_fluid(depth, depth / spec.counts[2])
        kw: dict[str, Any] = {
            "t_end": self.t_end,
            "h": self.step,
            "frame": self.frame,
            "viscous_points": self.viscous_points,
            "penalty_points": self.penalty_points,
            "contact_points_per_edge": self.contact_points_per_edge,
            "stepper": self.stepper,
        }
        if self.contact_stiffness_factor != 1.0:
            kw["contact_stiffness_factor"] = self.contact_stiffness_factor
        if self.fluid.wall_damping_ratio != vehicle.WALL_DAMPING_RATIO:
            kw["wall_damping_ratio"] = self.fluid.wall_damping_ratio
        return (self.mesh(), fluid, self.tank, self.motion()), kw

    def to_dict(self) -> dict[str, Any]:
        """The scene as parsed (a dict that :func:`load_scene` reads back)."""
        return _merge(self.raw, {})


def _speed(m: Mapping[str, Any], prefix: str) -> float:
    given = [k for k in ("speed", "speed_mph", "speed_kmh") if k in m]
    if len(given) != 1:
        raise _fail(f"{prefix}.speed", None, "exactly one of `speed` (m/s), `speed_mph`, `speed_kmh`")
    k = given[0]
    scale = {"speed": 1.0, "speed_mph": MPH, "speed_kmh": 1 / 3.6}[k]
    return _number(m[k], f"{prefix}.{k}", 0.0, _MAX_SPEED / scale, "", open_lo=True) * scale


def _maneuver(m: Mapping[str, Any], t_end: float) -> dict[str, Any]:
    kind = _choice(m.get("type"), "maneuver.type", MANEUVERS)
    keys = {
        "lane_change": ("speed", "speed_mph", "speed_kmh", "offset", "length", "double", "hold"),
        "bump": (
            "speed",
            "speed_mph",
            "speed_kmh",
            "shape",
            "height",
            "height_in",
            "suspension_frequency",
            "suspension_damping",
            "wheelbase",
            "wheel_radius",
            "ramp_up",
            "top",
            "ramp_down",
        ),
        "pulse": ("axis", "acceleration", "t1", "ramp"),
        "samples": ("x", "y", "z"),
    }[kind]
    _check_keys(m, "maneuver", ("type", "t0", *keys))
    out: dict[str, Any] = {"type": kind, "t0": _number(m.get("t0", 0.2), "maneuver.t0", 0.0, 600.0, "s")}
    defaults = _maneuver_defaults()
    if kind == "lane_change":
        d = defaults["lane_change"]
        out["speed"] = _speed(m, "maneuver")
        out["offset"] = _number(m.get("offset", d["offset"]), "maneuver.offset", 0.1, 20.0, "m")
        out["length"] = _number(m.get("length", d["length"]), "maneuver.length", 1.0, 1000.0, "m")
        out["hold"] = _number(m.get("hold", d["hold"]), "maneuver.hold", 0.0, 1000.0, "m")
        dbl = m.get("double", True)
        if not isinstance(dbl, bool):
            raise _fail("maneuver.double", dbl, "true or false")
        out["double"] = dbl
    elif kind == "bump":
        out["speed"] = _speed(m, "maneuver")
        out["shape"] = _choice(m.get("shape", "half_round"), "maneuver.shape", ("half_round", "trapezoid"))
        if ("height" in m) == ("height_in" in m):
            raise _fail("maneuver.height", m.get("height"), "exactly one of `height` (m) or `height_in`")
        h = (
            _number(m["height"], "maneuver.height", 0.001, 1.0, "m")
            if "height" in m
            else _number(m["height_in"], "maneuver.height_in", 0.04, 40.0, "in") * INCH
        )
        out["height"] = h
        d = defaults["bump"]
        out["suspension_frequency"] = _number(
            m.get("suspension_frequency", d["suspension_frequency"]), "maneuver.suspension_frequency", 0.2, 50.0, "Hz"
        )
        out["suspension_damping"] = _number(
            m.get("suspension_damping", d["suspension_damping"]), "maneuver.suspension_damping", 0.01, 2.0, ""
        )
        out["wheelbase"] = _number(m.get("wheelbase", d["wheelbase"]), "maneuver.wheelbase", 0.5, 30.0, "m")
        out["wheel_radius"] = _number(m.get("wheel_radius", d["wheel_radius"]), "maneuver.wheel_radius", 0.1, 2.0, "m")
        if out["shape"] == "trapezoid":
            for k, f in defaults["trapezoid"].items():
                out[k] = _number(m.get(k, f * h), f"maneuver.{k}", 0.0 if k == "top" else 0.01, 100.0, "m")
        else:
            for k in ("ramp_up", "top", "ramp_down"):
                if k in m:
                    raise _fail(f"maneuver.{k}", m[k], 'only with shape = "trapezoid"')
    elif kind == "pulse":
        out["axis"] = _choice(m.get("axis", "x"), "maneuver.axis", ("x", "y", "z"))
        out["acceleration"] = _number(m.get("acceleration", 0.0), "maneuver.acceleration", -50.0, 50.0, "m/s^2")
        out["ramp"] = _number(m.get("ramp", 0.05), "maneuver.ramp", 1e-3, 10.0, "s", open_lo=False)
        lo = out["t0"] + 2 * out["ramp"]
        out["t1"] = _number(m.get("t1", t_end), "maneuver.t1", lo, 1e4, f"s (> t0 + 2 ramp = {lo:g})", open_lo=True)
    else:
        for ax in ("x", "y", "z"):
            if ax in m:
                rows = m[ax]
                if not isinstance(rows, list | tuple) or not 2 <= len(rows) <= _MAX_ROWS:
                    raise _fail(f"maneuver.{ax}", rows, f"a list of 2 to {_MAX_ROWS} pairs [t, a]")
                pts = []
                for i, r in enumerate(rows):
                    if not isinstance(r, list | tuple) or len(r) != 2:
                        raise _fail(f"maneuver.{ax}[{i}]", r, "a pair [t (s), a (m/s^2)]")
                    pts.append(
                        (
                            _number(r[0], f"maneuver.{ax}[{i}][0] (t)", 0.0, 1e4, "s"),
                            _number(r[1], f"maneuver.{ax}[{i}][1] (a)", -50.0, 50.0, "m/s^2"),
                        )
                    )
                _increasing([p[0] for p in pts], lambda i, ax=ax: f"maneuver.{ax}[{i}][0] (t)")
                out[ax] = pts
    return out


@functools.cache
def _maneuver_defaults() -> dict[str, dict[str, float]]:
    """Defaults of the ``[maneuver]`` keys, from the one maneuver library (``rail_mbs::maneuvers``)."""
    from railslosh import _core

    return _core.maneuver_defaults()


def _motion(m: Mapping[str, Any], t_end: float) -> Any:
    from railslosh import slosh

    mo = slosh.Motion()
    if m["type"] in ("lane_change", "bump"):
        # one definition (rail_mbs::maneuvers), shared with the co-simulation: accelerations
        # and the rotation (heading of a lane change, pitch over a bump) sampled every 1 ms
        from railslosh import _core

        d = _core.maneuver_motion(m, m["t0"], t_end)
        mo.acceleration = {ax: [(float(t), float(a)) for t, a in pts] for ax, pts in d["acceleration"].items()}
        if d["rotation_axis"] is not None:
            mo.rotation_axis = tuple(float(x) for x in d["rotation_axis"])
            mo.angular_acceleration = [(float(t), float(a)) for t, a in d["angular_acceleration"]]
    elif m["type"] == "pulse":
        mo.pulse(m["axis"], m["acceleration"], m["t0"], m["t1"], ramp=m["ramp"])
    else:
        for ax in ("x", "y", "z"):
            if ax in m:
                mo.acceleration[ax] = [(float(t), float(a)) for t, a in m[ax]]
    return mo


def _slosh_tank(tk: Mapping[str, Any], counts: tuple[int, int, int]) -> Any:
    from railslosh import mesh, slosh

    _check_keys(
        tk,
        "tank",
        ("shape", "length", "radius", "head_depth", "semi_axis_y", "semi_axis_z", "lower", "upper", "bulkheads"),
    )
    shape = _choice(tk.get("shape", "elliptic"), "tank.shape", TANK_SHAPES)
    allowed = {
        "elliptic": ("length", "semi_axis_y", "semi_axis_z"),
        "cylinder": ("length", "radius", "head_depth", "bulkheads"),
        "box": ("lower", "upper"),
    }[shape]
    for k in tk:
        if k != "shape" and k not in allowed:
            raise _fail(f"tank.{k}", tk[k], f"not with shape = {shape!r} (allowed: {', '.join(allowed)})")
    if shape == "elliptic":
        return slosh.TankGeometry.elliptic(
            _number(tk.get("length", mesh.SWRI_LENGTH), "tank.length", 0.05, 50.0, "m"),
            _number(tk.get("semi_axis_y", mesh.SWRI_SEMI_AXIS_Y), "tank.semi_axis_y", 0.02, 5.0, "m"),
            _number(tk.get("semi_axis_z", mesh.SWRI_SEMI_AXIS_Z), "tank.semi_axis_z", 0.02, 5.0, "m"),
        )
    if shape == "cylinder":
        length = _number(tk.get("length", mesh.TANK_CAR_LENGTH), "tank.length", 0.1, 50.0, "m")
        radius = _number(tk.get("radius", mesh.TANK_CAR_RADIUS), "tank.radius", 0.05, 5.0, "m")
        head = _number(tk.get("head_depth", mesh.TANK_CAR_HEAD_DEPTH), "tank.head_depth", 0.0, radius, "m (<= radius)")
        bh = _bulkheads(tk.get("bulkheads", []), "tank.bulkheads", length / 2, counts[0])
        return slosh.TankGeometry.cylinder(length, radius, head, bh)
    lo = [_number(x, f"tank.lower[{i}]", -50.0, 50.0, "m") for i, x in enumerate(_list3(tk.get("lower"), "tank.lower"))]
    hi = [_number(x, f"tank.upper[{i}]", -50.0, 50.0, "m") for i, x in enumerate(_list3(tk.get("upper"), "tank.upper"))]
    for i in range(3):
        if hi[i] <= lo[i] + 0.01:
            raise _fail(f"tank.upper[{i}]", hi[i], f"> tank.lower[{i}] + 0.01 = {lo[i] + 0.01:g} m")
    return slosh.TankGeometry.box((lo[0], lo[1], lo[2]), (hi[0], hi[1], hi[2]))


def _list3(v: Any, fieldname: str) -> list[Any]:
    if not isinstance(v, list | tuple) or len(v) != 3:
        raise _fail(fieldname, v, "three numbers [x, y, z] (m)")
    return list(v)


def slosh_scene_from_dict(data: Mapping[str, Any]) -> SloshScene:
    """Validates a parsed prescribed-motion scene (one with a ``[maneuver]`` section)."""
    data = _table(data, "scene")
    for k in data:
        if k not in _SLOSH_SECTIONS:
            raise ValueError(
                f"invalid parameter `{k}`: unknown section of a slosh scene; allowed one of "
                f"{', '.join(sorted(_SLOSH_SECTIONS))}"
            )
    name, description = _meta(data)
    sv = _table(data.get("solver", {}), "solver")
    _check_keys(sv, "solver", ("t_end", "step", "frame", "contact_stiffness_factor", "stepper"))
    stepper = _choice(sv.get("stepper", "implicit"), "solver.stepper", STEPPERS)
    wall = _number(sv.get("contact_stiffness_factor", 1.0), "solver.contact_stiffness_factor", 0.1, 1000.0, "")
    t_end = _number(sv.get("t_end", 2.0), "solver.t_end", 0.0, 600.0, "s", open_lo=True)
    step = _number(sv.get("step", 0.01), "solver.step", 1e-5, min(0.05, t_end), "s (<= t_end)")
    frame = _choice(sv.get("frame", "inertial"), "solver.frame", ("inertial", "tank"))
    fl = _table(data.get("fluid", {}), "fluid")
    _check_keys(fl, "fluid", ("oil", "fill", "model", *_CUSTOM_KEYS))
    oil, custom = _fluid_section(fl)
    fill = _number(fl.get("fill", 0.5), "fluid.fill", 0.1, 0.9, "(volume fraction)")
    ms = _table(data.get("mesh", {}), "mesh")
    _check_keys(ms, "mesh", ("counts", "viscous_points", "penalty_points", "contact_points_per_edge"))
    counts = _counts(ms.get("counts", [2, 4, 2]), "mesh.counts", ((1, 40), (1, 40), (1, 10)))
    rules = {
        k: _integer(ms.get(k, 3), f"mesh.{k}", lo, 6)
        for k, lo in (("viscous_points", 3), ("penalty_points", 2), ("contact_points_per_edge", 2))
    }
    tk = dict(_table(data.get("tank", {}), "tank"))
    zeta = _wall_damping_ratio(tk)
    tk.pop("wall_damping_ratio", None)
    tank = _slosh_tank(tk, counts)
    spec = FluidSpec(
        oil=oil, fill=fill, counts=counts, bulkheads=tank.bulkheads, custom=custom, wall_damping_ratio=zeta
    )
    maneuver = _maneuver(_table(data.get("maneuver", {}), "maneuver"), t_end)
    out = _table(data.get("outputs", {}), "outputs")
    if out.get("vtu", False) is not False or "snapshot_every" in out:
        raise _fail(
            "outputs.vtu" if "vtu" in out else "outputs.snapshot_every",
            out.get("vtu", out.get("snapshot_every")),
            "not in a slosh scene (fluid snapshots come from vehicle scenes)",
        )
    outputs = dataclasses.replace(
        _outputs({"outputs": {k: v for k, v in out.items() if k != "vtu"}}, False, step), vtu=False
    )
    sc = SloshScene(
        tank=tank,
        fluid=spec,
        maneuver=maneuver,
        t_end=t_end,
        step=step,
        frame=frame,
        contact_stiffness_factor=wall,
        stepper=stepper,
        name=name,
        description=description,
        outputs=outputs,
        raw=dict(data),
        **rules,
    )
    try:
        sc.mesh()
        sc.fluid.make_fluid(sc.depth())
    except ValueError as exc:
        msg = str(exc)
        raise ValueError(msg if msg.startswith("invalid parameter") else f"invalid parameter `mesh`: {msg}") from exc
    return sc


def load_scene(
    source: str | os.PathLike[str] | Mapping[str, Any], overrides: Mapping[str, Any] | None = None
) -> Scene | SloshScene:
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
    if isinstance(data, Mapping) and "maneuver" in data:
        return slosh_scene_from_dict(data)
    return scene_from_dict(data)


def run_scene(
    scene: Scene | SloshScene | str | os.PathLike[str] | Mapping[str, Any],
    progress: Any = None,
) -> dict[str, Any]:
    """Runs a scene (a :class:`Scene` or :class:`SloshScene`, or anything :func:`load_scene` takes)
    with :func:`railslosh.vehicle.run`, :func:`railslosh.vehicle.run_fluid` or
    :func:`railslosh.slosh.run`; returns its dict of arrays with ``"scene"`` added.

    ``progress(t, t_end, steps, newton_iterations, rejected_steps)`` is called during the run (about
    every 0.5 s of wall time); if it raises, the run stops and the exception propagates.
    Vehicle scenes with liquid cargo run the fluid model of :func:`railslosh.fluid_model.decide`
    (``[fluid] slosh_model``); every vehicle result carries ``fluid_model`` and ``fluid_model_reason``.
    Raises :class:`railslosh.slosh.SimulationError` when the run stops early."""
    from railslosh import fluid_model, slosh

    sc = scene if isinstance(scene, Scene | SloshScene) else load_scene(scene)
    if isinstance(sc, SloshScene):
        args, kw = sc.run_args()
        res = slosh.run(*args, **kw, progress=progress)
        res["scene"] = sc
        return res
    choice = fluid_model.decide(sc)
    rows = np.asarray(sc.track_rows, dtype=float)
    try:
        if sc.fluid is None:
            res = vehicle.run(rows, **sc.run_kwargs(), progress=progress)
        elif choice.model == "ancf":
            res = vehicle.run_fluid(rows, **sc.fluid_kwargs(), progress=progress)
        elif choice.model == "pendulum":
            res = vehicle.run_equivalent(rows, **sc.equivalent_kwargs(choice.axis or "longitudinal"), progress=progress)
        else:
            res = vehicle.run(rows, **sc.rigid_kwargs(), progress=progress)
    except slosh.SimulationError as exc:
        exc.results.update(fluid_model=choice.model, fluid_model_reason=choice.reason)
        raise
    res["fluid_model"] = choice.model
    res["fluid_model_reason"] = choice.reason
    res["scene"] = sc
    return res
