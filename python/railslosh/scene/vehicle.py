"""Vehicle scenes: a train of tank cars on a track, with rigid lading or liquid cargo, as a
validated :class:`Scene` whose methods give the arguments of the :mod:`railslosh.vehicle` runs."""

from __future__ import annotations

import dataclasses
import functools
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from railslosh import _core, rail, vehicle
from railslosh.irregularity import Irregularity, from_spec
from railslosh.limits import Limit, invalid, missing
from railslosh.scene.common import Outputs, meta, settle_time, vehicle_outputs
from railslosh.scene.fluid import FluidSpec, vehicle_fluid
from railslosh.scene.schema import DEFAULT_STEP, Section, increasing, number_list, scoped, table, unknown_sections
from railslosh.scene.track import friction_table, irregularity_spec, irregularity_table, track

_BRAKE_TIME = Limit(0.0, 1e4, "s", "a time")
_BRAKE_TORQUE = Limit(0.0, 1e5, "N m", "a torque")
_BRAKE_FACTOR = Limit(0.0, 10.0, "", "a factor")


@functools.cache
def car_defaults() -> dict[str, float]:
    """The tank car's scalar parameters (``[car]`` keys) and their defaults."""
    p = vehicle.tank_car_parameters()
    return {k: float(v) for k, v in p.items() if k not in ("dof", "total_mass")}


def car_limit(key: str, default: float) -> tuple[Limit, str]:
    """Allowed range of a car parameter and the rule, in words: friction in [0, 1]; stiffness and
    damping from 0 (switched off) to 10 times the default; every other quantity 0.1 to 10 times
    its default."""
    if key == "friction":
        return Limit(0.0, 1.0, noun="a friction coefficient"), ""
    if re.search(r"_[kc][xyz]?$", key) or key.endswith(("stiffness", "damping")):
        return Limit(0.0, 10.0 * max(default, 1.0)), " (0 to 10 times the default)"
    return Limit(0.1 * default, 10.0 * default), " (0.1 to 10 times the default)"


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
    step: float | None = None
    """``[train] step``, the largest integrator step, s; ``None`` (not given): chosen for the run by
    :meth:`largest_step`."""
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
    car: Mapping[str, float | str] = field(default_factory=dict)
    wheel_profile: str = "s1002"
    name: str = ""
    """Title of the scene (``[scene] name``)."""
    description: str = ""
    settle_time: float | None = None
    """``[scene] settle_time``: the settling phase that peaks, statistics and the report leave out, s
    (``None``: detected from the results, :func:`railslosh.results.settling`)."""
    fluid: FluidSpec | None = None
    """Liquid cargo (``[fluid]``, ``[mesh]``, ``[tank]``); ``None`` = rigid lading only."""
    brake_factors: tuple[float, ...] | None = None
    brake_design: Mapping[str, float] | None = None
    """``{"v1": m/s, "duration": s}`` when ``[brake] design = true`` (times/torques then computed)."""
    outputs: Outputs = field(default_factory=lambda: Outputs())
    irregularity: Mapping[str, Any] | None = None
    """``[track.irregularities]`` as given, checked (SI units; a scene file's relative ``file`` made
    absolute); ``None`` = perfect track. :meth:`irregularity_spec` fills in the defaults for this train."""
    friction_map: Mapping[str, Any] | None = None
    """``[track.friction]``, checked (the ``friction_map`` of :func:`railslosh.vehicle.run`); ``None`` =
    ``car.friction`` everywhere."""

    @property
    def kind(self) -> str:
        """``"vehicle"`` (rigid lading) or ``"fluid_vehicle"`` (ANCF liquid in the tanks)."""
        return "vehicle" if self.fluid is None else "fluid_vehicle"

    def track(self) -> rail.Track:
        """The track as a :class:`railslosh.rail.Track`."""
        return rail.Track.from_table(np.asarray(self.track_rows, dtype=float))

    def mirror_symmetric(self) -> bool:
        """Whether the run's inputs are mirror-symmetric about the track's vertical centre plane
        (y → −y, ``docs/frames.md``): straight track without superelevation, rail cants mirrored
        (``cant_right == −cant_left``, Table 1 convention), no irregularity, no friction map and no
        wheelset offset. The cars, tanks, liquids and brakes are symmetric by construction, so every
        lateral response of such a run (the liquid's lateral load and centre of mass, left against
        right wheel loads) is zero in an exact solution (:func:`railslosh.scene.run.mirror_symmetry`)."""
        rows = np.zeros((len(self.track_rows), 6))
        for i, r in enumerate(self.track_rows):
            rows[i, : len(r)] = r
        straight = bool(np.all(rows[:, 1] == 0.0) and np.all(rows[:, 2] == 0.0))
        cants = bool(np.all(rows[:, 4] == -rows[:, 5]))
        perfect = self.irregularity is None or self.irregularity.get("kind") == "perfect"
        return straight and cants and perfect and self.friction_map is None and self.wheelset_lateral_offset == 0.0

    def irregularity_spec(self) -> dict[str, Any] | None:
        """The track irregularity of ``[track.irregularities]`` for this train, defaults filled in (the
        spec of :func:`railslosh.irregularity.from_spec`: ``start`` 10 m ahead of the leading wheelset
        at t = 0, ``length`` covering the run, ...); ``None`` on perfect track."""
        if self.irregularity is None:
            return None
        return irregularity_spec(
            self.irregularity,
            cars=self.cars,
            station=self.station,
            car=self.car,
            speed=max(self.speed, self.drive if not isinstance(self.drive, bool) else 0.0),
            t_end=self.t_end,
        )

    def track_irregularity(self) -> Irregularity | None:
        """The :class:`railslosh.irregularity.Irregularity` of :meth:`irregularity_spec` (``None`` on
        perfect track): generated (a fraction of a second for a few hundred metres; the cost grows
        with the length squared) or read from its file, once per scene (the fluid-model rule and
        the run both ask for it; a changed scene, ``dataclasses.replace``, makes its own)."""
        return self._track_irregularity

    @functools.cached_property
    def _track_irregularity(self) -> Irregularity | None:
        spec = self.irregularity_spec()
        return None if spec is None else from_spec(spec)

    def largest_step(self, model: str = "rigid") -> tuple[float, str]:
        """The largest integrator step of a run of this scene with liquid model ``model``
        (``"ancf"``, ``"pendulum"`` or ``"rigid"``), s, and why: ``[train] step`` where the scene
        gives it; else, for a braked ANCF run of a named oil, the step at which its coupler force is
        converged (:func:`railslosh._core.braking_step`: 2 ms for ECP with light crude or water,
        1 ms with medium or heavy crude, 4 ms for conventional braking); else
        :data:`DEFAULT_STEP`. So a sweep over the oil of a scene without ``step`` gives each oil
        its own step."""
        if self.step is not None:
            return self.step, "train.step"
        f = self.fluid
        if model == "ancf" and f is not None and f.oil != "custom" and self.brake_times is not None:
            scope = "ECP" if self.brake_scope == "all" else "conventional"
            return _core.braking_step(
                self.brake_scope, f.oil
            ), f"{scope} braking of {f.oil} (railslosh._core.braking_step)"
        return DEFAULT_STEP, "the default"

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
            "step": self.largest_step()[0],
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
            "irregularity": self.track_irregularity(),
            "friction_map": None if self.friction_map is None else dict(self.friction_map),
        }

    def fluid_kwargs(self) -> dict[str, Any]:
        """Keyword arguments of :func:`railslosh.vehicle.run_fluid` (after the track)."""
        if self.fluid is None:
            raise missing("fluid", "a scene with a [fluid] section (liquid cargo)")
        kw = self.run_kwargs()
        for k in ("lading_mass", "lading_height", "wheelset_lateral_offset", "coupler_stiffness", "coupler_damping"):
            kw.pop(k)
        f = self.fluid
        kw |= {
            "step": self.largest_step("ancf")[0],
            "oil": f.oil if f.oil != "custom" else "light",
            "fluid": f.make_fluid(2.0 * self.tank_radius() * f.fill) if f.oil == "custom" else None,
            "counts": f.counts,
            "fill": f.fill,
            "bulkheads": [tuple(b) for b in f.bulkheads] or None,
            "snapshot_every": self.outputs.snapshot_every,
            "brake_factors": None if self.brake_factors is None else list(self.brake_factors),
            "wall_damping_ratio": f.wall_damping_ratio,
            "wall_adhesion": f.wall_adhesion,
            "shear_stabilization": f.shear_stabilization,
        }
        return kw

    def equivalent_kwargs(self, slosh_axis: str) -> dict[str, Any]:
        """Keyword arguments of :func:`railslosh.vehicle.run_equivalent` (after the track): the liquid
        as its equivalent slosh model along ``slosh_axis``."""
        kw = self.fluid_kwargs()
        for k in ("counts", "snapshot_every", "wall_damping_ratio", "wall_adhesion", "shear_stabilization"):
            kw.pop(k)
        kw["slosh_axis"] = slosh_axis
        kw["step"] = self.largest_step("pendulum")[0]
        return kw

    def rigid_kwargs(self) -> dict[str, Any]:
        """Keyword arguments of :func:`railslosh.vehicle.run` (after the track) with the liquid as rigid
        lading: its mass at its rest centroid height, spread over the compartments' length (its pitch and
        yaw inertia, ``car.lading_length``, as the equivalent model's fixed masses carry theirs)."""
        if self.fluid is None:
            return self.run_kwargs()
        f = self.fluid
        geo = vehicle.equivalent_model(f.fill, bulkheads=list(f.bulkheads) or None, car=dict(self.car) or None)
        kw = self.run_kwargs()
        kw["lading_mass"] = f.mass({**car_defaults(), **self.car})
        kw["lading_height"] = float(geo["centroid"][2])
        kw["car"] = {**self.car, "lading_length": float(sum(m["compartment_length"] for m in geo["modes"]))}
        return kw

    def tank_radius(self) -> float:
        """Tank radius of the car, m (default or ``[car] tank_radius``)."""
        return float({**car_defaults(), **self.car}["tank_radius"])

    def replace(self, **changes: Any) -> Scene:
        """A copy with fields changed, validated again (e.g. ``scene.replace(t_end=0.1)``)."""
        new = scene_from_dict(_to_dict(dataclasses.replace(self, **changes)))
        return dataclasses.replace(new, track_source=self.track_source)

    def to_dict(self) -> dict[str, Any]:
        """The scene as a TOML-like dict (SI units) that :func:`railslosh.scene.load_scene` reads back."""
        return _to_dict(self)


def _to_dict(sc: Scene) -> dict[str, Any]:
    train: dict[str, Any] = {
        "cars": sc.cars,
        "station": sc.station,
        "speed": sc.speed,
        "drive": sc.drive,
        "t_end": sc.t_end,
        "record_every": sc.record_every,
        "load_filter": sc.load_filter,
        "wheelset_lateral_offset": sc.wheelset_lateral_offset,
    }
    if sc.step is not None:
        train["step"] = sc.step
    if sc.coupler_stiffness is not None:
        train["coupler_stiffness"] = sc.coupler_stiffness
    if sc.coupler_damping is not None:
        train["coupler_damping"] = sc.coupler_damping
    d: dict[str, Any] = {"track": {"rows": [list(r) for r in sc.track_rows]}, "train": train}
    if sc.friction_map is not None:
        d["track"]["friction"] = {
            k: [list(p) for p in v] if isinstance(v, list) else v for k, v in sc.friction_map.items()
        }
    if sc.irregularity is not None:
        d["track"]["irregularities"] = {
            k: [dict(x) for x in v] if k == "defects" else (list(v) if isinstance(v, list | tuple) else v)
            for k, v in sc.irregularity.items()
        }
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


def _car(doc: Mapping[str, Any]) -> tuple[dict[str, Any], str]:
    """``[car]``: the overridden parameters (checked by the model too; ``truck`` a name, every
    other one a number) and the wheel profile."""
    defaults = car_defaults()
    sec = Section("vehicle", "car", doc, extra=defaults)
    wheel_profile = sec.get("wheel_profile")
    car: dict[str, Any] = {}
    for k, v in sec.values.items():
        if k == "truck":
            car[k] = sec.get("truck")
        elif k != "wheel_profile":
            limit, note = car_limit(k, defaults[k])
            car[k] = limit.check(v, f"car.{k}", note=note)
    if car or wheel_profile != "s1002":
        try:
            vehicle.tank_car_parameters(car or None, wheel_profile)
        except Exception as exc:  # any rejection by the model is a bad [car] section
            raise scoped(exc, "car") from exc
    return car, wheel_profile


def _train(doc: Mapping[str, Any], rows: list[list[float]], params: Mapping[str, float]) -> dict[str, Any]:
    """``[train]``: every key checked; the whole train stays on the track for the whole run."""
    tr = Section("vehicle", "train", doc)
    out: dict[str, Any] = {"cars": tr.get("cars")}
    if "speed" in tr and "speed_kmh" in tr:
        raise invalid("train.speed", tr.values["speed"], "either `train.speed` (m/s) or `train.speed_kmh`, not both")
    speed = tr.get("speed_kmh") / 3.6 if "speed_kmh" in tr else tr.get("speed")
    drive = tr.values.get("drive", False)
    if not isinstance(drive, bool):
        drive = tr.field("speed").limit.check(drive, "train.drive", note=" (or true / false)")  # type: ignore[union-attr]
    out |= {"speed": speed, "drive": drive, "t_end": tr.get("t_end")}
    out["step"] = tr.get("step") if "step" in tr else None  # None: Scene.largest_step chooses
    out["record_every"] = tr.get("record_every", lo=out["step"] or DEFAULT_STEP, note=" (≥ train.step)")
    out["load_filter"] = tr.get("load_filter")
    for k in ("wheelset_lateral_offset", "coupler_stiffness", "coupler_damping"):
        out[k] = tr.get(k)

    # The train must fit on the track: front and rear couplers inside the table for the whole run.
    reach = params["coupler_reach"]
    pitch = 2.0 * reach + 1.0
    travel = max(speed, drive if not isinstance(drive, bool) else 0.0) * out["t_end"]
    lo = rows[0][0] + (out["cars"] - 1) * pitch + reach
    hi = rows[-1][0] - reach - travel
    out["station"] = tr.get("station")
    if not lo <= out["station"] <= hi:
        raise invalid(
            "train.station",
            tr.values.get("station", 50.0),
            f"a track position from {lo:.3f} to {hi:.3f} m (all {out['cars']} car(s) on the track for the whole run)",
        )
    return out


def _brake(doc: Mapping[str, Any], speed: float, cars: int) -> dict[str, Any]:
    """``[brake]``: a torque table or the designed brake, its scope and per-car factors."""
    br = Section("vehicle", "brake", doc)
    out: dict[str, Any] = {"scope": br.get("scope"), "design": None, "times": None, "torques": None, "factors": None}
    if br.get("design"):
        if "times" in br or "torques" in br:
            raise invalid("brake.design", True, "either `brake.design = true` or `brake.times`/`brake.torques`")
        v1 = br.get("design_v1_kmh", hi=speed * 3.6, note=" (≤ the train speed)")
        duration = br.get("design_duration")
        if speed <= v1 / 3.6:
            raise invalid("train.speed", speed, "a speed > brake.design_v1_kmh for a designed brake")
        out["design"] = {"v1": v1 / 3.6, "duration": duration}
    else:
        br.only_with(("design_v1_kmh", "design_duration"), "with `brake.design = true`")
    if "factors" in br:
        out["factors"] = tuple(number_list(br.values["factors"], "brake.factors", _BRAKE_FACTOR))
        if len(out["factors"]) > cars:
            raise invalid("brake.factors", br.values["factors"], f"at most {cars} numbers, one per car")
    if out["design"] is None and ("times" in br) != ("torques" in br):
        absent = "brake.times" if "times" not in br else "brake.torques"
        raise missing(absent, "both `brake.times` and `brake.torques` in a [brake] section")
    if "times" in br:
        times = number_list(br.values["times"], "brake.times", _BRAKE_TIME)
        increasing(times, lambda i: f"brake.times[{i}]")
        torques = number_list(br.values["torques"], "brake.torques", _BRAKE_TORQUE)
        if len(torques) != len(times):
            raise invalid("brake.torques", br.values["torques"], f"{len(times)} numbers, one per `brake.times`")
        out["times"], out["torques"] = tuple(times), tuple(torques)
    return out


def _lading(doc: Mapping[str, Any], radius: float) -> tuple[float, float]:
    """``[lading]``: rigid lading mass and height of its centre within the tank radius."""
    ld = Section("vehicle", "lading", doc)
    return ld.get("mass"), ld.get("height", lo=-radius, hi=radius, note=" (within the tank radius)")


def scene_from_dict(data: Mapping[str, Any]) -> Scene:
    """Validates a parsed vehicle scene (the dict a TOML file gives) and returns the :class:`Scene`."""
    data = table(data, "scene")
    unknown_sections(data, "vehicle")
    if "track" not in data:
        raise missing("track", "a [track] section (preset, rows or us_rows)")
    rows, source = track(data)
    irregular = irregularity_table(data)
    # [car] first: the train and lading checks use its geometry.
    car, wheel_profile = _car(data)
    params = {**car_defaults(), **car}
    tr = _train(data, rows, params)
    if irregular is not None:  # checked against the train (where it stands, how far it runs)
        speed = max(tr["speed"], tr["drive"] if not isinstance(tr["drive"], bool) else 0.0)
        irregularity_spec(irregular, cars=tr["cars"], station=tr["station"], car=car, speed=speed, t_end=tr["t_end"])
    br = _brake(data, tr["speed"], tr["cars"])
    lading_mass, lading_height = _lading(data, params["tank_radius"])
    name, description = meta("vehicle", data)
    settle = settle_time("vehicle", data)
    fluid = None
    if "fluid" in data:
        fluid = vehicle_fluid(data, params)
        for key, val in (
            ("lading.mass", lading_mass),
            ("train.wheelset_lateral_offset", tr["wheelset_lateral_offset"]),
            ("train.coupler_stiffness", tr["coupler_stiffness"]),
            ("train.coupler_damping", tr["coupler_damping"]),
        ):
            if val:
                raise invalid(key, val, "none in a scene with liquid cargo ([fluid])")
    else:
        for sec in ("mesh", "tank"):
            if sec in data:
                raise invalid(sec, data[sec], "no [mesh] or [tank] section without a [fluid] section (liquid cargo)")
        if br["factors"] is not None:
            raise invalid("brake.factors", list(br["factors"]), "no factors without a [fluid] section (liquid cargo)")
    outputs = vehicle_outputs(data, fluid is not None, tr["record_every"])
    times, torques = br["times"], br["torques"]
    if br["design"] is not None:
        mass = float(vehicle.tank_car_parameters(dict(car) or None, wheel_profile)["total_mass"]) + lading_mass
        if fluid is not None:
            mass += fluid.mass(params)
        t, q = vehicle.design_brake_torque(mass, tr["speed"], br["design"]["v1"], br["design"]["duration"])
        times, torques = tuple(t), tuple(q)

    return Scene(
        track_rows=tuple(tuple(r) for r in rows),
        track_source=source,
        **{k: tr[k] for k in ("cars", "station", "speed", "drive", "t_end", "step", "record_every", "load_filter")},
        wheelset_lateral_offset=tr["wheelset_lateral_offset"],
        coupler_stiffness=tr["coupler_stiffness"],
        coupler_damping=tr["coupler_damping"],
        brake_times=times,
        brake_torques=torques,
        brake_scope=br["scope"],
        lading_mass=lading_mass,
        lading_height=lading_height,
        car=car,
        wheel_profile=wheel_profile,
        name=name,
        description=description,
        settle_time=settle,
        fluid=fluid,
        brake_factors=br["factors"],
        brake_design=br["design"],
        outputs=outputs,
        irregularity=irregular,
        friction_map=friction_table(data),
    )
