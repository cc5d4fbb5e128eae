"""Type stubs of the Rust extension module ``railslosh._core``."""

from typing import Any

import numpy as np
import numpy.typing as npt

__version__: str

class RailsloshError(Exception):
    """Base class of railslosh simulation errors."""

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

class Fluid:
    """A fluid: density, rheology and penalty parameters (validated on construction)."""

    def __init__(
        self,
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
    ) -> None: ...
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
    def elastic_modulus(self) -> float: ...

class FluidBody:
    """A meshed fluid body: reference data, constant mass matrix, forces and Jacobians."""

    def __init__(
        self,
        mesh: FluidMesh,
        fluid: Fluid,
        viscous_points: int = 3,
        penalty_points: int = 3,
        mass_points: int = 4,
    ) -> None: ...
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
    tank_shape: str,
    tank_dims: list[float],
    bulkheads: list[tuple[float, float]],
    acceleration: list[list[tuple[float, float]]],
    rotation_axis: tuple[float, float, float] | None,
    angular_acceleration: list[tuple[float, float]],
    t_end: float,
    h: float,
    frame: str = "inertial",
    gravity: list[float] = ...,
    viscous_points: int = 3,
    penalty_points: int = 3,
) -> dict[str, Any]: ...
def run_validation(name: str, quick: bool = False) -> list[dict[str, Any]]: ...
def _panic_for_test() -> None: ...
