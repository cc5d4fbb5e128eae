"""Fluid sloshing in a rigid tank with prescribed motion.

    >>> import railslosh as rs
    >>> mesh = rs.mesh.box((0.416, 0.324, 0.132), (3, 6, 2))
    >>> tank = rs.slosh.box_tank((-0.208, -0.162, 0.0), (0.208, 0.162, 0.3))
    >>> motion = rs.slosh.Motion().pulse("y", 0.3 * 9.81, 0.0, 0.5)
    >>> res = rs.slosh.run(mesh, rs.fluids.water(depth=0.132), tank, motion, t_end=2.0, h=0.004)
    >>> res["force_tank"].shape  # (steps + 1, 3): load of the fluid on the tank, tank axes

Loads are the force and moment the fluid exerts on the tank (through wall and bulkhead
contact), moments about the tank origin, in tank and global axes (see docs/frames.md).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from railslosh import _core
from railslosh._core import Fluid, FluidMesh, RailsloshError

AXES = {"x": 0, "y": 1, "z": 2}


@dataclass(frozen=True)
class Tank:
    """Rigid tank geometry in the tank frame, with optional bulkheads (x, thickness)."""

    shape: str
    dims: tuple[float, ...]
    bulkheads: tuple[tuple[float, float], ...] = ()


def cylinder_tank(length: float, radius: float, head_depth: float, bulkheads=()) -> Tank:
    """Horizontal cylinder (axis x, centred) with half-ellipsoidal heads of depth `head_depth`."""
    return Tank("cylinder", (length, radius, head_depth), tuple(bulkheads))


def elliptic_tank(length: float, semi_axis_y: float, semi_axis_z: float) -> Tank:
    """Flat-ended cylinder of elliptical section (the SwRI tank of seed 003)."""
    return Tank("elliptic", (length, semi_axis_y, semi_axis_z))


def box_tank(lower: tuple[float, float, float], upper: tuple[float, float, float]) -> Tank:
    """Closed rectangular box between two corners."""
    return Tank("box", (*lower, *upper))


@dataclass
class Motion:
    """Prescribed tank motion: piecewise-linear translational acceleration per global axis
    (samples (t, a), integrated exactly), and rotation about a fixed axis with a
    piecewise-linear angular acceleration."""

    acceleration: dict[str, list[tuple[float, float]]] = field(default_factory=dict)
    rotation_axis: tuple[float, float, float] | None = None
    angular_acceleration: list[tuple[float, float]] = field(default_factory=list)

    def pulse(self, axis: str, accel: float, t0: float, t1: float, ramp: float = 0.01) -> Motion:
        """Add a rectangular acceleration pulse (m/s^2) on [t0, t1] with linear ramps."""
        if axis not in AXES:
            raise ValueError(f"invalid parameter `axis` = {axis!r}: allowed one of x, y, z")
        if not (t1 > t0 + 2 * ramp and ramp > 0):
            raise ValueError(f"invalid parameter `pulse` = [{t0}, {t1}] ramp {ramp}: allowed t1 > t0 + 2 ramp > t0")
        self.acceleration[axis] = [(t0, 0.0), (t0 + ramp, accel), (t1 - ramp, accel), (t1, 0.0)]
        return self


class SimulationError(RailsloshError):
    """A run stopped early; `.results` holds everything computed before the failure."""

    def __init__(self, message: str, results: dict):
        super().__init__(message)
        self.results = results


def run(
    mesh: FluidMesh,
    fluid: Fluid,
    tank: Tank,
    motion: Motion | None = None,
    *,
    t_end: float,
    h: float = 0.01,
    frame: str = "inertial",
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.81),
) -> dict:
    """Integrate the fluid in the moving tank up to `t_end` with steps of at most `h`.

    `frame="inertial"` moves the walls; `frame="tank"` solves in the tank frame with the
    pseudo-forces of seed 003 (appendix C, eq. 7.40). Returns a dict of numpy arrays
    (see ``railslosh._core.run_slosh``) and the integrator statistics under ``stats``.
    Raises :class:`SimulationError` (with ``.results``) if the run stops early.
    """
    motion = motion or Motion()
    unknown = set(motion.acceleration) - set(AXES)
    if unknown:
        raise ValueError(f"invalid parameter `motion.acceleration` axes {sorted(unknown)}: allowed x, y, z")
    acc = [motion.acceleration.get(a, []) for a in ("x", "y", "z")]
    res = _core.run_slosh(
        mesh,
        fluid,
        tank.shape,
        list(tank.dims),
        list(tank.bulkheads),
        acc,
        motion.rotation_axis,
        motion.angular_acceleration,
        t_end,
        h,
        frame,
        list(gravity),
    )
    if res["error"] is not None:
        raise SimulationError(f"slosh run stopped at t = {res['t'][-1]:.4f} s: {res['error']}", res)
    return res
