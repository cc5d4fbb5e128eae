"""Scene files: a train of tank cars on a track (run with :func:`railslosh.vehicle.run`), with
rigid lading or liquid cargo, or a tank moved by a prescribed maneuver (:func:`railslosh.slosh.run`),
described in TOML.

    >>> from railslosh import scene
    >>> sc = scene.load_scene("examples/scenes/single_car_table1_curve_60kmh.toml")
    >>> res = scene.run_scene(sc)              # the dict of railslosh.vehicle.run
    >>> short = scene.load_scene("examples/scenes/two_car_ecp_braking_rigid.toml", {"train": {"t_end": 0.1}})

Every section and key, with its limits, default and meaning, is in ``docs/scenes.md``, written
from the one schema table (:data:`railslosh.scene.schema.SCHEMA`). SI units unless a name says
otherwise (``_kmh``, ``_mph``, ``_ft``, ``_in``, ``_percent``; see ``docs/frames.md``).

**Vehicle scenes.** ``[track]`` (required): exactly one of ``preset = "table1" | "tangent"``
(Table 1 of seed 000: two opposite 3-degree curves with 3 in super-elevation and spirals, 2800 ft;
or a straight track of ``length`` m), ``rows`` (SI segment table ``[s, curvature, superelevation,
grade, cant_right, cant_left]``, 3 to 6 numbers a row) or ``us_rows`` (ft, arc-definition degrees
positive to the left, in, %, rad). ``[track.irregularities]``: the rails' irregularity
(:mod:`railslosh.irregularity`): ``kind = "fra"`` (with ``class``), ``"erri_low"``, ``"erri_high"``,
``"file"`` or ``"perfect"``, ``seed``, ``wavelengths``, ``taper``, ``start`` (≥ 1 m ahead of the
leading wheelset at t = 0; default 10 m), ``length``, ``step``, ``channels``, ``file``, ``units``,
``sha256``, ``defects`` (:meth:`Scene.irregularity_spec` fills in the defaults; ``--set
track.irregularities.seed=2`` reaches its keys). ``[train]``: ``cars``, ``station`` (front tank centre at t = 0),
``speed`` or ``speed_kmh``, ``drive`` (``true`` holds the front car to ``speed``, a number to that
speed), ``t_end``, ``step``, ``record_every``, ``load_filter`` (``"hat_mean"``: loads as their
anti-aliased hat-weighted mean over the steps, or ``"sample"``; see :func:`railslosh.vehicle.run`),
``wheelset_lateral_offset``, ``coupler_stiffness``, ``coupler_damping``. ``[brake]``: ``times`` and
``torques`` (N m per wheelset, against the motion) and ``scope = "all"`` (ECP) or ``"front"``; or
``design = true``: the torque of :func:`railslosh.vehicle.design_brake_torque` that slows the loaded
car from the train speed to ``design_v1_kmh`` in ``design_duration`` s (seed 000 §8.2), scaled per
car by ``factors`` (fluid scenes). ``[lading]``: rigid lading ``mass`` and ``height`` of its centre
above the tank axis. ``[car]``: any key of :func:`railslosh.vehicle.tank_car_parameters` but ``dof``
and ``total_mass``, and ``wheel_profile``.

**Liquid cargo** (an ANCF fluid in every tank, :func:`railslosh.vehicle.run_fluid`): ``[fluid]``:
``oil = "light" | "medium" | "heavy" | "water" | "custom"`` (seed 000 Table 2 crude oils, Oldroyd;
a custom oil gives ``model`` and ``density`` and any rheology parameter), ``fill`` (liquid volume
fraction, :data:`railslosh.limits.FILL`), ``slosh_model = "auto" | "ancf" | "pendulum" | "rigid"``
(:mod:`railslosh.fluid_model`; the key is not ``model``, which names a custom oil's rheology).
``[mesh] counts``; ``[tank] bulkheads = [[x, thickness], ...]`` and ``wall_damping_ratio``
(1 removes most of the wall ringing from the loads: docs/validation.md, "Wall damping");
``[outputs]``: ``snapshot_every`` (fluid mesh snapshots for ParaView), ``netcdf``, ``vtu``,
``plots``. Rigid lading, coupler overrides and wheelset offsets do not go with liquid cargo.

**Prescribed-motion slosh scenes** (a ``[maneuver]`` section): see :class:`SloshScene`.

Every error is a ``ValueError`` naming the dotted field, its value and what is expected, e.g.
``invalid `train.speed` = 250.0: expected a speed from 0 to 70 m/s``; unknown sections and keys are
named with the closest allowed name. The package: :mod:`~railslosh.scene.schema` (the table and
its checks), :mod:`~railslosh.scene.track`, :mod:`~railslosh.scene.vehicle` (:class:`Scene`),
:mod:`~railslosh.scene.fluid` (:class:`FluidSpec`), :mod:`~railslosh.scene.tank`,
:mod:`~railslosh.scene.maneuvers`, :mod:`~railslosh.scene.slosh` (:class:`SloshScene`),
:mod:`~railslosh.scene.common` (``[scene]``, ``[outputs]``), :mod:`~railslosh.scene.load`
(:func:`load_scene`) and :mod:`~railslosh.scene.run` (:func:`run_scene`).
"""

from __future__ import annotations

# ``X as X``: names also importable from railslosh.scene (documented where they are defined).
from railslosh.constants import INCH as INCH
from railslosh.constants import MPH as MPH
from railslosh.scene.common import Outputs
from railslosh.scene.fluid import FluidSpec
from railslosh.scene.load import load_scene, parse_overrides, parse_value, read_scene
from railslosh.scene.run import run_scene
from railslosh.scene.schema import LOAD_FILTERS as LOAD_FILTERS
from railslosh.scene.schema import MANEUVERS as MANEUVERS
from railslosh.scene.schema import OILS, PRESETS, SCHEMA
from railslosh.scene.schema import STEPPERS as STEPPERS
from railslosh.scene.schema import TANK_SHAPES as TANK_SHAPES
from railslosh.scene.schema import merge as merge
from railslosh.scene.slosh import SloshScene
from railslosh.scene.slosh import slosh_scene_from_dict as slosh_scene_from_dict
from railslosh.scene.vehicle import Scene, scene_from_dict

__all__ = [
    "OILS",
    "PRESETS",
    "FluidSpec",
    "Outputs",
    "Scene",
    "SloshScene",
    "load_scene",
    "parse_overrides",
    "parse_value",
    "read_scene",
    "run_scene",
    "scene_from_dict",
]

# The public names are documented, and pickled, as railslosh.scene's.
for _obj in (Outputs, FluidSpec, Scene, SloshScene, load_scene, read_scene, parse_overrides, parse_value, run_scene,
             scene_from_dict, slosh_scene_from_dict):  # fmt: skip
    _obj.__module__ = __name__
del _obj

_TRAIN_KEYS = tuple(SCHEMA["vehicle"]["train"])
"""The keys of ``[train]``."""
