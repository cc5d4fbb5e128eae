"""railslosh: liquid sloshing in rail tank cars, coupled with vehicle multibody dynamics.

The numerical kernels are Rust (``railslosh._core``); this package holds model setup,
analysis and the ``railslosh`` command-line tool. Units are SI throughout; frames and sign
conventions are defined in ``docs/frames.md``.
"""

from railslosh import constants, fluids, irregularity, mesh, rail, scene, slosh, vehicle
from railslosh._core import (
    Fluid,
    FluidBody,
    FluidMesh,
    RailsloshError,
    __version__,
)
from railslosh.body import mass_matrix

__all__ = [
    "Fluid",
    "FluidBody",
    "FluidMesh",
    "RailsloshError",
    "__version__",
    "constants",
    "fluids",
    "irregularity",
    "mass_matrix",
    "mesh",
    "rail",
    "scene",
    "slosh",
    "vehicle",
]
