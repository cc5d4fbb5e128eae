"""The one argument of each run kernel of :mod:`railslosh._core`, as typed dicts (issue 18).

The vehicle runs take a ``train`` (:class:`TrainArgs`) and a cargo (:class:`FluidCargoArgs`,
:class:`EquivalentCargoArgs`); the slosh run takes a ``scenario`` (:class:`SloshArgs`). The binding
reads each dict key by key (``crates/railslosh-py/src/args.rs``): a key left out or ``None`` takes
the Rust scenario's default, a value of the wrong type is a ``TypeError`` naming its key, an unknown
key a ``ValueError``. These classes are defined here once, at run time, and the stub of
``railslosh._core`` imports them; ``tests/test_errors.py`` checks that each lists exactly the keys
the binding reads. :func:`railslosh.vehicle.run` and :func:`railslosh.slosh.run` build them from
their keyword arguments; scripts may build them directly for the ``_core`` kernels.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, TypedDict

if TYPE_CHECKING:
    from railslosh._core import Fluid

__all__ = ["EquivalentCargoArgs", "FluidCargoArgs", "SloshArgs", "TrainArgs"]


class _TrainRequired(TypedDict):
    track: list[list[float]]
    station: float
    speed: float
    t_end: float


class TrainArgs(_TrainRequired, total=False):
    """The train of a vehicle run (``railslosh.vehicle._train_args`` builds it); a key left out or
    ``None`` takes ``rail_mbs::vehicle::TrainScenario``'s default; an unknown key is a ValueError."""

    irregularity: dict[str, Any] | None
    cars: int
    step: float
    record_every: float
    load_filter: str
    snapshot_every: float
    drive_speed: float | None
    brake_times: list[float] | None
    brake_torques: list[float] | None
    brake_scope: str
    brake_factors: list[float] | None
    wheel_profile: str
    wheelset_lateral_offset: float
    coupler_stiffness: float | None
    coupler_damping: float | None
    car: dict[str, float | str] | None
    friction_map: dict[str, Any] | None
    lading_mass: float
    lading_height: float
    checkpoint: str | None
    checkpoint_every: int | None
    resume_from: str | None


class _FillRequired(TypedDict):
    fill: float


class FluidCargoArgs(_FillRequired, total=False):
    """The ANCF cargo of ``run_fluid_train``; keys left out take ``FluidCargo::new``'s defaults."""

    oil: str
    fluid: Fluid | None
    counts: tuple[int, int, int]
    bulkheads: list[tuple[float, float]] | None
    wall_damping_ratio: float
    wall_adhesion: float
    shear_stabilization: bool


class EquivalentCargoArgs(_FillRequired, total=False):
    """The equivalent-model cargo of ``run_equivalent_train``."""

    oil: str
    fluid: Fluid | None
    bulkheads: list[tuple[float, float]] | None
    slosh_axis: str


class _SloshRequired(TypedDict):
    tank_shape: str
    tank_dims: list[float]
    t_end: float
    step: float


class SloshArgs(_SloshRequired, total=False):
    """The scenario of ``run_slosh`` (``railslosh.slosh.run`` builds it); a key left out or ``None``
    takes ``rail_mbs::slosh::SloshScenario::new``'s default; an unknown key is a ValueError."""

    bulkheads: list[tuple[float, float]]
    acceleration: list[list[tuple[float, float]]]
    rotation_axis: tuple[float, float, float] | None
    angular_acceleration: list[tuple[float, float]]
    frame: str
    gravity: list[float]
    viscous_points: int
    penalty_points: int
    volume_tolerance: float
    penetration_limit: float
    contact_stiffness_factor: float
    contact_points_per_edge: int
    contact_point_rule: str
    stepper: str
    wall_damping_ratio: float
    snapshot_every: float
    wall_adhesion: float
