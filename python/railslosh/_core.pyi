"""Type stubs of the Rust extension module ``railslosh._core``."""

import os
from collections.abc import Callable, Mapping, Sequence
from typing import Any, final

import numpy as np
import numpy.typing as npt

from railslosh.kernel_args import EquivalentCargoArgs, FluidCargoArgs, SloshArgs, TrainArgs

__version__: str

_Progress = Callable[[float, float, int, int, int], object]
"""Progress callback of the runs: ``(t, t_end, steps, newton_iterations, rejected_steps)``."""

WALL_DAMPING_RATIO: float
LUBRICATED_GAUGE_FACE: dict[str, float]
GRAVITY: float
TANK_HEAD_DEPTH: float
TANK_CAR_LENGTH: float
TANK_CAR_RADIUS: float
FOOT: float
INCH: float
MPH: float
ARC_DEGREE_RADIUS_FT: float

class RailsloshError(Exception):
    """Base class of railslosh simulation errors."""

class DataNotFoundError(RailsloshError):
    """External reference data (e.g. the Manchester contact benchmark) were not found; the case is skipped."""

@final
class FluidMesh:
    """A structured ANCF fluid mesh (reference configuration, tank frame)."""

    @property
    def nodes(self) -> npt.NDArray[np.float64]: ...
    @property
    def connectivity(self) -> npt.NDArray[np.int64]: ...
    @property
    def element_lengths(self) -> npt.NDArray[np.float64]: ...
    @property
    def boundary(self) -> list[tuple[int, str, str]]: ...
    @property
    def n_nodes(self) -> int: ...
    @property
    def n_elements(self) -> int: ...
    @property
    def n_coords(self) -> int: ...
    @property
    def counts(self) -> tuple[int, int, int]: ...
    @property
    def exact_volume(self) -> float: ...
    @property
    def free_surface_z(self) -> float: ...
    @property
    def kind(self) -> str: ...

@final
class Fluid:
    """A fluid: density, rheology and penalty parameters (validated on construction)."""

    def __new__(
        cls,
        density: float,
        model: str,
        *,
        viscosity: float = 0.0,
        yield_stress: float = 0.0,
        consistency: float | None = None,
        power_index: float = 1.0,
        elastic_modulus: float | None = None,
        bulk_penalty: float,
        bulk_damping: float = 0.0,
        shear_rate_reg: float = 1e-2,
        shear_stabilization: float = 0.0,
        hourglass_stabilization: float = 0.0,
    ) -> Fluid: ...
    @property
    def density(self) -> float: ...
    @property
    def model(self) -> str: ...
    @property
    def yield_stress(self) -> float: ...
    @property
    def bulk_penalty(self) -> float: ...
    @property
    def bulk_damping(self) -> float: ...
    @property
    def shear_stabilization(self) -> float: ...
    @property
    def hourglass_stabilization(self) -> float: ...
    @property
    def elastic_modulus(self) -> float: ...

@final
class FluidBody:
    """A meshed fluid body: reference data, constant mass matrix, forces and Jacobians."""

    def __new__(
        cls,
        mesh: FluidMesh,
        fluid: Fluid,
        viscous_points: int = 3,
        penalty_points: int = 3,
        mass_points: int = 4,
    ) -> FluidBody: ...
    @property
    def n_coords(self) -> int: ...
    @property
    def total_mass(self) -> float: ...
    @property
    def reference_volume(self) -> float: ...
    @property
    def mesh(self) -> FluidMesh: ...
    @property
    def fluid(self) -> Fluid: ...
    def reference_coordinates(self) -> npt.NDArray[np.float64]: ...
    def scalar_mass_csc(
        self,
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int64], npt.NDArray[np.int64], tuple[int, int]]: ...
    def gravity_force(self, g: tuple[float, float, float] | list[float]) -> npt.NDArray[np.float64]: ...
    def internal_forces(self, e: npt.NDArray[np.float64], edot: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
    def element_tangent(
        self, index: int, e: npt.NDArray[np.float64], edot: npt.NDArray[np.float64]
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    def element_dofs(self, index: int) -> list[int]: ...
    def volume(self, e: npt.NDArray[np.float64]) -> float: ...
    def center_of_mass(self, e: npt.NDArray[np.float64]) -> tuple[float, float, float]: ...
    def kinetic_energy(self, edot: npt.NDArray[np.float64]) -> float: ...

def crude_oils() -> list[tuple[str, tuple[float, float, float]]]: ...
def nadal_limit(contact_angle: float, friction: float) -> float: ...
def default_bulk_penalty(density: float, depth: float, strain: float = ...) -> float: ...
def default_bulk_damping(bulk_penalty: float, density: float, element_height: float) -> float: ...
def default_shear_stabilization(density: float, element_height: float, heads_depth: float | None = None) -> float: ...
def box_mesh(
    origin: tuple[float, float, float], size: tuple[float, float, float], counts: tuple[int, int, int]
) -> FluidMesh: ...
def cylinder_tank(
    length: float,
    radius: float,
    head_depth: float,
    fill: float,
    n_length: int,
    n_width: int,
    n_height: int,
    grading: float = 1.0,
) -> FluidMesh: ...
def elliptic_cylinder(
    length: float,
    semi_axis_y: float,
    semi_axis_z: float,
    fill: float,
    n_length: int,
    n_width: int,
    n_height: int,
) -> FluidMesh: ...
def validation_cases() -> list[str]: ...
def run_slosh(
    mesh: FluidMesh,
    fluid: Fluid,
    scenario: SloshArgs,
    *,
    progress: _Progress | None = None,
    stream: str | os.PathLike[str] | None = None,
    checkpoint: str | os.PathLike[str] | None = None,
    checkpoint_every: int = 100,
    resume_from: str | os.PathLike[str] | None = None,
) -> dict[str, Any]: ...
def run_validation(name: str, quick: bool = False) -> list[dict[str, Any]]: ...
def work_precision_cases() -> list[str]: ...
def run_work_precision(case: str, quick: bool = False) -> list[dict[str, Any]]: ...
def _panic_for_test() -> None: ...

_F64 = npt.NDArray[np.float64]

@final
class Track:
    """Track geometry from a segment table (columns of equal length; see railslosh.rail.Track)."""

    def __new__(
        cls,
        s: _F64,
        curvature: _F64,
        superelevation: _F64,
        grade: _F64,
        cant_right: _F64,
        cant_left: _F64,
        *,
        units: str = "si",
        gauge: float = ...,  # 1.435 m
        cant_base: float = ...,  # 1.5 m
        origin: tuple[float, float, float] = ...,  # (0, 0, 0)
        heading: float = 0.0,
    ) -> Track: ...
    @property
    def gauge(self) -> float: ...
    @property
    def cant_base(self) -> float: ...
    @property
    def range(self) -> tuple[float, float]: ...
    @property
    def table(self) -> _F64: ...
    @property
    def units(self) -> str: ...
    def position(self, s: _F64) -> _F64: ...
    def tangent(self, s: _F64) -> _F64: ...
    def frame(self, s: _F64) -> tuple[_F64, _F64]: ...
    def curvature(self, s: _F64) -> _F64: ...
    def superelevation(self, s: _F64) -> _F64: ...
    def grade(self, s: _F64) -> _F64: ...
    def heading(self, s: _F64) -> _F64: ...
    def bank_angle(self, s: _F64) -> _F64: ...
    def balance_speed(self, s: _F64) -> _F64: ...
    def rail_point(self, s: _F64, side: str) -> _F64: ...
    def rail_inward_cant(self, s: _F64, side: str) -> _F64: ...
    def project(self, points: _F64) -> tuple[_F64, _F64, _F64]: ...

@final
class Profile:
    """A wheel or rail profile z(y) (m; y towards the field side, z up)."""

    @staticmethod
    def s1002(spacing: float = 2e-4) -> Profile: ...
    @staticmethod
    def uic60(spacing: float = 2e-4) -> Profile: ...
    @staticmethod
    def aar1b_approx() -> Profile: ...
    @staticmethod
    def from_simpack(path: str | os.PathLike[str]) -> Profile: ...
    @staticmethod
    def from_points(y: _F64, z: _F64, name: str = "points", kind: str | None = None) -> Profile: ...
    @staticmethod
    def from_two_column(
        path: str | os.PathLike[str],
        *,
        scale: float = 1.0,
        z_down: bool = False,
        mirror_y: bool = False,
        kind: str | None = None,
    ) -> Profile: ...
    @property
    def name(self) -> str: ...
    @property
    def kind(self) -> str | None: ...
    @property
    def y_range(self) -> tuple[float, float]: ...
    @property
    def knots(self) -> _F64: ...
    def highest_point(self) -> tuple[float, float]: ...
    def sample(self, n: int) -> _F64: ...
    def eval(self, y: _F64) -> tuple[_F64, _F64, _F64]: ...
    def trim_steep_ends(self, max_slope: float) -> Profile: ...

def lubricated_gauge_face(
    rail: Profile, *, mu_top: float = ..., mu_gauge: float = ..., depth: float = ..., width: float = ...
) -> list[tuple[float, float]]: ...
def wheel_rail_contact(
    wheel: Profile,
    rail: Profile,
    *,
    side: str = "left",
    nominal_radius: float = 0.46,
    wheel_offset: float = 0.75,
    rail_offset: float | None = None,
    gauge: float = 1.435,
    gauge_depth: float = 0.014,
    rail_cant: float = 0.0,
    trim_slope: float | None = None,
    lateral_shift: float = 0.0,
    yaw: float = 0.0,
    roll: float = 0.0,
    load: float | None = None,
    penetration: float | None = None,
    speed: float = 0.0,
    lateral_velocity: float = 0.0,
    yaw_rate: float = 0.0,
    axle_rate: float | None = None,
    creepages: tuple[float, float, float] | None = None,
    creep_model: str = "shen-hedrick-elkins",
    creep_parameters: dict[str, float] | None = None,
    friction: float = 0.3,
    friction_profile: list[tuple[float, float]] | None = None,
    young: float = 2.1e11,
    poisson: float = 0.3,
    scan_points: int = 400,
    patch_model: str = "hertz",
    kp_epsilon: float | None = None,
    kp_strips: int | None = None,
    patch_combination: str = "separate",
    a_sep: float | None = None,
    d_sep: float | None = None,
    d_comb: float | None = None,
) -> dict[str, Any]: ...

# --- vehicle (crates/railslosh-py/src/vehicle.rs) ---

def tank_car_parameters(car: dict[str, float | str] | None = None, wheel_profile: str = "s1002") -> dict[str, Any]: ...
def wheelset_stations(
    cars: int = 1, station: float = 50.0, car: dict[str, float | str] | None = None
) -> list[float]: ...
def track_irregularity(
    kind: str,
    length: float,
    *,
    track_class: int | None = None,
    start: float = 0.0,
    step: float = 0.25,
    wavelengths: tuple[float, float] = ...,
    seed: int = 1,
    taper: float = 20.0,
    channels: list[str] | None = None,
) -> dict[str, Any]: ...
def track_irregularity_defects(
    defects: list[dict[str, Any]],
    *,
    samples: dict[str, Any] | None = None,
    start: float = 0.0,
    end: float | None = None,
    step: float = 0.05,
) -> dict[str, Any]: ...
def track_psd(
    kind: str, channel_name: str, omega: npt.NDArray[np.float64], *, track_class: int | None = None
) -> npt.NDArray[np.float64]: ...
def run_train(train: TrainArgs, *, progress: _Progress | None = None, stream: str | None = None) -> dict[str, Any]: ...
def design_brake_torque(
    mass: float, v0: float = ..., v1: float = ..., duration: float = 10.0
) -> tuple[list[float], list[float]]: ...
def run_fluid_train(
    train: TrainArgs, cargo: FluidCargoArgs, *, progress: _Progress | None = None, stream: str | None = None
) -> dict[str, Any]: ...
def run_equivalent_train(
    train: TrainArgs, cargo: EquivalentCargoArgs, *, progress: _Progress | None = None, stream: str | None = None
) -> dict[str, Any]: ...
def equivalent_model(
    fill: float = 0.5,
    *,
    oil: str = "light",
    fluid: Fluid | None = None,
    bulkheads: list[tuple[float, float]] | None = None,
    slosh_axis: str = "longitudinal",
    car: dict[str, float | str] | None = None,
) -> dict[str, Any]: ...
def hat_mean_resample(t: Sequence[float], values: Sequence[Sequence[float]], dt: float) -> npt.NDArray[np.float64]: ...
def equivalent_lambda(depth_fraction: float) -> float: ...
def braking_step(brake_scope: str, oil: str) -> float: ...

# --- co-simulation: the slosh participant (rail_mbs::cosim, issue 6) ---

_Vec3 = npt.ArrayLike
_TankInput = dict[str, Any]
"""Tank motion at one coupling time. Tank-frame form (seed 003, tank axes): keys
``acceleration``, ``angular_velocity``, ``angular_acceleration``, ``gravity`` (missing: zero,
gravity (0, 0, -g)). Pose form (global axes), recognised by ``rotation`` (3x3, tank -> global)
or ``quaternion`` ([w, x, y, z]): keys ``position``, ``rotation``/``quaternion``, ``velocity``,
``angular_velocity``, ``acceleration``, ``angular_acceleration`` (missing vectors: zero)."""

@final
class SloshParticipantState:
    """Opaque saved state of a SloshParticipant (exact rollback)."""

    @property
    def time(self) -> float: ...
    def to_bytes(self) -> bytes: ...
    @staticmethod
    def from_bytes(data: bytes) -> SloshParticipantState: ...

@final
class SloshParticipant:
    """The slosh model as a co-simulation participant: loads are the force and moment of the
    fluid on the tank, tank axes, moment about ``reference_point`` (tank frame)."""

    def __new__(
        cls,
        mesh: FluidMesh,
        fluid: Fluid,
        tank_shape: str,
        tank_dims: list[float],
        bulkheads: list[tuple[float, float]] = ...,
        h_max: float = 0.005,
        reference_point: tuple[float, float, float] | list[float] = ...,
        gravity: float = ...,
        t0: float = 0.0,
        viscous_points: int = 3,
        penalty_points: int = 3,
    ) -> SloshParticipant: ...
    def advance(
        self, t_end: float, input_start: _TankInput, input_end: _TankInput
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    def set_initial_input(self, input: _TankInput) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    def settle(self, duration: float, input: _TankInput) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    def save_state(self) -> SloshParticipantState: ...
    def restore_state(self, state: SloshParticipantState) -> None: ...
    def added_mass(self) -> npt.NDArray[np.float64]: ...
    def loads(self) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    @property
    def time(self) -> float: ...
    @property
    def fluid_mass(self) -> float: ...
    @property
    def com_tank(self) -> npt.NDArray[np.float64]: ...
    @property
    def volume(self) -> float: ...
    @property
    def reference_point(self) -> npt.NDArray[np.float64]: ...
    @property
    def gravity(self) -> float: ...
    @property
    def h_max(self) -> float: ...
    @property
    def margins(self) -> dict[str, Any]: ...
    @property
    def stats(self) -> dict[str, Any]: ...

def seed003_maneuvers(
    dt: float = 0.005, t_after: float = 2.0, gravity: float = ..., t_before: float = 0.5
) -> list[dict[str, Any]]: ...
def maneuver_defaults() -> dict[str, dict[str, float]]: ...
def maneuver_motion(spec: Mapping[str, Any], t0: float, t_end: float, dt: float = 1e-3) -> dict[str, Any]: ...
