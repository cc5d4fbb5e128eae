"""Fluid sloshing in a rigid tank with prescribed motion.

    >>> import railslosh as rs
    >>> mesh = rs.mesh.box((0.416, 0.324, 0.132), (3, 6, 2))
    >>> tank = rs.slosh.TankGeometry.box((-0.208, -0.162, 0.0), (0.208, 0.162, 0.3))
    >>> motion = rs.slosh.Motion().pulse("y", 0.3 * rs.constants.GRAVITY, 0.0, 0.5)
    >>> res = rs.slosh.run(mesh, rs.fluids.water(depth=0.132), tank, motion, t_end=2.0, step=0.004,
    ...                    viscous_points=4, penalty_points=4, contact_points_per_edge=4,
    ...                    wall_damping_ratio=1.0, wall_adhesion=4.0)  # clean loads (README)
    >>> res["force_tank"].shape  # (steps + 1, 3): load of the fluid on the tank, tank axes

Loads are the force and moment the fluid exerts on the tank (through wall and bulkhead
contact), moments about the tank origin, in tank and global axes (see docs/frames.md).
"""

from __future__ import annotations

import os
import re
import warnings
from dataclasses import dataclass, field

from railslosh import _core, limits
from railslosh._core import Fluid, FluidMesh, RailsloshError
from railslosh.constants import GRAVITY
from railslosh.kernel_args import SloshArgs
from railslosh.progress import ProgressArg
from railslosh.progress import callback as progress_callback

AXES = {"x": 0, "y": 1, "z": 2}


@dataclass(frozen=True)
class TankGeometry:
    """Rigid tank geometry in the tank frame, with optional bulkheads (x, thickness): the
    Python form of ``ancf_core::tank::TankGeometry``. Build it with :meth:`cylinder`,
    :meth:`elliptic` or :meth:`box`."""

    shape: str
    dims: tuple[float, ...]
    bulkheads: tuple[tuple[float, float], ...] = ()

    @classmethod
    def cylinder(cls, length: float, radius: float, head_depth: float, bulkheads=()) -> TankGeometry:
        """Horizontal cylinder (axis x, centred) with half-ellipsoidal heads of depth `head_depth`."""
        return cls("cylinder", (length, radius, head_depth), tuple(bulkheads))

    @classmethod
    def elliptic(cls, length: float, semi_axis_y: float, semi_axis_z: float) -> TankGeometry:
        """Flat-ended cylinder of elliptical section (the SwRI tank of seed 003)."""
        return cls("elliptic", (length, semi_axis_y, semi_axis_z))

    @classmethod
    def box(cls, lower: tuple[float, float, float], upper: tuple[float, float, float]) -> TankGeometry:
        """Closed rectangular box between two corners."""
        return cls("box", (*lower, *upper))


Tank = TankGeometry
"""Deprecated alias of :class:`TankGeometry` (one release)."""


def _deprecated(old: str, new: str) -> None:
    warnings.warn(f"railslosh.slosh.{old} is deprecated: use railslosh.slosh.{new}", DeprecationWarning, stacklevel=3)


def cylinder_tank(length: float, radius: float, head_depth: float, bulkheads=()) -> TankGeometry:
    """Deprecated (one release): :meth:`TankGeometry.cylinder` (``railslosh.mesh.cylinder_tank``
    is the liquid's mesh, a different thing)."""
    _deprecated("cylinder_tank", "TankGeometry.cylinder")
    return TankGeometry.cylinder(length, radius, head_depth, bulkheads)


def elliptic_tank(length: float, semi_axis_y: float, semi_axis_z: float) -> TankGeometry:
    """Deprecated (one release): :meth:`TankGeometry.elliptic`."""
    _deprecated("elliptic_tank", "TankGeometry.elliptic")
    return TankGeometry.elliptic(length, semi_axis_y, semi_axis_z)


def box_tank(lower: tuple[float, float, float], upper: tuple[float, float, float]) -> TankGeometry:
    """Deprecated (one release): :meth:`TankGeometry.box`."""
    _deprecated("box_tank", "TankGeometry.box")
    return TankGeometry.box(lower, upper)


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
            raise ValueError(f"invalid `axis` = {axis!r}: expected one of x, y, z")
        if not (t1 > t0 + 2 * ramp and ramp > 0):
            raise ValueError(f"invalid `pulse` = [{t0}, {t1}] ramp {ramp}: expected t1 > t0 + 2 ramp > t0")
        self.acceleration[axis] = [(t0, 0.0), (t0 + ramp, accel), (t1 - ramp, accel), (t1, 0.0)]
        return self


#: Failure causes (``SimulationError.cause``) and the patterns of the Rust error messages
#: that name them, matched in this order (the names are those of Rust's ``FailureCause``).
FAILURE_CAUSES: tuple[tuple[str, str], ...] = (
    ("containment", r"not contained: "),
    ("energy_growth", r"energy balance broken"),
    ("distorted_element", r"distorted: J ="),
    ("wheel_off_rail", r"wheel off the rail"),
    ("contact_penetration", r"penetration .* beyond its limit"),
    ("volume_error", r"volume .* deviates from its reference"),
    ("inverted_element", r"inverted: J =|inverted element|J = [-+0-9.e]+ <= 0"),
    ("singular_constraints", r"singular KKT matrix"),
    ("non_finite", r"non-finite"),
    ("newton_divergence", r"Newton iteration did not converge|below h_min"),
)


def failure_cause(message: str) -> str:
    """Cause name of a failure message, ``"unknown"`` if it names none of :data:`FAILURE_CAUSES`."""
    for name, pattern in FAILURE_CAUSES:
        if re.search(pattern, message):
            return name
    return "unknown"


class SimulationError(RailsloshError):
    """A run stopped early; `.results` holds everything computed before the failure and
    `.cause` names why (one of :data:`FAILURE_CAUSES`, e.g. ``"inverted_element"``)."""

    def __init__(self, message: str, results: dict):
        super().__init__(message)
        self.results = results
        self.cause = failure_cause(message)


def run(
    mesh: FluidMesh,
    fluid: Fluid,
    tank: TankGeometry,
    motion: Motion | None = None,
    *,
    t_end: float,
    step: float = 0.01,
    frame: str = "inertial",
    gravity: tuple[float, float, float] = (0.0, 0.0, -GRAVITY),
    progress: ProgressArg = None,
    volume_tolerance: float = 0.01,
    penetration_limit: float = 0.5,
    contact_stiffness_factor: float = 1.0,
    stream: str | os.PathLike[str] | None = None,
    checkpoint: str | os.PathLike[str] | None = None,
    checkpoint_every: int = 100,
    resume_from: str | os.PathLike[str] | None = None,
    viscous_points: int = 3,
    penalty_points: int = 3,
    contact_points_per_edge: int = 3,
    stepper: str = "implicit",
    wall_damping_ratio: float = _core.WALL_DAMPING_RATIO,
    snapshot_every: float = 0.0,
    wall_adhesion: float = 0.0,
    h: float | None = None,
) -> dict:
    """Integrate the fluid in the moving tank up to `t_end` with steps of at most `step` (s; every
    step is recorded). ``h`` is the old name of ``step``, deprecated (one name for the step across
    the API, scenes and ``run.json``: ``step``); it warns and will be removed.

    `frame="inertial"` moves the walls; `frame="tank"` solves in the tank frame with the
    pseudo-forces of seed 003 (appendix C, eq. 7.40). Returns a dict of numpy arrays
    (see ``railslosh._core.run_slosh``) and the integrator statistics under ``stats``.
    Raises :class:`SimulationError` (with ``.results``) if the run stops early.
    ``progress=True`` shows a progress bar on stderr (:mod:`railslosh.progress`); a callable
    ``progress(t, t_end, steps, newton_iterations, rejected_steps)`` is called after the first step,
    then about every 0.5 s of wall time and at the end; if it raises, the run stops and the
    exception propagates.

    Failure guards, checked on every accepted step: the run stops with a
    :class:`SimulationError` (``cause`` ``"volume_error"`` / ``"contact_penetration"``) when the
    fluid volume deviates from its initial value by more than ``volume_tolerance`` (relative), or
    a boundary point penetrates a wall deeper than ``penetration_limit`` times the smallest element
    edge (``math.inf`` disables either). ``wall_damping_ratio`` (0 to 10, default
    ``_core.WALL_DAMPING_RATIO`` = 0.1) is the damping ratio of the liquid column on the penalty
    wall spring; 1 (critical) removes most of the wall ringing from the loads after an impact
    (docs/validation.md, "Wall damping"). ``wall_adhesion`` (0 to 50, default 0: a unilateral
    wall) is the suction an adhesive wall holds on the wetted liquid (the mesh's wall faces, not
    its free surface), in units of the hydrostatic pressure at the bottom ρ g H: it keeps the
    penalty liquid's transient tension from peeling the wetted faces off the wall and slapping them
    back (docs/validation.md, "Wall peeling"). ``contact_stiffness_factor`` scales the
    wall-contact penalty stiffness (damping ratio kept).

    Run-time invariants (``rail_mbs::invariants``), also on every accepted step: ``"containment"``
    when a fluid node, contact point or the centre of mass lies beyond a wall by more than the same
    penetration limit; ``"distorted_element"`` / ``"inverted_element"`` when the volume ratio
    J = det F at any quadrature or check point falls to 0.1 / 0; ``"energy_growth"`` when the energy
    E (kinetic, gravitational, penalty, contact springs) exceeds E0 + the work put in by more than 5 %
    of the energy scale. The results carry ``stored_energy``, ``input_work``, ``energy_error``,
    ``min_volume_ratio``, ``containment_gap`` per sample and the worst ``margins``.
    ``viscous_points``, ``penalty_points`` (Gauss points per direction) and
    ``contact_points_per_edge`` set the quadrature of the viscous stress, the penalty and the wall
    contact.

    ``stepper``: ``"implicit"`` (HHT-alpha, Newton on the sparse system; default), ``"explicit"``
    (central differences with the fluid's constant mass factored once: one force evaluation and a
    triangular solve per sub-step, sub-stepped at 0.8 of the stable step estimated by power
    iteration, landing on every ``step``; invariants checked at every ``step``) or ``"auto"`` (the
    cheaper one from the stable step at the start). The results carry ``stepper`` and
    ``stepper_reason``; for the explicit stepper ``newton_iterations`` counts its sub-steps.
    Checkpoints need the implicit stepper.

    ``stream`` (a file path) writes every sample to that file as it is computed (flushed per step),
    so a run that is interrupted -- killed, out of time -- loses nothing already computed; read it
    with :func:`read_stream`, which returns the arrays of this function.

    ``checkpoint`` (a file path) keeps the state of the run there (the stepper's, and the
    invariants' energy account and worst margins), rewritten atomically every
    ``checkpoint_every`` accepted steps. ``resume_from`` continues a run of the same scene from
    such a file: the results start at the checkpoint time and are bitwise identical to the
    uninterrupted run's from there on, energy error and input work included (the first sample
    reports 0 Newton iterations). Together with ``stream`` this restarts long runs without losing or changing
    anything.

    ``snapshot_every`` (s, 0 = none) keeps fluid mesh snapshots in the **tank frame**: the result's
    ``snapshots`` is a list of ``(t, [nodes × 4 × 3])`` (positions and the three position gradients
    of each node, the layout of :func:`railslosh.vehicle.run_fluid` with one car) and
    ``connectivity`` the element-node table, which :func:`railslosh.results.write_vtu` writes for
    ParaView.
    """
    if h is not None:
        warnings.warn(
            "`h` of railslosh.slosh.run is deprecated: use `step` (the name of the step in vehicle runs and scenes)",
            DeprecationWarning,
            stacklevel=2,
        )
        step = h
    wall_damping_ratio = limits.check("wall_damping_ratio", wall_damping_ratio)
    wall_adhesion = limits.check("wall_adhesion", wall_adhesion)
    motion = motion or Motion()
    unknown = set(motion.acceleration) - set(AXES)
    if unknown:
        raise ValueError(f"invalid `motion.acceleration` axes {sorted(unknown)}: expected x, y, z")
    acc = [motion.acceleration.get(a, []) for a in ("x", "y", "z")]
    with progress_callback(progress, "slosh run") as on_progress:
        scenario = SloshArgs(
            tank_shape=tank.shape,
            tank_dims=list(tank.dims),
            bulkheads=list(tank.bulkheads),
            acceleration=acc,
            rotation_axis=motion.rotation_axis,
            angular_acceleration=motion.angular_acceleration,
            t_end=t_end,
            step=step,
            frame=frame,
            gravity=list(gravity),
            volume_tolerance=volume_tolerance,
            penetration_limit=penetration_limit,
            contact_stiffness_factor=contact_stiffness_factor,
            viscous_points=viscous_points,
            penalty_points=penalty_points,
            contact_points_per_edge=contact_points_per_edge,
            stepper=stepper,
            wall_damping_ratio=wall_damping_ratio,
            snapshot_every=snapshot_every,
            wall_adhesion=wall_adhesion,
        )
        res = _core.run_slosh(
            mesh,
            fluid,
            scenario,
            progress=on_progress,
            stream=None if stream is None else os.fspath(stream),
            checkpoint=None if checkpoint is None else os.fspath(checkpoint),
            checkpoint_every=checkpoint_every,
            resume_from=None if resume_from is None else os.fspath(resume_from),
        )
    res["wall_damping_ratio"] = wall_damping_ratio
    res["wall_adhesion"] = wall_adhesion
    if res["error"] is not None:
        raise SimulationError(f"slosh run stopped at t = {res['t'][-1]:.4f} s: {res['error']}", res)
    return res


def read_stream(path: str | os.PathLike[str]) -> dict:
    """The samples of a :func:`run` ``stream`` file (also of an interrupted run: every complete
    sample), as the arrays of :func:`run` (``t``, ``force_tank`` (n, 3), ...), without ``stats``.
    The format is the journal of ``rail_mbs::integrator::Journal`` (docs/robustness.md)."""
    import numpy as np

    from railslosh.journal import read_journal

    # the columns are rail_mbs::slosh::SloshRecord::COLUMNS: a vector as its `_x`, `_y`, `_z`
    col = read_journal(path, "slosh stream")
    out: dict = {}
    for name, values in col.items():
        stem, _, axis = name.rpartition("_")
        if axis in ("x", "y", "z") and all(f"{stem}_{a}" in col for a in "xyz"):
            if stem not in out:
                out[stem] = np.stack([col[f"{stem}_{a}"] for a in "xyz"], axis=1)
        else:
            out[name] = values.astype(np.int64) if name == "newton_iterations" else values
    return out
