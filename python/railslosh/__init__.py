"""railslosh: liquid sloshing in rail tank cars, coupled with vehicle multibody dynamics.

The numerical kernels are Rust (``railslosh._core``); this package holds model setup,
analysis and the ``railslosh`` command-line tool. Units are SI throughout; frames and sign
conventions are defined in ``docs/frames.md``.
"""

from railslosh import _core, constants, fluids, irregularity, limits, mesh, rail, scene, slosh, vehicle
from railslosh._core import (
    Fluid,
    FluidBody,
    FluidMesh,
    RailsloshError,
    __version__,
)
from railslosh.body import mass_matrix

# a wrongly typed argument of a compiled function names the argument (PyO3 names it in a note only)
limits.name_native_arguments(_core)

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
