"""Rail vehicles: the freight tank car of the crude-oil paper (seed 000 §8.1, 68 DOF) and trains
of such cars joined by couplers, run on a track with rigid lading.

    >>> from railslosh import rail, vehicle
    >>> track = rail.Track([0, 5000], curvature=[1 / 1000] * 2, superelevation=[0.0425] * 2)
    >>> res = vehicle.run(track, speed=60 / 3.6, drive=True, t_end=2.0, lading_mass=36e3, lading_height=-0.5)
    >>> res["wheel_vertical"].shape   # (samples, wheelsets, [left, right]), N
    >>> res["l_over_v"], res["unloading"], res["coupler_force"]

Every car parameter has a documented default (``tank_car_parameters()`` lists them with the
DOF count; sources in the Rust docs of ``rail_mbs::vehicle::TankCarParams``) and can be
overridden with ``car={"wheelbase": 1.778, ...}``; ``car={"truck": "three_piece"}`` builds each bogie as a
warp-capable three-piece freight truck instead of seed 000's rigid frame
(``rail_mbs::vehicle::TruckModel``; docs/user-guide.md, "Bogie model"). Units are SI; wheel arrays are ordered front to
rear over all cars, ``[left, right]`` looking forward; lateral forces are positive to the track's
left; coupler forces are positive in tension.
"""

from __future__ import annotations

import math
import numbers
import os
import warnings
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from railslosh import _core, limits
from railslosh import irregularity as irregularity_module
from railslosh.irregularity import CLEARANCE, Irregularity
from railslosh.kernel_args import EquivalentCargoArgs, FluidCargoArgs, TrainArgs
from railslosh.progress import ProgressArg
from railslosh.progress import callback as progress_callback
from railslosh.slosh import SimulationError

WALL_DAMPING_RATIO: float = _core.WALL_DAMPING_RATIO
"""Default damping ratio of the liquid column on the penalty wall of a fluid vehicle run
(``rail_mbs``/``ancf_core::contact::WALL_DAMPING_RATIO``; ``wall_damping_ratio`` of :func:`run_fluid`)."""

__all__ = [
    "design_brake_torque",
    "equivalent_model",
    "read_stream",
    "run",
    "run_equivalent",
    "run_fluid",
    "tank_car_parameters",
    "wheelset_stations",
]


def tank_car_parameters(car: dict[str, float | str] | None = None, wheel_profile: str = "s1002") -> dict[str, float]:
    """Default (or overridden) scalar parameters of the tank car, its total mass and DOF count. ``car``
    overrides numbers by name, and ``truck`` ("rigid_frame", the default, or "three_piece") picks the
    bogie model (the DOF count follows it)."""
    return dict(_core.tank_car_parameters(car, wheel_profile))


def wheelset_stations(cars: int = 1, station: float = 50.0, car: dict[str, float | str] | None = None) -> np.ndarray:
    """Track positions (arc length s, m) of every wheelset at t = 0, front to rear over all cars whose
    front tank centre is at ``station``: read off the train that ``rail_mbs::vehicle::build_train``
    builds, so it is the runs' own placement (car k's tank centre at ``station - k (2 coupler_reach +
    1)``, its bogie centres at ± ``truck_centers``/2, the wheelsets at ± ``wheelbase``/2 about them)."""
    return np.asarray(_core.wheelset_stations(int(cars), float(station), car), dtype=float)


def _irregularity(
    irregularity: Irregularity | dict[str, Any] | None,
    cars: int,
    station: float,
    car: dict[str, float | str] | None,
    travel: Any = None,
) -> tuple[dict[str, Any] | None, Irregularity | None]:
    """The samples dict for the kernels and the :class:`railslosh.irregularity.Irregularity`
    (``None``, ``None`` without one), checked to be zero under the train at t = 0. A generated FRA
    track that exceeds its class's gauge or cross-level limits within ``travel`` (m, the initial
    speed times the run's time) ahead of the leading wheelset is run as given, with a warning
    (:func:`railslosh.irregularity.class_limit_exceedances`)."""
    if irregularity is None:
        return None, None
    irr = irregularity if isinstance(irregularity, Irregularity) else Irregularity.from_dict(irregularity)
    if isinstance(cars, bool) or not isinstance(cars, numbers.Integral) or cars < 1:
        return irr.to_dict(), irr  # the kernels refuse the train with their own message
    if isinstance(station, bool) or not isinstance(station, numbers.Real):
        return irr.to_dict(), irr
    lead = float(wheelset_stations(cars, station, car)[0])
    clear = irr.clear_until()
    if clear < lead + CLEARANCE:
        where = "everywhere (its first sample is not zero)" if clear == -float("inf") else f"from {clear:.6g} m"
        raise limits.invalid(
            "irregularity",
            {k: v for k, v in irr.spec.items() if k != "defects"},
            f"a track that is perfect under the train at t = 0, up to {CLEARANCE:g} m ahead of the leading "
            f"wheelset at {lead:.6g} m; it is irregular {where}: start the irregular section (and its taper) "
            f"at {lead + CLEARANCE:.6g} m or beyond",
        )
    if isinstance(travel, numbers.Real) and math.isfinite(travel):
        exceeded = irregularity_module.class_limit_exceedances(irr, lead + abs(float(travel)))
        if exceeded:
            warnings.warn(
                f"the generated FRA class {irr.spec.get('class')} track exceeds its class's limits where "
                f"this run goes (up to {lead + abs(float(travel)):.6g} m): {'; '.join(exceeded)}. It runs as "
                "given; a real track of that class would be repaired there",
                RuntimeWarning,
                stacklevel=3,
            )
    return irr.to_dict(), irr


def _travel(speed: Any, t_end: Any) -> float | None:
    """How far the train goes at its initial ``speed`` (m/s) in ``t_end`` (s), m; ``None`` for input
    the kernels will refuse."""
    ok = all(isinstance(x, numbers.Real) and not isinstance(x, bool) for x in (speed, t_end))
    return float(speed) * float(t_end) if ok else None


def _table(track: Any) -> list[list[float]]:
    if hasattr(track, "table"):
        rows = np.asarray(track.table() if callable(track.table) else track.table, dtype=float)
    else:
        rows = np.asarray(track, dtype=float)
    if rows.ndim != 2 or rows.shape[1] != 6:
        raise ValueError(
            "invalid `track`: expected a rail.Track or rows (s, curvature, superelevation, grade, "
            f"cant_right, cant_left), got shape {rows.shape}"
        )
    return rows.tolist()


def _drive_and_brake(
    drive: bool | float, speed: float, brake: tuple[Sequence[float], Sequence[float]] | None
) -> tuple[float | None, list[float] | None, list[float] | None]:
    """Driven speed (None = free) and the brake table as lists."""
    drive_speed = None
    if drive is True:
        drive_speed = float(speed)
    elif drive is not False:
        drive_speed = float(drive)
    if brake is None:
        return drive_speed, None, None
    return drive_speed, list(map(float, brake[0])), list(map(float, brake[1]))


def _raise_on_error(res: dict[str, Any], what: str) -> dict[str, Any]:
    if "error" in res:
        t_last = res["t"][-1] if len(res["t"]) else 0.0
        raise SimulationError(f"{what} stopped at t = {t_last:.4f} s: {res['error']}", res)
    return res


def _bulkheads(bulkheads: Sequence[tuple[float, float]] | None) -> list[tuple[float, float]] | None:
    """Bulkheads ``[(x, thickness)]`` (tank frame, m) as the kernels take them."""
    return None if bulkheads is None else [(float(x), float(t)) for x, t in bulkheads]


def _train_args(
    track: Any,
    *,
    irregularity: Irregularity | dict[str, Any] | None,
    cars: int,
    station: float,
    speed: float,
    t_end: float,
    drive: bool | float,
    brake: tuple[Sequence[float], Sequence[float]] | None,
    brake_factors: Sequence[float] | None = None,
    car: dict[str, float | str] | None,
    friction_map: Mapping[str, Any] | None,
    **settings: Any,
) -> tuple[TrainArgs, Irregularity | None]:
    """The train of a vehicle run as the kernels take it (:class:`railslosh.kernel_args.TrainArgs`), one form
    for :func:`run`, :func:`run_fluid` and :func:`run_equivalent`, and the run's irregularity.
    ``settings`` are the remaining ``TrainArgs`` keys, passed on as given (``step``,
    ``record_every``, ``load_filter``, ``brake_scope``, ``wheel_profile``, ...)."""
    drive_speed, times, torques = _drive_and_brake(drive, speed, brake)
    samples, irr = _irregularity(irregularity, cars, station, car, _travel(speed, t_end))
    train = TrainArgs(
        track=_table(track),
        irregularity=samples,
        cars=cars,
        station=station,
        speed=speed,
        t_end=t_end,
        drive_speed=drive_speed,
        brake_times=times,
        brake_torques=torques,
        brake_factors=None if brake_factors is None else list(map(float, brake_factors)),
        car=car,
        friction_map=None if friction_map is None else dict(friction_map),
        **settings,
    )
    return train, irr


def _run_files(
    checkpoint: str | os.PathLike[str] | None, checkpoint_every: int, resume_from: str | os.PathLike[str] | None
) -> dict[str, Any]:
    """The ``TrainArgs`` keys of a run's checkpoint file and the file it resumes from."""
    return {
        "checkpoint": None if checkpoint is None else os.fspath(checkpoint),
        "checkpoint_every": checkpoint_every,
        "resume_from": None if resume_from is None else os.fspath(resume_from),
    }


def _run_train(
    kernel: Any,
    what: str,
    train: TrainArgs,
    irr: Irregularity | None,
    *cargo: FluidCargoArgs | EquivalentCargoArgs,
    progress: ProgressArg,
    stream: str | os.PathLike[str] | None,
    **extra: Any,
) -> dict[str, Any]:
    """Runs ``kernel`` (``railslosh._core.run_train``, ``run_fluid_train`` or
    ``run_equivalent_train``) on ``train`` and its cargo with a progress bar, adds the run's
    ``load_filter``, ``extra`` entries and irregularity to the results, and raises
    :class:`railslosh.slosh.SimulationError` (``what`` stopped at t = ...) on a failed run."""
    with progress_callback(progress, "vehicle run") as on_progress:
        res = dict(kernel(train, *cargo, progress=on_progress, stream=None if stream is None else os.fspath(stream)))
    res["load_filter"] = train["load_filter"]
    res.update(extra)
    if irr is not None:
        res["irregularity"] = irr
    return _raise_on_error(res, what)


def run(
    track: Any,
    *,
    irregularity: Irregularity | dict[str, Any] | None = None,
    cars: int = 1,
    station: float = 50.0,
    speed: float = 0.0,
    t_end: float = 1.0,
    step: float = 1e-3,
    record_every: float = 0.01,
    load_filter: str = "hat_mean",
    drive: bool | float = False,
    brake: tuple[Sequence[float], Sequence[float]] | None = None,
    brake_scope: str = "all",
    lading_mass: float = 0.0,
    lading_height: float = 0.0,
    wheel_profile: str = "s1002",
    wheelset_lateral_offset: float = 0.0,
    coupler_stiffness: float | None = None,
    coupler_damping: float | None = None,
    car: dict[str, float | str] | None = None,
    progress: ProgressArg = None,
    stream: str | os.PathLike[str] | None = None,
    checkpoint: str | os.PathLike[str] | None = None,
    checkpoint_every: int = 50,
    resume_from: str | os.PathLike[str] | None = None,
    friction_map: Mapping[str, Any] | None = None,
) -> dict[str, Any]:
    """Run ``cars`` coupled tank cars on ``track`` and return arrays of wheel loads ``Q``
    (``wheel_vertical``), lateral wheel forces ``Y``, ``l_over_v``, the wheel ``unloading`` ratio
    ``(Q0 - Q)/Q0``, ``coupler_force``, tank stations and speeds, and solver statistics.

    ``drive=True`` holds the front car to ``speed`` with the trajectory constraint (a number gives
    another speed); ``brake=(times, torques)`` applies that torque (N m) to every wheelset of the
    braked cars (``brake_scope`` ``"all"`` = ECP, ``"front"`` = front car only).
    ``progress=True`` shows a progress bar on stderr (:mod:`railslosh.progress`); a callable
    ``progress(t, t_end, steps, newton_iterations, rejected_steps)`` is called after the first step,
    then about every 0.5 s of wall time and at the end; if it raises, the run stops and the
    exception propagates. ``stream`` (a file path) writes every recorded sample to that file as it
    is computed (flushed per sample), so an interrupted run keeps it; read it with :func:`read_stream`.
    ``checkpoint`` (a file path) keeps the whole run's state there, replaced atomically every
    ``checkpoint_every`` recorded samples; ``resume_from`` continues a run of the same arguments from
    such a file: the results start at the checkpoint's sample and are bit for bit those of the
    uninterrupted run from there on (``rail_mbs::vehicle::checkpoint``). The same in
    :func:`run_fluid` and :func:`run_equivalent`.

    Load channels (``Q``, ``Y``, coupler and fluid forces) are recorded every ``record_every`` s as
    ``load_filter = "hat_mean"`` (default): their mean over the integrator steps weighted by the
    sample's hat function ``1 - |t - t_k|/record_every``, a zero-phase anti-aliasing low-pass
    (-3 dB at ``0.32/record_every``, 16 Hz at 0.02 s; impulses preserved), or ``"sample"``: the value
    at the recording time, which aliases contact ringing above the record's Nyquist frequency.

    ``irregularity`` (a :class:`railslosh.irregularity.Irregularity` or its samples dict) displaces
    the rails in the wheel/rail contact (``docs/frames.md``, "Track irregularities"); it must be zero
    under the train at t = 0, up to :data:`railslosh.irregularity.CLEARANCE` ahead of the leading
    wheelset (:func:`wheelset_stations`), else ``ValueError``. The result keeps it as
    ``"irregularity"`` (its ``spec`` and samples go into the results' attributes and variables).

    ``friction_map`` sets the wheel/rail friction over the rail profile and along the track
    (``rail_mbs::wheel_rail::FrictionMap``; default ``None``: ``car["friction"]`` everywhere): either
    ``{"preset": "lubricated_gauge_face", "mu_top": 0.4, "mu_gauge": 0.1, "depth": 0.002, "width":
    0.002}`` (``mu_gauge`` on the gauge face down from ``depth`` m below the rail top, blending to
    ``mu_top`` over ``width`` m; the values shown are the defaults,
    ``railslosh._core.LUBRICATED_GAUGE_FACE``, as :func:`railslosh.rail.lubricated_gauge_face`) or
    ``{"profile": [(v, mu), ...]}``
    (μ over the rail profile's lateral coordinate v, m, as :func:`railslosh.rail.contact`), each with
    an optional ``"along_track": [(s, factor), ...]`` (a factor on μ over the distance s, m). Every
    contact patch takes the μ of its own place. The same in :func:`run_fluid` and
    :func:`run_equivalent`.

    Raises ``ValueError`` naming a bad field, and :class:`railslosh.slosh.SimulationError` (with
    ``.results`` up to the failure) when the run stops early.
    """
    train, irr = _train_args(
        track,
        irregularity=irregularity,
        cars=cars,
        station=station,
        speed=speed,
        t_end=t_end,
        drive=drive,
        brake=brake,
        car=car,
        friction_map=friction_map,
        step=step,
        record_every=record_every,
        load_filter=load_filter,
        brake_scope=brake_scope,
        lading_mass=lading_mass,
        lading_height=lading_height,
        wheel_profile=wheel_profile,
        wheelset_lateral_offset=wheelset_lateral_offset,
        coupler_stiffness=coupler_stiffness,
        coupler_damping=coupler_damping,
        **_run_files(checkpoint, checkpoint_every, resume_from),
    )
    return _run_train(_core.run_train, "vehicle run", train, irr, progress=progress, stream=stream)


def design_brake_torque(
    mass: float, v0: float = 40 / 3.6, v1: float = 5 / 3.6, duration: float = 10.0
) -> tuple[list[float], list[float]]:
    """Brake torque per wheelset, ``(times, torques)``, that slows a car of total mass ``mass`` (kg,
    liquid included) from ``v0`` to ``v1`` (m/s) in ``duration`` s: ``T0 (1 - exp(-(t - 0.5)/0.5))``
    after a 0.5 s settling time (the design of seed 000 §8.2; see ``railslosh_cases::vehicle::studies``)."""
    return _core.design_brake_torque(mass, v0, v1, duration)


def run_fluid(
    track: Any,
    *,
    irregularity: Irregularity | dict[str, Any] | None = None,
    cars: int = 1,
    station: float = 300.0,
    speed: float = 0.0,
    t_end: float = 1.0,
    step: float = 4e-3,
    record_every: float = 0.02,
    load_filter: str = "hat_mean",
    snapshot_every: float = 0.0,
    drive: bool | float = False,
    brake: tuple[Sequence[float], Sequence[float]] | None = None,
    brake_scope: str = "all",
    brake_factors: Sequence[float] | None = None,
    oil: str = "light",
    fluid: Any = None,
    counts: tuple[int, int, int] = (6, 4, 2),
    fill: float = 0.5,
    bulkheads: Sequence[tuple[float, float]] | None = None,
    wheel_profile: str = "s1002",
    car: dict[str, float | str] | None = None,
    progress: ProgressArg = None,
    stream: str | os.PathLike[str] | None = None,
    checkpoint: str | os.PathLike[str] | None = None,
    checkpoint_every: int = 50,
    resume_from: str | os.PathLike[str] | None = None,
    friction_map: Mapping[str, Any] | None = None,
    wall_damping_ratio: float = WALL_DAMPING_RATIO,
    wall_adhesion: float = 0.0,
    shear_stabilization: bool = True,
) -> dict[str, Any]:
    """Run tank cars whose tanks carry an ANCF fluid, solved monolithically with the cars.

    ``oil`` is ``"light"``, ``"medium"``, ``"heavy"`` (seed 000 Table 2, Oldroyd) or ``"water"``;
    ``fluid`` (a :class:`railslosh.Fluid`, e.g. from :mod:`railslosh.fluids`) overrides it.
    ``counts`` = fluid elements along the length, width and height; ``bulkheads`` = ``[(x, thickness)]``
    in the tank frame (m). Returns the arrays of :func:`run` plus ``oil_com_tank`` and ``oil_com_global``
    (samples, cars, 3), ``fluid_force_tank`` (the fluid's load on each tank, tank frame), ``volume_error``,
    the run-time invariants per car and sample (``containment_gap`` in m, ``min_volume_ratio``,
    ``energy_error``; worst values in ``margins``) and ``snapshots`` (``[(t, [nodes x 4 x 3 per
    car])]``, position then gradients per node).
    ``progress``, ``stream`` and ``irregularity`` work as in :func:`run`. ``wall_damping_ratio`` (0 to
    10, default :data:`WALL_DAMPING_RATIO`) is the damping ratio of the liquid column on the penalty
    wall spring: 1 (critical) removes most of the 20-30 Hz wall ringing from the loads after a wave
    hits a head, at about 1.35x the run time (docs/validation.md, "Wall damping"). ``wall_adhesion``
    (0 to 50, default 0: a unilateral wall) is the suction the tank wall holds on the wetted liquid,
    in units of the hydrostatic pressure at the bottom ρ g H (docs/validation.md, "Wall peeling";
    :func:`railslosh.slosh.run`). ``shear_stabilization`` (default true, as in scenes) gives a fluid
    without its own the recommended zero-energy-mode control
    (:func:`railslosh.fluids.default_shear_stabilization` for the element height), which makes the
    liquid's rest state stable (docs/validation.md, "A stable rest state"); false runs the bare
    discretization, whose rest state has growing modes on the car meshes.
    ``fill`` is the liquid volume fraction, :data:`railslosh.limits.FILL` (0.03 to 0.97, as in scenes).
    """
    fill = limits.check("fill", fill)
    wall_damping_ratio = limits.check("wall_damping_ratio", wall_damping_ratio)
    wall_adhesion = limits.check("wall_adhesion", wall_adhesion)
    train, irr = _train_args(
        track,
        irregularity=irregularity,
        cars=cars,
        station=station,
        speed=speed,
        t_end=t_end,
        drive=drive,
        brake=brake,
        brake_factors=brake_factors,
        car=car,
        friction_map=friction_map,
        step=step,
        record_every=record_every,
        load_filter=load_filter,
        snapshot_every=snapshot_every,
        brake_scope=brake_scope,
        wheel_profile=wheel_profile,
        **_run_files(checkpoint, checkpoint_every, resume_from),
    )
    cargo = FluidCargoArgs(
        oil=oil,
        fluid=fluid,
        counts=tuple(counts),
        fill=fill,
        bulkheads=_bulkheads(bulkheads),
        wall_damping_ratio=wall_damping_ratio,
        wall_adhesion=wall_adhesion,
        shear_stabilization=bool(shear_stabilization),
    )
    return _run_train(
        _core.run_fluid_train,
        "fluid vehicle run",
        train,
        irr,
        cargo,
        progress=progress,
        stream=stream,
        wall_damping_ratio=wall_damping_ratio,
        wall_adhesion=wall_adhesion,
        shear_stabilization=bool(shear_stabilization),
    )


SLOSH_AXES = ("longitudinal", "lateral")
"""Directions the equivalent slosh model can represent (one per run)."""


def equivalent_model(
    fill: float = 0.5,
    *,
    oil: str = "light",
    fluid: Any = None,
    bulkheads: Sequence[tuple[float, float]] | None = None,
    slosh_axis: str = "longitudinal",
    car: dict[str, float | str] | None = None,
) -> dict[str, Any]:
    """The equivalent spring-mass / pendulum model of one car's liquid (``rail_mbs::vehicle::equivalent``):
    liquid ``mass``, ``depth``, ``depth_fraction``, ``lambda``, rest ``centroid`` (tank frame) and one
    entry of ``modes`` per compartment (``mass`` m1, ``fixed_mass`` m0, ``omega``, ``frequency``,
    ``damping_ratio``, ``position``, ``pendulum_length``, ``compartment_length``). ``fill`` is the liquid
    volume fraction, as in :func:`run_fluid`."""
    fill = limits.check("fill", fill)
    return dict(
        _core.equivalent_model(
            fill,
            oil=oil,
            fluid=fluid,
            bulkheads=_bulkheads(bulkheads),
            slosh_axis=slosh_axis,
            car=car,
        )
    )


def run_equivalent(
    track: Any,
    *,
    irregularity: Irregularity | dict[str, Any] | None = None,
    cars: int = 1,
    station: float = 300.0,
    speed: float = 0.0,
    t_end: float = 1.0,
    step: float = 4e-3,
    record_every: float = 0.02,
    load_filter: str = "hat_mean",
    drive: bool | float = False,
    brake: tuple[Sequence[float], Sequence[float]] | None = None,
    brake_scope: str = "all",
    brake_factors: Sequence[float] | None = None,
    oil: str = "light",
    fluid: Any = None,
    fill: float = 0.5,
    bulkheads: Sequence[tuple[float, float]] | None = None,
    slosh_axis: str = "longitudinal",
    lading_mass: float = 0.0,
    lading_height: float = 0.0,
    wheel_profile: str = "s1002",
    car: dict[str, float | str] | None = None,
    progress: ProgressArg = None,
    stream: str | os.PathLike[str] | None = None,
    checkpoint: str | os.PathLike[str] | None = None,
    checkpoint_every: int = 50,
    resume_from: str | os.PathLike[str] | None = None,
    friction_map: Mapping[str, Any] | None = None,
) -> dict[str, Any]:
    """Run tank cars whose liquid is its equivalent mechanical model: per compartment one slosh mass
    on a spring (``slosh_axis = "longitudinal"``, braking) or one pendulum hinged on the tank axis
    (``"lateral"``, curving), the rest of the liquid carried rigidly (see :func:`equivalent_model`).
    Arguments as :func:`run_fluid` (``irregularity`` as :func:`run`; ``fill`` is the volume fraction;
    ``fluid`` gives density and plastic viscosity, yield stresses are ignored). Returns the arrays of
    :func:`run` plus ``oil_com_tank`` (samples, cars, 3; liquid centre of mass in the tank frame, as
    :func:`run_fluid`),
    ``slosh_displacement`` (samples, cars, modes; m, along the slosh axis), ``fluid_mass`` and
    ``equivalent_model``."""
    if slosh_axis not in SLOSH_AXES:
        raise ValueError(f"invalid `slosh_axis` = {slosh_axis!r}: expected one of {', '.join(SLOSH_AXES)}")
    fill = limits.check("fill", fill)
    train, irr = _train_args(
        track,
        irregularity=irregularity,
        cars=cars,
        station=station,
        speed=speed,
        t_end=t_end,
        drive=drive,
        brake=brake,
        brake_factors=brake_factors,
        car=car,
        friction_map=friction_map,
        step=step,
        record_every=record_every,
        load_filter=load_filter,
        brake_scope=brake_scope,
        lading_mass=lading_mass,
        lading_height=lading_height,
        wheel_profile=wheel_profile,
        **_run_files(checkpoint, checkpoint_every, resume_from),
    )
    cargo = EquivalentCargoArgs(
        oil=oil,
        fluid=fluid,
        fill=fill,
        bulkheads=_bulkheads(bulkheads),
        slosh_axis=slosh_axis,
    )
    return _run_train(
        _core.run_equivalent_train, "equivalent-slosh vehicle run", train, irr, cargo, progress=progress, stream=stream
    )


def read_stream(path: str | os.PathLike[str]) -> dict[str, Any]:
    """The samples of a :func:`run`, :func:`run_fluid` or :func:`run_equivalent` ``stream`` file (also of an interrupted
    run: every complete sample), as arrays shaped like the run's results: ``t``,
    ``wheel_vertical`` and ``wheel_lateral`` (samples, wheelsets, [left, right]),
    ``wheelset_lateral``, ``coupler_force``, ``tank_station``, ``tank_speed`` and, for fluid runs,
    ``oil_com_tank``, ``fluid_force_tank`` (samples, cars, 3), ``volume_error``, ``containment_gap``,
    ``min_volume_ratio`` and ``energy_error`` (samples, cars)."""
    import re

    from railslosh.journal import read_journal

    col = read_journal(path, "vehicle stream")
    out: dict[str, Any] = {"t": col.pop("t")}
    groups: dict[str, dict[tuple[int, int], np.ndarray]] = {}
    pattern = re.compile(r"^(\w+)\[(\d+)\](?:\.(left|right|x|y|z))?$")
    comp = {None: 0, "left": 0, "right": 1, "x": 0, "y": 1, "z": 2}
    width: dict[str, int] = {}
    for name, values in col.items():
        m = pattern.match(name)
        if m is None:
            raise ValueError(f"invalid `path` = {os.fspath(path)!r}: unknown column {name!r}")
        key, i, c = m.group(1), int(m.group(2)), m.group(3)
        groups.setdefault(key, {})[(i, comp[c])] = values
        width[key] = 0 if c is None else max(width.get(key, 0), comp[c] + 1)
    for key, cells in groups.items():
        n = max(i for i, _ in cells) + 1
        w = width[key]
        arr = np.zeros((len(out["t"]), n, max(w, 1)))
        for (i, c), v in cells.items():
            arr[:, i, c] = v
        out[key] = arr[:, :, 0] if w == 0 else arr
    return out
