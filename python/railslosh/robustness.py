"""Robustness test matrix (formerly ``railslosh.stress``): many cheap runs over the extremes of
every input.

Each case either completes with finite results and a volume error <= 1 %, or stops with a
typed error naming its cause (:data:`CAUSES`) and keeps everything computed so far
(``SimulationError.results``), or is rejected up front with a ``ValueError`` naming the
field. Anything else -- a run that finishes with a volume error > 1 % or non-finite values,
an untyped exception, partial results that are empty or non-finite -- is a ``bug``.

    >>> from railslosh import robustness
    >>> table = robustness.run_matrix(robustness.cases("quick"))
    >>> table["counts"]            # {"ok": ..., "typed_error": ..., "rejected": ..., "bug": ...}

Command line: ``railslosh robustness [--full] [--json out.json] [--csv out.csv]`` (``stress`` is a
deprecated alias); the matrix and
the recorded counts are documented in docs/robustness.md.
"""

from __future__ import annotations

import csv
import dataclasses
import math
import time
from collections import Counter
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from railslosh.constants import GRAVITY
from railslosh.slosh import FAILURE_CAUSES, failure_cause

#: Failure causes and their message patterns (see :func:`railslosh.slosh.failure_cause`).
CAUSES = FAILURE_CAUSES

#: Relative volume error above which a completed run is a bug.
VOLUME_TOLERANCE = 0.01

G = GRAVITY


def classify(message: str) -> str:
    """Cause name of a failure message (``"unknown"`` if it names none of :data:`CAUSES`)."""
    return failure_cause(message)


@dataclass
class Case:
    """One run of the matrix: ``axis`` is the stressed input, ``value`` its setting."""

    axis: str
    value: Any
    kind: str  # "slosh", "vehicle" or "fluid_vehicle"
    kwargs: dict[str, Any] = field(default_factory=dict)

    @property
    def name(self) -> str:
        return f"{self.kind}:{self.axis}={self.value}"


# --- case builders -----------------------------------------------------------------------

_BOX = (0.416, 0.324)  # tank length, width (m): the SwRI rectangular tank of seed 003
_TANK_HEIGHT = 0.3


def _slosh(axis: str, value: Any, **kw: Any) -> Case:
    base = {
        "fill": 0.44,
        "viscosity": 1e-3,
        "yield_stress": 0.0,
        "power_index": 1.0,
        "penalty_factor": 1.0,
        "contact_factor": 1.0,
        "step": 0.01,
        "t_end": 0.25,
        "accel": (0.0, 0.3 * G, 0.0),
        "counts": (2, 3, 2),
        "frame": "inertial",
        "points": (3, 3, 3),  # viscous, penalty points per direction; contact points per face edge
    }
    base.update(kw)
    return Case(axis, value, "slosh", base)


def _vehicle(axis: str, value: Any, **kw: Any) -> Case:
    base = {"speed": 0.0, "t_end": 0.2, "step": 1e-3, "brake": None}
    base.update(kw)
    return Case(axis, value, "vehicle", base)


def _scene(name: str, t_end: float | None, **changes: Any) -> Case:
    """A shipped scene (``examples/scenes/<name>.toml``), shortened to ``t_end`` (``None``: as
    shipped), with :meth:`Scene.replace`-style ``changes`` (e.g. a slosh scene's quadrature)."""
    value = name if t_end is None else f"{name}@{t_end:g}s"
    if changes:
        value += "," + ",".join(f"{k}={v}" for k, v in sorted(changes.items()))
    return Case("scene", value, "scene", {"name": name, "t_end": t_end, "changes": changes})


def _fluid_vehicle(axis: str, value: Any, **kw: Any) -> Case:
    base = {"speed": 0.0, "t_end": 0.1, "step": 4e-3, "fill": 0.5, "counts": (2, 2, 1), "brake": None}
    base.update(kw)
    return Case(axis, value, "fluid_vehicle", base)


def _severe_brake(mass: float = 90e3) -> tuple[list[float], list[float]]:
    """Brake torque per wheelset that stops a loaded car from 120 km/h in 5 s (about 0.68 g)
    -- beyond adhesion, so the wheels slide."""
    from railslosh import vehicle

    return vehicle.design_brake_torque(mass, 120 / 3.6, 1 / 3.6, 5.0)


def cases(form: str = "quick") -> list[Case]:
    """The stress matrix: ``"quick"`` (CI, about a minute on 2 cores) or ``"full"`` (tens of
    minutes; shipped scenes run to their end)."""
    if form not in ("quick", "full"):
        raise ValueError(f"invalid `form` = {form!r}: expected 'quick' or 'full'")
    full = form == "full"
    out: list[Case] = []
    visc = [1e-3, 1e-1, 1e1, 1e3, 1e4] if full else [1e-3, 1e4]
    out += [_slosh("viscosity", v, viscosity=v) for v in visc]
    tau = [0.0, 1.0, 10.0, 100.0, 1e3] if full else [1e3]
    out += [_slosh("yield_stress", v, yield_stress=v, viscosity=0.1) for v in tau]
    n_idx = [0.3, 0.5, 0.8, 1.2, 1.5] if full else [0.3, 1.5]
    out += [_slosh("power_index", v, power_index=v, viscosity=0.1) for v in n_idx]
    fills = [0.1, 0.3, 0.5, 0.7, 0.9] if full else [0.1, 0.9]
    out += [_slosh("fill", v, fill=v) for v in fills]
    steps = [1e-5, 1e-4, 1e-3, 1e-2] if full else [1e-5, 1e-2]
    # Small steps: a fixed number of steps (300) rather than a fixed duration.
    out += [_slosh("time_step", v, step=v, t_end=min(0.25, 300 * v)) for v in steps]
    pen = [0.01, 0.1, 1.0, 10.0, 100.0] if full else [0.01, 100.0]
    out += [_slosh("penalty_factor", v, penalty_factor=v) for v in pen]
    out += [_slosh("contact_penalty_factor", v, contact_factor=v) for v in pen]
    # Severe braking of the tank alone: -1 g (quick) and up to -3 g (full) along x.
    brakes = [1.0, 2.0, 3.0] if full else [1.0]
    out += [_slosh("braking_g", v, accel=(-v * G, 0.0, 0.0), t_end=0.3) for v in brakes]
    if full:
        # Impacts (coupling, collision) far beyond braking: the penalty fluid then compresses
        # by more than the 1 % volume limit unless the penalty is raised.
        out += [_slosh("impact_g", v, accel=(-v * G, 0.0, 0.0), t_end=0.1) for v in (10.0, 30.0)]
        out.append(_slosh("impact_g", "30-penalty-x100", accel=(-30 * G, 0.0, 0.0), t_end=0.1, penalty_factor=100.0))
    if full:
        # Combined extremes.
        out.append(_slosh("combined", "viscous-low-fill-big-step", viscosity=1e4, fill=0.1, step=0.01))
        out.append(
            _slosh("combined", "bingham-full-soft", yield_stress=1e3, viscosity=0.1, fill=0.9, penalty_factor=0.01)
        )
        out.append(_slosh("mesh", "4x6x3", counts=(4, 6, 3), t_end=0.2))
    speeds = [0.0, 30.0, 60.0, 90.0, 120.0] if full else [0.0, 120.0]
    out += [_vehicle("speed_kmh", v, speed=v / 3.6) for v in speeds]
    out.append(_vehicle("braking", "severe-120kmh", speed=120 / 3.6, brake="severe", t_end=0.3 if full else 0.2))
    fv_fill = [0.1, 0.5, 0.9] if full else [0.9]
    out += [_fluid_vehicle("fill", v, fill=v) for v in fv_fill]
    out.append(_fluid_vehicle("speed_kmh", 120.0, speed=120 / 3.6))
    out.append(_fluid_vehicle("braking", "severe-120kmh", speed=120 / 3.6, brake="severe"))
    if full:
        out += [_fluid_vehicle("time_step", v, step=v) for v in (1e-3, 1e-2)]
    # Shipped scenes as a user runs them. Quick: the SwRI maneuvers shortened past the time at
    # which the liquid of the 2026-11-24 main had left its tank (about 1.4 s for the 40 mph lane
    # change, under 2 s for the bumps), also with the coarse 3x3x3 quadrature that let it.
    slosh_scenes = [n for n in shipped_scenes() if n.startswith("swri_")]
    if full:
        out += [_scene(n, None) for n in shipped_scenes()]
        out += [_scene(n, None, viscous_points=3, penalty_points=3, contact_points_per_edge=3) for n in slosh_scenes]
        # every slosh scene over the mesh quadrature, contact points and frames
        for n in slosh_scenes:
            for vp, cp in ((4, 5), (5, 4), (6, 4)):
                out.append(_scene(n, None, viscous_points=vp, penalty_points=vp, contact_points_per_edge=cp))
            out.append(_scene(n, None, frame="tank"))
        # a grid over the slosh inputs that interact (fill x mesh x lateral level x frame)
        for fill in (0.2, 0.5, 0.8):
            for counts in ((1, 2, 2), (2, 3, 2), (3, 6, 2)):
                for g in (0.1, 0.5, 1.0):
                    for frame in ("inertial", "tank"):
                        value = f"fill={fill},counts={counts},a={g}g,{frame}"
                        acc = (0.0, g * G, 0.0)
                        out.append(_slosh("grid", value, fill=fill, counts=counts, accel=acc, frame=frame, t_end=0.5))
        # rheology under a 1 g lateral load
        for mu in (1e-3, 1.0, 1e2):
            for tau in (0.0, 10.0, 1e3):
                out.append(
                    _slosh("rheology_1g", f"mu={mu},tau={tau}", viscosity=mu, yield_stress=tau, accel=(0.0, G, 0.0))
                )
        # quadrature and contact points
        for vp in (3, 4, 5, 6):
            for cp in (2, 4, 6):
                out.append(_slosh("points", f"{vp}^3,{cp}x{cp}", points=(vp, vp, cp), counts=(1, 2, 2)))
        # rigid vehicle: speed x step; severe braking of the fluid car from lower speeds
        for v in (30.0, 60.0, 90.0, 120.0):
            for step in (1e-3, 2e-3, 5e-3):
                out.append(_vehicle("speed_step", f"{v}kmh,{step}", speed=v / 3.6, step=step))
        for v in (60.0, 90.0):
            out.append(_fluid_vehicle("braking", f"severe-{v:g}kmh", speed=v / 3.6, brake="severe"))
        out += [_slosh("braking_g_tank_frame", v, accel=(-v * G, 0.0, 0.0), t_end=0.3, frame="tank") for v in brakes]
        # fluid vehicle: mesh x fill
        for counts in ((2, 2, 1), (3, 2, 2), (4, 2, 2)):
            for fill in (0.3, 0.5, 0.7):
                out.append(_fluid_vehicle("mesh_fill", f"counts={counts},fill={fill}", counts=counts, fill=fill))
    else:
        out += [_scene(n, 1.5) for n in ("swri_lane_change_40mph", "swri_bump_trapezoid_9in_15mph")]
        out.append(_scene("swri_lane_change_40mph", 1.5, viscous_points=3, penalty_points=3, contact_points_per_edge=3))
    return out


def shipped_scenes() -> list[str]:
    """Names of the scenes in ``examples/scenes`` (next to the package in a source tree), sorted;
    empty when the folder is not there (an installed wheel without the repository)."""
    d = _scenes_dir()
    return sorted(p.stem for p in d.glob("*.toml")) if d is not None else []


def _scenes_dir() -> Any:
    from pathlib import Path

    for base in (Path(__file__).resolve().parents[2], Path.cwd()):
        d = base / "examples" / "scenes"
        if d.is_dir():
            return d
    return None


# --- running ------------------------------------------------------------------------------


def _fluid(kw: dict[str, Any], depth: float):
    from railslosh import fluids

    rho = fluids.LIQUIDS["water"][0]
    k = kw["penalty_factor"] * fluids.default_bulk_penalty(rho, depth)
    mu, tau, n = kw["viscosity"], kw["yield_stress"], kw["power_index"]
    if n != 1.0 or tau > 0.0:
        # by keyword: the positional order is (density, consistency, power_index, yield_stress)
        return fluids.herschel_bulkley(
            rho, consistency=mu, power_index=n, yield_stress=tau, depth=depth, bulk_penalty=k
        )
    return fluids.newtonian(rho, mu, depth=depth, bulk_penalty=k)


def _run_slosh(kw: dict[str, Any]) -> tuple[dict[str, Any], float]:
    """Returns (results, relative volume error of the last recorded state)."""
    from railslosh import mesh, slosh

    lx, ly = _BOX
    depth = kw["fill"] * _TANK_HEIGHT
    fluid = _fluid(kw, depth)
    m = mesh.box((lx, ly, depth), kw["counts"])
    tank = slosh.TankGeometry.box((-lx / 2, -ly / 2, 0.0), (lx / 2, ly / 2, _TANK_HEIGHT))
    motion = slosh.Motion()
    for axis, a in zip("xyz", kw["accel"], strict=True):
        if a != 0.0:
            motion.pulse(axis, a, 0.0, 10.0, ramp=0.02)
    vp, pp, cp = kw["points"]
    res = slosh.run(
        m,
        fluid,
        tank,
        motion,
        t_end=kw["t_end"],
        step=kw["step"],
        frame=kw["frame"],
        contact_stiffness_factor=kw["contact_factor"],
        viscous_points=vp,
        penalty_points=pp,
        contact_points_per_edge=cp,
    )
    return res, _slosh_volume_error(res)


def _slosh_volume_error(res: dict[str, Any]) -> float:
    vol = np.asarray(res["volume"])
    return float(np.max(np.abs(vol / vol[0] - 1.0))) if len(vol) else math.nan


def _brake(kw: dict[str, Any], mass: float) -> tuple[list[float], list[float]] | None:
    return _severe_brake(mass) if kw["brake"] == "severe" else None


def _run_vehicle(kw: dict[str, Any]) -> tuple[dict[str, Any], float]:
    from railslosh import rail, vehicle

    track = rail.Track([0.0, 5000.0], curvature=[0.0, 0.0], superelevation=[0.0, 0.0])
    brake = _brake(kw, 90e3)
    drive = brake is None
    res = vehicle.run(
        track, speed=kw["speed"], drive=drive, brake=brake, t_end=kw["t_end"], step=kw["step"], lading_mass=60e3
    )
    return res, 0.0


def _run_fluid_vehicle(kw: dict[str, Any]) -> tuple[dict[str, Any], float]:
    from railslosh import rail, vehicle

    track = rail.Track([0.0, 5000.0], curvature=[0.0, 0.0], superelevation=[0.0, 0.0])
    brake = _brake(kw, 90e3)
    res = vehicle.run_fluid(
        track,
        speed=kw["speed"],
        drive=brake is None,
        brake=brake,
        t_end=kw["t_end"],
        step=kw["step"],
        fill=kw["fill"],
        counts=kw["counts"],
        oil="water",
    )
    return res, _fluid_vehicle_volume_error(res)


def _fluid_vehicle_volume_error(res: dict[str, Any]) -> float:
    ve = np.asarray(res.get("volume_error", []), dtype=float)
    return float(np.max(np.abs(ve))) if ve.size else 0.0


def _run_scene(kw: dict[str, Any]) -> tuple[dict[str, Any], float]:
    from railslosh import scene

    d = _scenes_dir()
    if d is None:
        raise ValueError("invalid `scene`: expected a shipped scene (examples/scenes not found)")
    sc = scene.load_scene(d / f"{kw['name']}.toml")
    changes = dict(kw["changes"])
    if kw["t_end"] is not None:
        changes["t_end"] = min(sc.t_end, kw["t_end"])
    if changes:
        sc = dataclasses.replace(sc, **changes)
    res = scene.run_scene(sc)
    err = _slosh_volume_error(res) if sc.kind == "slosh" else _fluid_vehicle_volume_error(res)
    return res, err


_RUNNERS: dict[str, Callable[[dict[str, Any]], tuple[dict[str, Any], float]]] = {
    "slosh": _run_slosh,
    "vehicle": _run_vehicle,
    "fluid_vehicle": _run_fluid_vehicle,
    "scene": _run_scene,
}


def silent_failure(res: dict[str, Any]) -> str:
    """An independent check of a run that finished without an error, from its recorded outputs
    only (not the run's own invariant checks): the liquid's centre of mass stays inside its tank
    at every sample, and the recorded energy growth stays within 5 %. Returns what is wrong, or
    ``""``."""
    sc = res.get("scene")
    com = res.get("com_tank", res.get("oil_com_tank"))
    if com is not None and sc is not None:
        com = np.asarray(com, dtype=float).reshape(len(res["t"]), -1, 3)
        inside = _inside_tank(sc, com)
        if not inside.all():
            i = int(np.argmin(inside.all(axis=1)))
            return f"centre of mass outside the tank at t = {float(res['t'][i]):.3f} s: {com[i].round(4).tolist()}"
    eps = res.get("energy_error")
    if eps is not None and len(eps) and not np.nanmax(np.asarray(eps, dtype=float)) <= 0.05:
        return f"energy grew by {float(np.nanmax(eps)):.3g} of its scale"
    return ""


def _inside_tank(sc: Any, com: np.ndarray) -> np.ndarray:
    """Whether each tank-frame point (..., 3) lies inside the scene's tank (1 mm slack)."""
    x, y, z = com[..., 0], com[..., 1], com[..., 2]
    tank = getattr(sc, "tank", None)
    if tank is None or not hasattr(tank, "shape"):  # vehicle scene: the car's cylindrical tank
        r = sc.tank_radius() if hasattr(sc, "tank_radius") else np.inf
        return np.hypot(y, z) <= r + 1e-3
    d = list(tank.dims)
    if tank.shape == "elliptic":
        return ((y / d[1]) ** 2 + (z / d[2]) ** 2 <= 1.0 + 1e-3) & (np.abs(x) <= d[0] / 2 + 1e-3)
    if tank.shape == "cylinder":
        return (np.hypot(y, z) <= d[1] + 1e-3) & (np.abs(x) <= d[0] / 2 + d[2] + 1e-3)
    lo, hi = np.asarray(d[:3]), np.asarray(d[3:])
    return np.all((com >= lo - 1e-3) & (com <= hi + 1e-3), axis=-1)


def _arrays_finite(res: dict[str, Any]) -> tuple[bool, str]:
    """Whether every float array in the results is finite; names the first that is not."""
    for key, val in res.items():
        if key in ("stats", "error", "snapshots"):
            continue
        arr = np.asarray(val) if isinstance(val, (np.ndarray, list, tuple)) else None
        if arr is not None and arr.dtype.kind == "f" and not np.all(np.isfinite(arr)):
            return False, key
    return True, ""


def _samples(res: dict[str, Any]) -> int:
    t = res.get("t")
    return len(t) if t is not None else 0


def run_case(case: Case) -> dict[str, Any]:
    """Runs one case and classifies it (see the module docs). Never raises for a failed run."""
    from railslosh.slosh import SimulationError

    row: dict[str, Any] = {"case": case.name, "kind": case.kind, "axis": case.axis, "value": str(case.value)}
    t0 = time.perf_counter()
    try:
        res, vol_err = _RUNNERS[case.kind](case.kwargs)
        finite, bad = _arrays_finite(res)
        row.update(t_reached=float(res["t"][-1]), samples=_samples(res), volume_error=vol_err)
        silent = silent_failure(res)
        if not finite:
            row.update(outcome="bug", cause="non_finite_without_error", message=f"`{bad}` not finite")
        elif not vol_err <= VOLUME_TOLERANCE:
            row.update(outcome="bug", cause="volume_error_without_error", message=f"volume error {vol_err:.3%}")
        elif silent:
            row.update(outcome="bug", cause="silent_failure", message=silent)
        else:
            row.update(outcome="ok", cause="", message="")
    except SimulationError as exc:
        res = exc.results
        finite, bad = _arrays_finite(res)
        cause = classify(str(exc))
        row.update(t_reached=float(res["t"][-1]) if _samples(res) else math.nan, samples=_samples(res))
        slosh_like = case.kind == "slosh" or "com_tank" in res
        row["volume_error"] = (
            _slosh_volume_error(res) if slosh_like and _samples(res) else _fluid_vehicle_volume_error(res)
        )
        row["message"] = str(exc)
        if cause == "unknown" or _samples(res) == 0 or not finite:
            why = "unclassified error" if cause == "unknown" else "partial results empty or not finite"
            row.update(outcome="bug", cause=f"{cause}: {why}")
        else:
            row.update(outcome="typed_error", cause=cause)
    except ValueError as exc:
        row.update(outcome="rejected", cause="invalid_input", message=str(exc), t_reached=math.nan, samples=0)
        row["volume_error"] = math.nan
    except Exception as exc:  # noqa: BLE001 -- any other exception type is a bug by definition
        row.update(outcome="bug", cause=type(exc).__name__, message=str(exc), t_reached=math.nan, samples=0)
        row["volume_error"] = math.nan
    row["wall_s"] = round(time.perf_counter() - t0, 3)
    return row


def run_matrix(matrix: Iterable[Case], progress: Callable[[dict[str, Any]], None] | None = None) -> dict[str, Any]:
    """Runs every case; returns ``{"rows": [...], "counts": {...}, "causes": {...}}``."""
    rows = []
    for case in matrix:
        row = run_case(case)
        rows.append(row)
        if progress is not None:
            progress(row)
    counts = Counter(r["outcome"] for r in rows)
    causes = Counter(r["cause"] for r in rows if r["cause"])
    by_axis: dict[str, dict[str, int]] = {}
    for r in rows:
        by_axis.setdefault(f"{r['kind']}:{r['axis']}", Counter())[r["outcome"]] += 1
    return {
        "rows": rows,
        "counts": {k: counts.get(k, 0) for k in ("ok", "typed_error", "rejected", "bug")},
        "causes": dict(causes),
        "by_axis": {k: dict(v) for k, v in by_axis.items()},
    }


COLUMNS = (
    "case",
    "kind",
    "axis",
    "value",
    "outcome",
    "cause",
    "t_reached",
    "samples",
    "volume_error",
    "wall_s",
    "message",
)


def write_csv(table: dict[str, Any], path: str) -> None:
    """One row per case, columns :data:`COLUMNS`."""
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS, extrasaction="ignore")
        w.writeheader()
        for r in table["rows"]:
            w.writerow(r)


def _cmd_stress(args: Any) -> int:
    import json
    import sys

    def show(r: dict[str, Any]) -> None:
        msg = f"  {r['message'][:160]}" if r["message"] else ""
        print(f"{r['case']:48s} {r['outcome']:12s} {r['cause']:22s} {r['wall_s']:7.2f} s{msg}", file=sys.stderr)

    table = run_matrix(cases("full" if args.full else "quick"), progress=show)
    if args.csv:
        write_csv(table, args.csv)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(table, f, indent=1, default=str)
    print(json.dumps({"counts": table["counts"], "causes": table["causes"], "by_axis": table["by_axis"]}, indent=1))
    return 1 if table["counts"]["bug"] else 0


def add_subparser(sub: Any) -> None:
    """Registers ``railslosh robustness`` (alias ``stress``, deprecated) on an argparse sub-parser
    collection."""
    s = sub.add_parser(
        "robustness",
        aliases=["stress"],
        help="robustness test matrix: outcome counts (exit 1 if any run is a bug); 'stress' is a deprecated alias",
    )
    s.add_argument("--full", action="store_true", help="the full matrix (minutes) instead of the quick CI form")
    s.add_argument("--json", metavar="PATH", help="write every row and the counts as JSON")
    s.add_argument("--csv", metavar="PATH", help="write one CSV row per case")
    s.set_defaults(func=_cmd_stress)
