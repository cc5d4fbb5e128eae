"""Prescribed-motion slosh scenes (a ``[maneuver]`` section): a rigid tank moved by a maneuver,
the liquid an ANCF fluid mesh, run with :func:`railslosh.slosh.run`."""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from railslosh import fluids
from railslosh.constants import GRAVITY
from railslosh.scene.common import Outputs, meta, settle_time, slosh_outputs
from railslosh.scene.fluid import FluidSpec, oil_and_custom
from railslosh.scene.maneuvers import maneuver, motion
from railslosh.scene.schema import Section, counts, merge, scoped, table, unknown_sections
from railslosh.scene.tank import slosh_tank, tank_mesh
from railslosh.slosh import Motion, TankGeometry
from railslosh.vehicle import WALL_DAMPING_RATIO

SLOSH_COUNTS = ((1, 40), (1, 40), (1, 10))
"""Limits of ``[mesh] counts`` of a slosh scene (length, width, height)."""


@dataclass(frozen=True)
class SloshScene:
    """A validated prescribed-motion slosh scene: a rigid tank moved by a maneuver, the liquid an
    ANCF fluid mesh (run with :func:`railslosh.slosh.run`). Sections (every key, its limits and
    default: ``docs/scenes.md``):

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
      (``suspension_frequency`` Hz, default 2.0; ``suspension_damping`` ratio, default 0.3) whose massless
      wheel leaves the road rather than pull on it (that axle then falls freely until the wheel lands);
      the tank, midway between the axles, heaves and pitches; a trapezoid has ``ramp_up``, ``top`` and
      ``ramp_down`` lengths (m; defaults 4, 2 and 1 times the height: asymmetric, steep exit);
    * ``"pulse"``: ``axis``, ``acceleration`` (m/s^2), ``t0``, ``t1``, ``ramp`` (s);
    * ``"samples"``: ``x``, ``y``, ``z`` = ``[[t, a], ...]`` piecewise-linear accelerations.

    Every maneuver starts at ``t0`` (s, default 0.2).
    """

    tank: TankGeometry
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
    settle_time: float | None = None
    """``[scene] settle_time``: the settling phase that peaks, statistics and the report leave out, s
    (``None``: detected from the results, :func:`railslosh.results.settling`)."""
    outputs: Outputs = field(default_factory=Outputs)
    raw: Mapping[str, Any] = field(default_factory=dict, compare=False, repr=False)

    kind = "slosh"

    @property
    def shear_stabilization(self) -> bool:
        """Deprecated alias (one release) of ``fluid.shear_stabilization``: the key now lives with the
        liquid, as in vehicle scenes."""
        warnings.warn(
            "SloshScene.shear_stabilization is deprecated: use SloshScene.fluid.shear_stabilization",
            DeprecationWarning,
            stacklevel=2,
        )
        return self.fluid.shear_stabilization

    def mesh(self) -> Any:
        """The fluid mesh (reference configuration, tank frame)."""
        return tank_mesh(self.tank, self.fluid.fill, self.fluid.counts)

    def depth(self) -> float:
        """Liquid depth of the mesh at rest, m."""
        m = self.mesh()
        return float(m.free_surface_z - m.nodes[:, 2].min())

    def motion(self) -> Motion:
        """The :class:`railslosh.slosh.Motion` of the maneuver."""
        return motion(self.maneuver, self.t_end)

    def liquid_mass(self) -> float:
        """Mass of the liquid, kg (density times the exact volume of the mesh's region)."""
        return self.fluid.density() * float(self.mesh().exact_volume)

    def mirror_symmetric(self) -> bool:
        """Whether the run's inputs are mirror-symmetric about the tank's x–z plane (y → −y,
        ``docs/frames.md``): no lateral (y) acceleration, rotation (if any) about the y axis (the
        pitch of a bump), and a tank symmetric about y = 0 (every elliptic and cylinder tank, with or
        without bulkheads; a box whose walls are at ±y). A lane change is not (its lateral motion and
        heading are mirrored into the other lane); bumps, pulses along x or z and samples without y
        are. Then the liquid's lateral load is zero in an exact solution
        (:func:`railslosh.scene.run.mirror_symmetry`), as in the vehicle runs of
        :meth:`railslosh.scene.Scene.mirror_symmetric`."""
        mo = self.motion()
        lateral = any(a != 0.0 for _, a in mo.acceleration.get("y", ()))
        ax = mo.rotation_axis
        turning = any(a != 0.0 for _, a in mo.angular_acceleration)
        off_pitch = ax is not None and turning and (ax[0] != 0.0 or ax[2] != 0.0)
        symmetric_tank = self.tank.shape != "box" or self.tank.dims[1] == -self.tank.dims[4]
        return not lateral and not off_pitch and symmetric_tank

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
            k = fluids.default_bulk_penalty(spec.density(), depth) * max(1.0, self.peak_load_factor())
            spec = dataclasses.replace(spec, custom={**spec.custom, "bulk_penalty": k})
        heads = self.tank.shape == "cylinder" and self.tank.dims[2] > 0.0
        fluid = spec.make_fluid(depth, depth / spec.counts[2], heads)
        kw: dict[str, Any] = {
            "t_end": self.t_end,
            "step": self.step,
            "frame": self.frame,
            "viscous_points": self.viscous_points,
            "penalty_points": self.penalty_points,
            "contact_points_per_edge": self.contact_points_per_edge,
            "stepper": self.stepper,
        }
        if self.outputs.snapshot_every > 0:
            kw["snapshot_every"] = self.outputs.snapshot_every
        if self.contact_stiffness_factor != 1.0:
            kw["contact_stiffness_factor"] = self.contact_stiffness_factor
        if self.fluid.wall_damping_ratio != WALL_DAMPING_RATIO:
            kw["wall_damping_ratio"] = self.fluid.wall_damping_ratio
        if self.fluid.wall_adhesion != 0.0:
            kw["wall_adhesion"] = self.fluid.wall_adhesion
        return (self.mesh(), fluid, self.tank, self.motion()), kw

    def to_dict(self) -> dict[str, Any]:
        """The scene as parsed (a dict that :func:`railslosh.scene.load_scene` reads back)."""
        return merge(self.raw, {})


def slosh_scene_from_dict(data: Mapping[str, Any]) -> SloshScene:
    """Validates a parsed prescribed-motion scene (one with a ``[maneuver]`` section)."""
    data = table(data, "scene")
    unknown_sections(data, "slosh")
    name, description = meta("slosh", data)
    settle = settle_time("slosh", data)
    sv = Section("slosh", "solver", data)
    stepper = sv.get("stepper")
    wall = sv.get("contact_stiffness_factor")
    t_end = sv.get("t_end")
    step = sv.get("step", hi=min(0.05, t_end), note=" (≤ solver.t_end)")
    frame = sv.get("frame")
    fl = Section("slosh", "fluid", data)
    oil, custom = oil_and_custom(fl)
    fill = fl.get("fill")
    ms = Section("slosh", "mesh", data)
    n = counts(ms.values.get("counts", [2, 4, 2]), "mesh.counts", SLOSH_COUNTS)
    rules = {k: ms.get(k) for k in ("viscous_points", "penalty_points", "contact_points_per_edge")}
    tk = Section("slosh", "tank", data)
    zeta = tk.get("wall_damping_ratio")
    tank = slosh_tank(tk, n)
    spec = FluidSpec(
        oil=oil,
        fill=fill,
        counts=n,
        bulkheads=tank.bulkheads,
        custom=custom,
        wall_damping_ratio=zeta,
        wall_adhesion=tk.get("wall_adhesion"),
        shear_stabilization=ms.get("shear_stabilization"),
    )
    man = maneuver(data, t_end)
    outputs = slosh_outputs(data, step)
    sc = SloshScene(
        tank=tank,
        fluid=spec,
        maneuver=man,
        t_end=t_end,
        step=step,
        frame=frame,
        contact_stiffness_factor=wall,
        stepper=stepper,
        name=name,
        description=description,
        settle_time=settle,
        outputs=outputs,
        raw=dict(data),
        **rules,
    )
    try:
        sc.mesh()
        sc.fluid.make_fluid(sc.depth())
    except ValueError as exc:
        raise scoped(exc, "mesh", prefix=False) from exc
    return sc
