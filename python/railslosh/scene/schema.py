"""The scene schema: one table (:data:`SCHEMA`) of every section and key of both kinds of scene,
with its type, default, limits and meaning, and the checks that read a section through it.

Every error is a ``ValueError`` in the one form of :mod:`railslosh.limits`:
``invalid `train.t_end` = -1.0: expected a time > 0 s and ≤ 600 s``; unknown sections and keys
are named with the closest allowed name (``did you mean `maneuver`?``). ``docs/scenes.md`` is
this table, written by ``python -m railslosh.scene > docs/scenes.md``.

Limits that depend on other fields (the train's station on the track, ``record_every`` of at least
the step, bulkheads inside the shell, ...) are narrowed by the section code with ``lo=``/``hi=``;
the table holds their widest values.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from railslosh import _core, irregularity, mesh
from railslosh.constants import MPH
from railslosh.fluid_model import SLOSH_MODELS
from railslosh.limits import FILL, PARAMETERS, Limit, invalid, unknown
from railslosh.vehicle import WALL_DAMPING_RATIO

PRESETS = ("table1", "tangent")
"""Names accepted by ``[track] preset``."""
OILS = ("light", "medium", "heavy", "water", "custom")
"""Names accepted by ``[fluid] oil``."""
RHEOLOGIES = ("newtonian", "bingham", "herschel-bulkley", "oldroyd", "casson")
"""Values of ``[fluid] model`` (the rheology of a custom oil)."""
WHEEL_PROFILES = ("s1002", "aar1b")
#: Bogie models (rail_mbs::vehicle::TruckModel): seed 000's rigid frame, or a warp-capable
#: three-piece freight truck.
TRUCK_MODELS = ("rigid_frame", "three_piece")
BRAKE_SCOPES = ("all", "front")
STEPPERS = ("implicit", "explicit", "auto")
"""Values of ``[solver] stepper`` of slosh scenes."""
LOAD_FILTERS = ("hat_mean", "sample")
"""Values of ``[train] load_filter``."""
TANK_SHAPES = ("elliptic", "cylinder", "box")
"""Values of ``[tank] shape`` of slosh scenes."""
MANEUVERS = ("lane_change", "bump", "pulse", "samples")
"""Names accepted by ``[maneuver] type``."""
BUMP_SHAPES = ("half_round", "trapezoid")
IRREGULARITY_KINDS = (*irregularity.SPECTRA, "file", "perfect")
"""Values of ``[track.irregularities] kind``: a spectrum (:data:`railslosh.irregularity.SPECTRA`), a
measured file, or a perfect track carrying only the defects."""
MAX_SPEED = 70.0
"""Largest train or maneuver speed, m/s (252 km/h)."""
MAX_ROWS = 10_000
"""Most rows of a table (track, brake, acceleration samples)."""


@dataclass(frozen=True)
class Field:
    """One key of the schema: ``kind`` (``number``, ``integer``, ``choice``, ``flag``, ``text``, or
    a structured value checked by its section's code), default, limit or choices, and meaning."""

    kind: str
    doc: str
    default: Any = None
    limit: Limit | None = None
    choices: tuple[str, ...] = ()
    value: str = ""
    """What a structured value looks like (for the reference)."""
    default_doc: str = ""
    """The default in words, where it is not a constant."""

    def expected(self, **limits: Any) -> str:
        """What the key accepts, in words."""
        if self.limit is not None:
            return self.limit.expected(**limits)
        if self.kind == "choice":
            return "one of " + ", ".join(repr(c) for c in self.choices)
        if self.kind == "flag":
            return "true or false"
        if self.kind == "text":
            return "a string of at most 2000 characters"
        return self.value

    def check(self, value: Any, field: str, **limits: Any) -> Any:
        """``value`` checked (numbers converted), or the ``ValueError`` naming ``field``."""
        if self.limit is not None:
            return self.limit.check(value, field, **limits)
        ok = {
            "choice": isinstance(value, str) and value in self.choices,
            "flag": isinstance(value, bool),
            "text": isinstance(value, str) and len(value) <= 2000,
        }.get(self.kind)
        if ok is None:
            raise TypeError(f"`{field}` ({self.kind}) is checked by its section's code")
        if not ok:
            raise invalid(field, value, self.expected())
        return value


DEFAULT_STEP = 1e-3
"""Largest integrator step of a vehicle run whose scene gives no ``[train] step`` and that no rule of
:meth:`railslosh.scene.Scene.largest_step` covers, s."""


def _num(lo: float, hi: float, unit: str, noun: str, default: Any, doc: str, **kw: Any) -> Field:
    return Field("number", doc, default, Limit(lo, hi, unit, noun, lo_open=kw.pop("lo_open", False)), **kw)


def _int(lo: int, hi: int, default: Any, doc: str, noun: str = "an integer") -> Field:
    return Field("integer", doc, default, Limit(lo, hi, noun=noun, integer=True))


def _choice(choices: tuple[str, ...], default: Any, doc: str) -> Field:
    return Field("choice", doc, default, choices=choices)


def _flag(default: bool, doc: str) -> Field:
    return Field("flag", doc, default)


def _value(value: str, doc: str, default: Any = None, default_doc: str = "") -> Field:
    return Field("structured", doc, default, value=value, default_doc=default_doc)


_META = {
    "name": Field("text", "title of the scene", ""),
    "description": Field("text", "what the scene is for", ""),
    "settle_time": _num(
        0.0, 600.0, "s", "a time", None, "settling phase that peaks and the report leave out (default: detected)"
    ),
}
_CUSTOM = {
    "model": _choice(RHEOLOGIES, None, 'rheology of a custom oil (only with oil = "custom", required there)'),
    "density": _num(100.0, 20_000.0, "kg/m^3", "a density", None, 'liquid density (oil = "custom": required)'),
    "viscosity": _num(0.0, 1e5, "Pa s", "a viscosity", None, "dynamic (plastic) viscosity"),
    "yield_stress": _num(0.0, 1e5, "Pa", "a stress", None, "yield stress"),
    "consistency": _num(0.0, 1e5, "Pa s^n", "a consistency", None, "Herschel-Bulkley consistency"),
    "power_index": _num(0.05, 3.0, "", "a power-law index", None, "Herschel-Bulkley power index"),
    "elastic_modulus": _num(1e-3, 1e9, "Pa", "a modulus", None, "Oldroyd shear modulus below yield"),
    "bulk_penalty": _num(
        1.0, 1e10, "Pa", "a bulk modulus", None, "incompressibility penalty", default_doc="1000 ρ g depth"
    ),
    "bulk_damping": _num(0.0, 1e8, "Pa s", "a bulk viscosity", None, "penalty damping"),
}
CUSTOM_KEYS = tuple(k for k in _CUSTOM if k != "model")
"""The constructor arguments of a custom fluid (``[fluid]`` with ``oil = "custom"``)."""
_OIL = _choice(OILS, "light", "seed 000 Table 2 crude oils (Oldroyd), water, or a custom fluid")
_FILL = Field("number", "liquid volume as a fraction of the tank volume (railslosh.limits.FILL)", 0.5, FILL)
_WALL_DAMPING = Field(
    "number",
    "damping ratio of the liquid column on the penalty wall; 1 removes most wall ringing from the loads",
    WALL_DAMPING_RATIO,
    PARAMETERS["wall_damping_ratio"],
)
_GAUGE_FACE = _core.LUBRICATED_GAUGE_FACE
"""Defaults of the ``lubricated_gauge_face`` friction preset (``rail_mbs::wheel_rail::GaugeFaceLubrication``)."""
_WALL_ADHESION = Field(
    "number",
    "suction the wall holds on the wetted liquid, in units of the hydrostatic pressure rho g H at the bottom "
    "(0: a unilateral wall); keeps the wetted liquid from peeling off the wall and slapping back",
    0.0,
    PARAMETERS["wall_adhesion"],
)
_SHEAR_STABILIZATION = _flag(True, "zero-energy-mode control that makes the rest state stable (docs/validation.md)")
_BULKHEADS = _value(
    "[[x, thickness], ...] (m, tank frame)",
    "full-height plates, inside the shell, not overlapping, each compartment at least one element long",
    [],
)
_SPEEDS = {
    "speed": _num(0.0, MAX_SPEED, "m/s", "a speed", None, "vehicle speed (exactly one of the three)", lo_open=True),
    "speed_mph": _num(0.0, MAX_SPEED / MPH, "mph", "a speed", None, "speed in mph", lo_open=True),
    "speed_kmh": _num(0.0, MAX_SPEED * 3.6, "km/h", "a speed", None, "speed in km/h", lo_open=True),
}
_LIBRARY: dict[str, dict[str, float]] = _core.maneuver_defaults()


def maneuver_defaults() -> dict[str, dict[str, float]]:
    """Defaults of the lane change, the bump and the trapezoid's proportions: the one maneuver
    library's (``rail_mbs::maneuvers``)."""
    return _LIBRARY


def _library(kind: str, key: str, lo: float, hi: float, unit: str, noun: str, doc: str) -> Field:
    v = _LIBRARY[kind][key]
    return _num(lo, hi, unit, noun, v, doc, default_doc=f"`{v:g}` (rail_mbs::maneuvers)")


SCHEMA: dict[str, dict[str, dict[str, Field]]] = {
    "vehicle": {
        "track": {
            "preset": _choice(PRESETS, None, "Table 1 of seed 000 (two opposite 3° curves) or a straight track"),
            "rows": _value(
                "[[s, curvature, superelevation, grade, cant_right, cant_left], ...] (m, 1/m, m, 1, rad)",
                "segment table in SI units, 3 to 6 numbers a row (missing trailing columns are 0)",
            ),
            "us_rows": _value(
                "[[distance_ft, degree_of_curvature, superelevation_in, grade_percent, cant_right, cant_left], ...]",
                "segment table in US units (arc-definition degrees, positive = curve to the left)",
            ),
            "length": _num(100.0, 1e6, "m", "a length", 3000.0, 'length of preset = "tangent" (only there)'),
        },
        "track.friction": {
            "preset": _choice(
                ("lubricated_gauge_face",),
                None,
                "friction preset over the rail profile: mu_gauge on the gauge face, mu_top on the rest of the head "
                "(railslosh.vehicle.run, friction_map); give it or `profile`",
            ),
            "mu_top": _num(
                0.0, 1.0, "", "a friction coefficient", _GAUGE_FACE["mu_top"], "top-of-rail friction of the preset"
            ),
            "mu_gauge": _num(
                0.0, 1.0, "", "a friction coefficient", _GAUGE_FACE["mu_gauge"], "gauge-face friction of the preset"
            ),
            "depth": _num(
                1e-4,
                0.03,
                "m",
                "a depth",
                _GAUGE_FACE["depth"],
                "the preset's gauge face starts this far below the rail top",
            ),
            "width": _num(
                1e-4, 0.05, "m", "a width", _GAUGE_FACE["width"], "the preset's blend from mu_gauge to mu_top"
            ),
            "profile": _value(
                "[[v, mu], ...] (m, increasing v; 0 ≤ mu ≤ 1)",
                "friction over the rail profile's lateral coordinate v (railslosh.rail.contact's friction_profile)",
            ),
            "along_track": _value(
                "[[s, factor], ...] (m, increasing s; 0 ≤ factor ≤ 10)",
                "a factor on mu over the distance along the track (a wet or a greased stretch); 1 outside",
            ),
        },
        "track.irregularities": {
            "kind": _choice(
                IRREGULARITY_KINDS,
                None,
                'the rails\' irregularity (required): a spectrum, US FRA track class ("fra" with `class`) or ERRI '
                'B176 ("erri_low" good, "erri_high" poor track; no gauge spectrum), a measured "file", or a '
                '"perfect" track carrying only the `defects` (railslosh.irregularity; channels in docs/frames.md)',
            ),
            "class": _int(
                1,
                6,
                None,
                'FRA track class, 1 (worst) to 6 (best); kind = "fra" only, required there',
                "an FRA track class",
            ),  # fmt: skip
            "seed": _int(0, 999_999, 1, "seed of the random phases (spectra): the same seed gives the same track"),
            "wavelengths": _value(
                "[shortest, longest] (m, 0 < shortest < longest ≤ length)",
                "wavelength range drawn from the spectrum",
                [1.0, 70.0],
            ),
            "taper": _num(
                0.0, 1e4, "m", "a length", 20.0, "raised-cosine ramp from zero at `start` (spectra)", lo_open=True
            ),
            "start": _num(
                -1e6,
                1e6,
                "m",
                "a track position",
                None,
                "where the irregular section (or the file's first row) starts: ≥ 1 m ahead of the leading wheelset at "
                "t = 0, so that the train starts on perfect track",
                default_doc="10 m ahead of the leading wheelset at t = 0",
            ),
            "length": _num(
                0.0,
                5e4,
                "m",
                "a length",
                None,
                "length of the irregular section (spectra, perfect)",
                default_doc="speed × t_end + train length + 50 m rounded up to a whole km (a shorter t_end keeps "
                "the track)",
                lo_open=True,
            ),
            "step": _num(
                1e-3,
                10.0,
                "m",
                "a sample spacing",
                None,
                "sample spacing (spectra: ≤ half the shortest wavelength; defects span ≥ 8 steps)",
                default_doc='`0.25` (`0.05` with kind = "perfect")',
            ),
            "channels": _value(
                '["vertical", "alignment", "cross_level", "gauge"] (a subset)',
                "the channels drawn or kept from the file; the others are zero",
                default_doc="all four",
            ),
            "file": Field(
                "text",
                'measured irregularity file (kind = "file", required; format: railslosh.irregularity); a relative '
                "path is relative to the scene file",
            ),
            "units": _choice(
                irregularity.UNITS, None, "the file's channel units; must agree with its `# units:` line if it has one"
            ),
            "sha256": Field("text", "SHA-256 (hex) the file must have: a changed file is refused"),
            "defects": _value(
                '[{type = "cosine_dip", start, length, depth}, {type = "cusp", at, length, depth}, '
                '{type = "twist", start, base, cross_level, hold}, ...] (m)',
                "isolated defects added on top: within the section, each spanning ≥ 8 steps (depth positive down)",
                [],
            ),
        },
        "train": {
            "cars": _int(1, 50, 1, "number of tank cars", "a number of cars"),
            "station": _num(
                -1e6, 1e6, "m", "a track position", 50.0, "front tank centre at t = 0 (the train stays on the track)"
            ),
            "speed": _num(0.0, MAX_SPEED, "m/s", "a speed", 0.0, "initial speed (or speed_kmh, not both)"),
            "speed_kmh": _num(0.0, MAX_SPEED * 3.6, "km/h", "a speed", None, "initial speed in km/h"),
            "drive": _value(
                f"true, false or a speed from 0 to {MAX_SPEED:g} m/s",
                "true holds the front car to the train speed, a number to that speed",
                False,
            ),
            "t_end": _num(0.0, 600.0, "s", "a time", 1.0, "simulated time", lo_open=True),
            "step": _num(
                1e-6,
                0.01,
                "s",
                "a time step",
                None,
                "largest integrator step",
                default_doc=f"`{DEFAULT_STEP:g}`; a braked ANCF run of a named oil: its converged step (ECP "
                f"`{_core.braking_step('all', 'light'):g}`, `{_core.braking_step('all', 'heavy'):g}` with medium or "
                f"heavy crude; conventional `{_core.braking_step('front', 'light'):g}`)",
            ),
            "record_every": _num(1e-6, 10.0, "s", "an interval", 0.01, "recording interval (≥ train.step)"),
            "load_filter": _choice(
                LOAD_FILTERS, "hat_mean", "loads as their hat-weighted mean over the steps, or point samples"
            ),
            "wheelset_lateral_offset": _num(-0.0099, 0.0099, "m", "an offset", 0.0, "initial lateral wheelset offset"),
            "coupler_stiffness": _num(
                1e3, 1e10, "N/m", "a stiffness", None, "coupler stiffness", default_doc="model's"
            ),
            "coupler_damping": _num(0.0, 1e9, "N s/m", "a damping", None, "coupler damping", default_doc="model's"),
        },
        "brake": {
            "times": _value("[t, ...] (s, increasing, 0 to 10000)", "times of the torque table"),
            "torques": _value("[T, ...] (N m, 0 to 100000)", "brake torque per wheelset, against the motion"),
            "scope": _choice(BRAKE_SCOPES, "all", '"all" (ECP: every car) or "front" (conventional)'),
            "design": _flag(False, "true: the torque of vehicle.design_brake_torque instead of times/torques"),
            "design_v1_kmh": _num(0.0, MAX_SPEED * 3.6, "km/h", "a speed", 5.0, "designed brake: final speed"),
            "design_duration": _num(1.0, 600.0, "s", "a duration", 10.0, "designed brake: time to reach it"),
            "factors": _value("[f, ...] (0 to 10, one per car at most)", "per-car scale of the torque (fluid scenes)"),
        },
        "lading": {
            "mass": _num(0.0, 150_000.0, "kg", "a mass", 0.0, "rigid lading per car"),
            "height": _num(
                -15.0, 15.0, "m", "a height", 0.0, "its centre above the tank axis (within ± the tank radius)"
            ),
        },
        "car": {
            "wheel_profile": _choice(WHEEL_PROFILES, "s1002", "wheel profile"),
            "truck": _choice(
                TRUCK_MODELS,
                "rigid_frame",
                "bogie model: seed 000's rigid frame, or a three-piece truck whose side frames warp "
                '(docs/user-guide.md, "Bogie model")',
            ),
            "*": _value(
                "a number",
                "any key of vehicle.tank_car_parameters() but dof and total_mass: friction 0 to 1, stiffness and "
                "damping 0 to 10 times the default, anything else 0.1 to 10 times the default",
                default_doc="the model's",
            ),
        },
        "scene": _META,
        "fluid": {
            "oil": _OIL,
            "fill": _FILL,
            "slosh_model": _choice(SLOSH_MODELS, "auto", "liquid model: railslosh.fluid_model"),
            **_CUSTOM,
        },
        "mesh": {
            "counts": _value(
                "[n_length (1-40), n_width (2-20), n_height (1-10)]", "fluid elements per tank", [6, 4, 2]
            ),
            "shear_stabilization": _SHEAR_STABILIZATION,
        },
        "tank": {"bulkheads": _BULKHEADS, "wall_damping_ratio": _WALL_DAMPING, "wall_adhesion": _WALL_ADHESION},
        "outputs": {
            "netcdf": _flag(True, "write results.nc"),
            "vtu": _flag(True, "write fluid/*.vtu and fluid.pvd (needs snapshot_every)"),
            "plots": _flag(True, "write PNG plots"),
            "snapshot_every": _num(0.0, 600.0, "s", "an interval", 0.0, "fluid mesh snapshots (0 = none)"),
        },
    },
    "slosh": {
        "scene": _META,
        "tank": {
            "shape": _choice(TANK_SHAPES, "elliptic", "flat-ended elliptic cylinder, cylinder with heads, or box"),
            "wall_damping_ratio": _WALL_DAMPING,
            "wall_adhesion": _WALL_ADHESION,
        },
        "tank:elliptic": {
            "length": _num(0.05, 50.0, "m", "a length", mesh.SWRI_LENGTH, "tank length (default: SwRI tank)"),
            "semi_axis_y": _num(0.02, 5.0, "m", "a length", mesh.SWRI_SEMI_AXIS_Y, "half width"),
            "semi_axis_z": _num(0.02, 5.0, "m", "a length", mesh.SWRI_SEMI_AXIS_Z, "half height"),
        },
        "tank:cylinder": {
            "length": _num(0.1, 50.0, "m", "a length", mesh.TANK_CAR_SHELL_LENGTH, "shell length (default: tank car)"),
            "radius": _num(0.05, 5.0, "m", "a length", mesh.TANK_CAR_RADIUS, "shell radius"),
            "head_depth": _num(0.0, 5.0, "m", "a length", mesh.TANK_CAR_HEAD_DEPTH, "head depth (≤ radius)"),
            "bulkheads": _BULKHEADS,
        },
        "tank:box": {
            "lower": _value("[x, y, z] (m, -50 to 50)", "lower corner (required)"),
            "upper": _value("[x, y, z] (m, each > lower + 0.01)", "upper corner (required)"),
        },
        "fluid": {"oil": _OIL, "fill": _FILL, **_CUSTOM},
        "mesh": {
            "counts": _value("[n_length (1-40), n_width (1-40), n_height (1-10)]", "fluid elements", [2, 4, 2]),
            "viscous_points": _int(3, 6, 3, "Gauss points per direction of the viscous stress"),
            "penalty_points": _int(2, 6, 3, "Gauss points per direction of the volumetric penalty"),
            "contact_points_per_edge": _int(2, 6, 3, "wall-contact points per boundary-face edge"),
            "shear_stabilization": _SHEAR_STABILIZATION,
        },
        "solver": {
            "t_end": _num(0.0, 600.0, "s", "a time", 2.0, "simulated time", lo_open=True),
            "step": _num(1e-5, 0.05, "s", "a time step", 0.01, "largest step (≤ solver.t_end)"),
            "frame": _choice(("inertial", "tank"), "inertial", "moving walls, or the tank frame with pseudo-forces"),
            "contact_stiffness_factor": _num(0.1, 1000.0, "", "a factor", 1.0, "wall stiffness / default penalty"),
            "stepper": _choice(STEPPERS, "implicit", "time stepper: railslosh.slosh.run"),
        },
        "outputs": {
            "netcdf": _flag(True, "write results.nc"),
            "vtu": _flag(True, "write fluid/*.vtu and fluid.pvd, tank frame (needs snapshot_every)"),
            "plots": _flag(True, "write PNG plots"),
            "snapshot_every": _num(0.0, 600.0, "s", "an interval", 0.0, "fluid mesh snapshots (0 = none)"),
        },
        "maneuver": {
            "type": _choice(MANEUVERS, None, "the prescribed motion (required)"),
            "t0": _num(0.0, 600.0, "s", "a time", 0.2, "start of the maneuver"),
        },
        "maneuver:lane_change": {
            **_SPEEDS,
            "offset": _library("lane_change", "offset", 0.1, 20.0, "m", "a length", "lateral offset"),
            "length": _library("lane_change", "length", 1.0, 1000.0, "m", "a length", "length of one lane change"),
            "hold": _library("lane_change", "hold", 0.0, 1000.0, "m", "a length", "distance before returning"),
            "double": _flag(True, "return to the original lane"),
        },
        "maneuver:bump": {
            **_SPEEDS,
            "shape": _choice(BUMP_SHAPES, "half_round", "bump profile"),
            "height": _num(0.001, 1.0, "m", "a height", None, "bump height (or height_in, exactly one)"),
            "height_in": _num(0.04, 40.0, "in", "a height", None, "bump height in inches"),
            "suspension_frequency": _library(
                "bump", "suspension_frequency", 0.2, 50.0, "Hz", "a frequency", "each axle's suspension"
            ),
            "suspension_damping": _library(
                "bump", "suspension_damping", 0.01, 2.0, "", "a damping ratio", "its damping ratio"
            ),
            "wheelbase": _library("bump", "wheelbase", 0.5, 30.0, "m", "a length", "two-axle vehicle"),
            "wheel_radius": _library("bump", "wheel_radius", 0.1, 2.0, "m", "a length", "rolling over the bump"),
            **{
                k: _num(
                    0.0 if k == "top" else 0.01,
                    100.0,
                    "m",
                    "a length",
                    None,
                    "trapezoid only",
                    default_doc=f"{f:g} x height (rail_mbs::maneuvers)",
                )
                for k, f in _LIBRARY["trapezoid"].items()
            },  # fmt: skip
        },
        "maneuver:pulse": {
            "axis": _choice(("x", "y", "z"), "x", "direction of the pulse"),
            "acceleration": _num(-50.0, 50.0, "m/s^2", "an acceleration", 0.0, "pulse height"),
            "t1": _num(0.0, 1e4, "s", "a time", None, "end (> t0 + 2 ramp)", default_doc="solver.t_end", lo_open=True),
            "ramp": _num(1e-3, 10.0, "s", "a duration", 0.05, "linear ramps at both ends"),
        },
        "maneuver:samples": {
            ax: _value("[[t, a], ...] (s from 0 to 10000, m/s^2 from -50 to 50)", f"{ax} acceleration samples")
            for ax in ("x", "y", "z")
        },
    },
}
"""Every section (``name`` or ``name:variant`` for the keys of one tank shape or maneuver type) and
key of the two kinds of scene."""


def sections(kind: str) -> tuple[str, ...]:
    """The top-level sections of a ``"vehicle"`` or ``"slosh"`` scene (not the tables inside one,
    ``track.irregularities``)."""
    return tuple(s for s in SCHEMA[kind] if ":" not in s and "." not in s)


def section_keys(kind: str, name: str) -> tuple[str, ...]:
    """Every key of a section, over all its variants."""
    out = [k for s, fields in SCHEMA[kind].items() if s == name or s.startswith(name + ":") for k in fields]
    return tuple(dict.fromkeys(k for k in out if k != "*"))


def variant_keys(kind: str, name: str, variant: str) -> tuple[str, ...]:
    """The keys of one variant of a section (``"tank", "cylinder"``)."""
    return tuple(SCHEMA[kind][f"{name}:{variant}"])


def unknown_sections(data: Mapping[str, Any], kind: str) -> None:
    """Every section of a ``kind`` scene is one of its sections. A name no scene knows is named
    first, with the closest section name; then a section of the other kind of scene."""
    everything = {s for k in SCHEMA for s in sections(k)}
    for name in data:
        if name not in everything:
            raise unknown(str(name), "section", everything)
    own = sections(kind)
    for name in data:
        if name not in own:
            other = "vehicle scenes" if kind == "slosh" else "slosh scenes (those with a [maneuver] section)"
            raise ValueError(
                f"invalid `{name}`: expected one of the sections of a {kind} scene, {', '.join(sorted(own))}; "
                f"[{name}] belongs to {other}"
            )


def table(value: Any, field: str) -> Mapping[str, Any]:
    """A TOML table (section) with string keys."""
    if not isinstance(value, Mapping):
        raise invalid(field, value, "a table (section) of keys")
    for k in value:
        if not isinstance(k, str):
            raise invalid(field, k, "string keys")
    return value


def check_keys(values: Mapping[str, Any], name: str, allowed: Iterable[str]) -> None:
    """Every key of section ``name`` is one of ``allowed``; else the first unknown one is named
    with the closest allowed key."""
    allowed = tuple(allowed)
    for k in values:
        if k not in allowed:
            raise unknown(f"{name}.{k}", "key", allowed, prefix=f"{name}.")


_UNSET: Any = object()


class Section:
    """One section of a scene document, read through its rows of :data:`SCHEMA`: unknown keys are
    refused when it is made; :meth:`get` returns a key's value (or default) checked."""

    def __init__(self, kind: str, name: str, doc: Mapping[str, Any], extra: Iterable[str] = ()) -> None:
        self.kind, self.name = kind, name
        parts = name.split(".")  # a table inside a section: "track.irregularities"
        node: Any = doc.get(parts[0], {})
        for k, part in enumerate(parts[1:], 1):
            node = table(node, ".".join(parts[:k])).get(part, {})
        self.values = table(node, name)
        check_keys(self.values, name, (*section_keys(kind, name), *extra))

    def __contains__(self, key: str) -> bool:
        return key in self.values

    def __bool__(self) -> bool:
        return bool(self.values)

    def field(self, key: str, variant: str | None = None) -> Field:
        """The schema row of ``key`` (of ``variant`` when given)."""
        return SCHEMA[self.kind][self.name if variant is None else f"{self.name}:{variant}"][key]

    def get(self, key: str, default: Any = _UNSET, *, variant: str | None = None, **limits: Any) -> Any:
        """The checked value of ``key``, else its default (``None`` for keys without one: not
        set). ``limits``: ``lo``, ``hi``, ``note`` of ranges set by other fields."""
        f = self.field(key, variant)
        if key in self.values:
            value = self.values[key]
        else:
            value = f.default if default is _UNSET else default
            if value is None:
                return None
        return f.check(value, f"{self.name}.{key}", **limits)

    def only_with(self, keys: Iterable[str], condition: str) -> None:
        """Refuses any of ``keys`` given in this section: they are valid only under ``condition``."""
        for k in keys:
            if k in self.values:
                raise invalid(f"{self.name}.{k}", self.values[k], f"no `{self.name}.{k}` except {condition}")


def scoped(exc: Exception, section: str, *, prefix: bool = True) -> ValueError:
    """A model's error (e.g. of the compiled kernels) as a scene error: in the form of
    :func:`railslosh.limits.invalid`, its field put under ``section`` when ``prefix``
    (``viscosity`` -> ``fluid.viscosity``); a message naming no field is said of the section."""
    msg = str(exc)
    if not msg.startswith("invalid `"):
        return ValueError(f"invalid `{section}`: {msg}")
    if prefix:
        msg = re.sub(r"^invalid `([^`]+)`", rf"invalid `{section}.\1`", msg, count=1)
    return ValueError(msg)


def number_list(value: Any, field: str, limit: Limit, *, min_len: int = 1) -> list[float]:
    """A list of ``min_len`` to :data:`MAX_ROWS` numbers, each within ``limit``."""
    if not isinstance(value, list | tuple) or not min_len <= len(value) <= MAX_ROWS:
        raise invalid(field, value, f"a list of {min_len} to {MAX_ROWS} numbers")
    return [limit.check(x, f"{field}[{i}]") for i, x in enumerate(value)]


def increasing(xs: list[float], name: Callable[[int], str]) -> None:
    """Checks ``xs`` strictly increasing; ``name(i)`` is the dotted field of entry ``i``."""
    for i in range(1, len(xs)):
        if xs[i] <= xs[i - 1]:
            raise invalid(name(i), xs[i], f"strictly increasing values, > {xs[i - 1]!r}")


def counts(value: Any, field: str, limits: tuple[tuple[int, int], ...]) -> tuple[int, int, int]:
    """Three element counts ``[n_length, n_width, n_height]`` within ``limits``."""
    if not isinstance(value, list | tuple) or len(value) != 3:
        raise invalid(field, value, "three integers [n_length, n_width, n_height]")
    c = [Limit(lo, hi, noun="an element count", integer=True).check(x, f"{field}[{i}]") for i, (x, (lo, hi)) in
         enumerate(zip(value, limits, strict=True))]  # fmt: skip
    return c[0], c[1], c[2]


def triple(value: Any, field: str) -> list[Any]:
    """Three coordinates ``[x, y, z]`` (checked one by one by the caller)."""
    if not isinstance(value, list | tuple) or len(value) != 3:
        raise invalid(field, value, "three numbers [x, y, z] (m)")
    return list(value)


def merge(base: Mapping[str, Any], over: Mapping[str, Any]) -> dict[str, Any]:
    """``over`` merged into ``base`` table by table; a value ``None`` removes that key (TOML has
    no null)."""
    out = dict(base)
    for k, v in over.items():
        if v is None:
            out.pop(k, None)
        elif isinstance(v, Mapping) and isinstance(out.get(k), Mapping):
            out[k] = merge(out[k], v)
        else:
            out[k] = v
    return out


def reference() -> str:
    """``docs/scenes.md``: every section and key of :data:`SCHEMA` in Markdown."""
    out = [
        "# Scene files: every section and key",
        "",
        "Written from the schema table (`railslosh.scene.schema.SCHEMA`) by",
        "`python -m railslosh.scene > docs/scenes.md`; a test checks it is current. SI units unless a name",
        "says otherwise (`_kmh`, `_mph`, `_ft`, `_in`, `_percent`); frames and signs in `docs/frames.md`;",
        "the user guide (`docs/user-guide.md`) shows scenes at work. A vehicle scene needs `[track]`, a",
        "slosh scene `[maneuver]` with its `type`; every other key is optional unless its meaning says",
        "required. Limits marked with another field (≤ `solver.t_end`, ...) are narrowed by it. An error",
        "names the dotted field, its value and what is expected:",
        "",
        "```",
        "invalid `solver.t_end` = -1.0: expected a time > 0 s and ≤ 600 s",
        "invalid `manuever`: unknown section (did you mean `maneuver`?); expected one of fluid, maneuver, ...",
        "```",
        "",
        "A scene with a `[maneuver]` section is a prescribed-motion **slosh** scene (the tank moves as",
        "prescribed, `railslosh.slosh.run`); any other is a **vehicle** scene (tank cars on a track,",
        "`railslosh.vehicle.run`, with liquid cargo when it has a `[fluid]` section).",
    ]
    titles = {"vehicle": "Vehicle scenes", "slosh": "Slosh scenes (with `[maneuver]`)"}
    for kind, secs in SCHEMA.items():
        out += ["", f"## {titles[kind]}"]
        for name, fields in secs.items():
            base, _, variant = name.partition(":")
            what = {"tank": "shape", "maneuver": "type"}.get(base, "")
            title = f'`[{base}]` with {what} = `"{variant}"`' if variant else f"`[{base}]`"
            out += ["", f"### {title}", "", "| key | value | default | meaning |", "|---|---|---|---|"]
            for key, f in fields.items():
                default = f.default_doc or ("" if f.default is None else _toml(f.default))
                out.append(f"| `{key}` | {f.expected()} | {default} | {f.doc} |")
    return "\n".join(out) + "\n"


def _toml(value: Any) -> str:
    if isinstance(value, bool):
        return "`true`" if value else "`false`"
    if isinstance(value, str):
        return f'`"{value}"`'
    if isinstance(value, float):
        return f"`{value:.6g}`"
    return f"`{value!r}`"
