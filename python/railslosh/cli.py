"""The ``railslosh`` command-line tool: ``demo``, ``run``, ``plot``, ``report``, ``sweep``,
``validate``, ``bench`` and ``robustness`` (:func:`main`, :func:`build_parser`).

A user's mistake (a bad path, scene field, ``--set`` or ``--grid`` value) is one line on stderr,
in the form of :mod:`railslosh.limits` (``railslosh run: invalid `train.t_end` = -1.0: expected a
time > 0 s and ≤ 600 s``), and exit status 2; never a traceback.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

import railslosh as rs
from railslosh import (
    __version__,
    bench,
    fluid_model,
    limits,
    plots,
    report,
    results,
    robustness,
    scene,
    sweep,
    validate,
)
from railslosh._core import RailsloshError
from railslosh.constants import GRAVITY
from railslosh.progress import ProgressBar
from railslosh.scene.run import MIRROR_LOAD_LIMIT as _MIRROR_LOAD_LIMIT
from railslosh.slosh import SimulationError

_DESCRIPTION = """\
railslosh: liquid sloshing in rail tank cars, coupled with the vehicle dynamics.

Run a scene file (TOML), plot its results, write an HTML report, sweep a parameter
grid, or check the physics against the validation cases. Scene keys and their limits:
docs/scenes.md; the user guide: docs/user-guide.md."""

_EXAMPLES = """\
examples:
  railslosh demo                              the crude-oil tank car, built and checked (seconds)
  railslosh run examples/scenes/crude_ecp_braking_light.toml -o out/ecp --t-end 1
  railslosh run examples/scenes/crude_curve_60kmh.toml --set fluid.oil=heavy --set fluid.fill=0.7
  railslosh plot out/ecp/results.nc
  railslosh report out/ecp
  railslosh sweep examples/scenes/crude_ecp_braking_light.toml --grid oil=light,heavy --grid fill=0.5,0.7
  railslosh validate --list
  railslosh validate element-mass hydrostatic-cylinder --quick

Each command has its own help, e.g. railslosh run --help. Exit status: 0 done, 1 a run or
check failed, 2 bad input (one line on stderr saying which field and what it expects)."""


def _cmd_validate(args: argparse.Namespace) -> int:
    if args.list:
        for c in validate.CASES.values():
            print(f"{c.name:28s} {c.description}")
        return 0
    skipped: list[dict[str, str]] = []
    records = validate.run(args.cases, quick=args.quick, skipped=skipped)  # a bad case name: main says so
    failed = [r for r in records if not r["passed"]]
    # Cases without their external data are reported as skipped; they do not fail the run.
    for s in skipped:
        print(f"railslosh validate: {s['reason']}", file=sys.stderr)
    if args.json:
        json.dump(
            {"records": records, "passed": len(records) - len(failed), "failed": len(failed), "skipped": skipped},
            sys.stdout,
            indent=1,
        )
        print()
    else:
        for r in records:
            print(json.dumps(r))
        extra = f", {len(skipped)} cases skipped" if skipped else ""
        print(f"validate: {len(records) - len(failed)} checks passed, {len(failed)} failed{extra}", file=sys.stderr)
    return 1 if failed else 0


def _cmd_bench(args: argparse.Namespace) -> int:
    if args.list:
        for c in bench.cases():
            print(c)
        return 0
    t0 = time.perf_counter()
    points = bench.run(args.cases, quick=args.quick)
    paths = bench.write(points, args.output, plot=not args.no_plot)
    for r in bench.rows(points):
        errs = ", ".join(f"{k[6:]} {v:.3g}" for k, v in r.items() if k.startswith("error_") and isinstance(v, float))
        tag = "reference" if r["reference"] else ("FAILED: " + r["failure"] if r["failure"] else "")
        print(f"{r['case']:12s} wall {r['wall_s']:8.2f} s  {errs}  {tag}")
    print(f"bench: {len(points)} points in {time.perf_counter() - t0:.1f} s; wrote {', '.join(map(str, paths))}")
    return 0


def _cmd_demo(args: argparse.Namespace) -> int:
    print("railslosh demo: the crude-oil tank car of Grossi & Shabana (2018), seed 000 §8")
    mesh = rs.mesh.cylinder_tank(fill=args.fill, n_length=6, n_width=4, n_height=2)
    depth = mesh.free_surface_z + rs.mesh.TANK_CAR_RADIUS
    oil = rs.fluids.crude_oil(args.oil, depth=depth)
    body = rs.FluidBody(mesh, oil)
    m_exact = oil.density * mesh.exact_volume
    print(
        f"  tank: shell {rs.mesh.TANK_CAR_SHELL_LENGTH} m, radius {rs.mesh.TANK_CAR_RADIUS} m, "
        f"heads {rs.mesh.TANK_CAR_HEAD_DEPTH} m, fill {args.fill:.0%} by volume, liquid depth {depth:.3f} m"
    )
    print(f"  paper mesh: {mesh.n_elements} ANCF bricks, {mesh.n_nodes} nodes, {mesh.n_coords} coordinates")
    print(
        f"  fluid: {args.oil} crude, {oil.model}, rho = {oil.density} kg/m^3, "
        f"tau0 = {oil.yield_stress} Pa, k_IC = {oil.bulk_penalty:.3g} Pa"
    )
    print(
        f"  oil mass: {body.total_mass:.1f} kg (rho V_exact = {m_exact:.1f} kg, "
        f"{100 * (body.total_mass / m_exact - 1):+.3f} % geometric discretization error)"
    )

    # braking: the car decelerates at 0.1 g (about 40 -> 5 km/h in 10 s) from t = 0.2 s
    run_mesh = rs.mesh.cylinder_tank(fill=args.fill, n_length=args.n_length, n_width=2, n_height=2)
    tank = rs.slosh.TankGeometry.cylinder(
        rs.mesh.TANK_CAR_SHELL_LENGTH, rs.mesh.TANK_CAR_RADIUS, rs.mesh.TANK_CAR_HEAD_DEPTH
    )
    motion = rs.slosh.Motion().pulse("x", -0.1 * GRAVITY, 0.2, 100.0, ramp=0.2)
    print(
        f"  braking run: -0.1 g from t = 0.2 s for {args.t_end} s, {run_mesh.n_elements} bricks "
        f"({run_mesh.n_coords} coordinates), HHT, penalty wall contact"
    )
    t0 = time.perf_counter()
    res = rs.slosh.run(run_mesh, oil, tank, motion, t_end=args.t_end, step=0.01)
    wall = time.perf_counter() - t0
    m = rs.FluidBody(run_mesh, oil).total_mass
    fx = res["force_tank"][:, 0]
    com = res["com_tank"]
    st = res["stats"]
    print(
        f"    peak longitudinal load on the tank: {np.abs(fx).max() / 1e3:.1f} kN = "
        f"{np.abs(fx).max() / (m * 0.981):.2f} x the quasi-static m*0.1g"
    )
    print(f"    oil centre of mass moved forward by {1e3 * (com[:, 0].max() - com[0, 0]):.1f} mm (tank frame)")
    print(
        f"    volume change {100 * (res['volume'][-1] / res['volume'][0] - 1):+.3f} %, "
        f"max wall penetration {1e3 * res['max_penetration'].max():.2f} mm"
    )
    print(
        f"    {st['steps']} steps, {st['newton_iterations'] / max(st['steps'], 1):.1f} Newton iterations/step, "
        f"{wall:.1f} s wall ({args.t_end / wall:.3f} simulated s per wall s)"
    )
    print("  quick element validation:")
    records = validate.run(["element-mass", "element-jacobians", "rigid-motion-invariance"], quick=True)
    failed = [r for r in records if not r["passed"]]
    for r in records:
        mark = "ok  " if r["passed"] else "FAIL"
        print(f"    {mark} {r['case']}: {r['quantity']}: {r['measured']:.6g} (ref {r['reference']:.6g})")
    print(f"  {len(records) - len(failed)} checks passed, {len(failed)} failed")
    print("  more: railslosh validate --list; sloshing cases: railslosh validate hydrostatic-cylinder --quick")
    return 1 if failed else 0


# --- run / plot / report / sweep -------------------------------------------------------------------


def _cmd_run(args: argparse.Namespace) -> int:
    over = scene.parse_overrides(args.set)
    doc = scene.read_scene(args.scene)
    sc = scene.load_scene(doc, over or None)
    if args.t_end is not None:
        over.setdefault("solver" if sc.kind == "slosh" else "train", {})["t_end"] = args.t_end
        sc = scene.load_scene(doc, over)
    if args.set and "name" not in over.get("scene", {}):
        # the title of the plots, the report and results.nc says what was changed: "ECP braking, light
        # crude" run with --set fluid.oil=heavy is not the light crude
        sc = dataclasses.replace(sc, name=f"{sc.name or Path(args.scene).stem} [{', '.join(args.set)}]")
    out = _out_dir(args.out, Path("out") / Path(args.scene).stem)
    print(f"railslosh run: {sc.name or Path(args.scene).stem} ({sc.kind}, t_end = {sc.t_end:g} s) -> {out}")
    if sc.kind != "slosh":
        choice = fluid_model.decide(sc)
        print(f"  fluid model: {choice.model} ({choice.reason})")
    bar = None if args.quiet else ProgressBar(description=sc.name or Path(args.scene).stem)
    status = 0
    t0 = time.perf_counter()
    try:
        res = scene.run_scene(
            sc,
            progress=bar,
            checkpoint=args.checkpoint,
            checkpoint_every=args.checkpoint_every,
            resume_from=args.resume_from,
        )
    except SimulationError as exc:
        if bar is not None:
            bar.close()
        print(f"\nrailslosh run: {exc}", file=sys.stderr)
        res = dict(exc.results)
        res["scene"] = sc
        status = 1
    except KeyboardInterrupt:
        if bar is not None:
            bar.close()
        again = f"; continue it with --resume-from {args.checkpoint}" if args.checkpoint else ""
        print(f"\nrailslosh run: interrupted{again}", file=sys.stderr)
        return 130
    wall = time.perf_counter() - t0
    ds = results.to_dataset(res, sc)
    written = []
    if sc.outputs.netcdf:
        written.append(results.save(ds, out / "results.nc"))
    if sc.outputs.plots:
        written.extend(plots.plot_dataset(ds, out / "plots"))
    if sc.outputs.vtu and res.get("snapshots"):
        pvd = results.write_vtu(res, out, res["connectivity"])
        if pvd is not None:
            written.append(pvd)
    st = res.get("stats") or {}
    summary = {
        "scene": str(args.scene),
        "kind": sc.kind,
        "t_end": sc.t_end,
        "t_reached": float(res["t"][-1]) if len(res["t"]) else 0.0,
        "wall_time": wall,
        "stats": dict(st),
        "error": res.get("error"),
        "margins": res.get("margins"),
    }
    if args.resume_from:  # a continued run: its results start at the checkpoint
        summary["resumed_from"] = {"file": str(args.resume_from), "t": float(res["t"][0]) if len(res["t"]) else None}
    # the model and largest step the run used (run_scene records them, also on a failed run)
    keys = ("fluid_model", "fluid_model_reason", "step", "step_reason", "stepper", "stepper_reason")
    summary |= {k: res[k] for k in keys if k in res}
    if res.get("irregularity") is not None:  # the track irregularity: where it came from, its RMS per channel
        summary["irregularity"] = res["irregularity"].summary()
    mirror = res.get("mirror_symmetry")
    if mirror is not None:  # liquid on mirror-symmetric inputs: how far its lateral load strays from 0
        summary["mirror_symmetry"] = mirror
    (out / "run.json").write_text(json.dumps(summary, indent=1, default=str), encoding="utf-8")
    print(
        f"  {st.get('steps', 0)} steps, {st.get('newton_iterations', 0)} Newton iterations, "
        f"{st.get('rejected_steps', 0)} rejected, {wall:.1f} s wall"
    )
    for p in written:
        print(f"  wrote {p}")
    if mirror is not None and mirror["lateral_valid_until"] is not None:
        print(
            f"  warning: the inputs are mirror-symmetric, so the liquid's lateral load should stay 0; it exceeds "
            f"{mirror['limit']:.3g} N ({_MIRROR_LOAD_LIMIT:g} of the liquid's weight) "
            f"from t = {mirror['lateral_valid_until']:.3g} s "
            f"and reaches {mirror['worst_lateral_load']:.3g} N at {mirror['worst_time']:.3g} s: the lateral channels "
            "after that time are discretization error (run.json `mirror_symmetry`; docs/validation.md, "
            '"The ECP scenes\' lateral channels")',
            file=sys.stderr,
        )
    print(f"  next: railslosh report {out}")
    return status


def _out_dir(given: str | None, default: Path) -> Path:
    """The output directory (``-o``), made if needed."""
    out = Path(given) if given else default
    if out.exists() and not out.is_dir():
        raise limits.invalid("--out", str(out), "a directory for the results (this is a file)")
    out.mkdir(parents=True, exist_ok=True)
    return out


_NETCDF_MAGIC = (b"CDF\x01", b"CDF\x02", b"CDF\x05", b"\x89HDF\r\n\x1a\n")


def _results_file(path: Path, field: str) -> Path:
    """``path`` if it is a netCDF file (classic or netCDF-4 signature), else the error naming
    ``field``."""
    expected = "a results.nc written by `railslosh run`"
    if not path.exists():
        raise FileNotFoundError(f"invalid `{field}` = {str(path)!r}: no such file; expected {expected}")
    if path.is_dir():
        raise IsADirectoryError(f"invalid `{field}` = {str(path)!r}: a directory; expected {expected}")
    with path.open("rb") as f:
        head = f.read(8)
    if not head.startswith(_NETCDF_MAGIC):
        raise limits.invalid(field, str(path), f"{expected} (this is not a netCDF file)")
    return path


def _load_results(path: Path, field: str) -> Any:
    _results_file(path, field)
    try:
        return results.load(path)
    except OSError as exc:  # a damaged file with a netCDF signature
        raise limits.invalid(field, str(path), f"a readable netCDF file ({exc.strerror or exc})") from exc


def _cmd_plot(args: argparse.Namespace) -> int:
    src = Path(args.results)
    ds = _load_results(src, "results")
    if "time" not in ds.dims or "sweep_dims" in ds.attrs:
        raise limits.invalid("results", str(src), "the results of one run (`railslosh run`), not of a sweep")
    paths = plots.plot_dataset(ds, Path(args.out) if args.out else src.parent / "plots")
    for p in paths:
        print(f"wrote {p}")
    return 0 if paths else 1


def _cmd_report(args: argparse.Namespace) -> int:
    d = Path(args.results_dir)
    if not d.is_dir():
        what = "a file" if d.exists() else "no such directory"
        raise limits.invalid("results_dir", str(d), f"a directory written by `railslosh run` ({what})")
    _results_file(d / "results.nc", "results_dir/results.nc")
    p = report.write_report(d, args.out)
    print(f"wrote {p}")
    return 0


def _cmd_sweep(args: argparse.Namespace) -> int:
    grid = sweep.parse_grid(args.grid)
    over = scene.parse_overrides(args.set)
    base = scene.read_scene(args.scene)
    sweep.sweep_points(base, grid, over or None)  # every point checked before anything is said or run
    n = math.prod(len(v) for v in grid.values())
    where = args.scheduler or f"a local Dask cluster ({args.workers or 'all'} workers)"
    print(f"railslosh sweep: {n} runs of {args.scene} on {where}")
    t0 = time.perf_counter()

    def done(k: int, total: int) -> None:
        print(f"  {k}/{total} runs done, {time.perf_counter() - t0:.1f} s", file=sys.stderr, flush=True)

    ds = sweep.run_sweep(
        base,
        grid,
        overrides=over or None,
        scheduler=args.scheduler,
        workers=args.workers,
        processes=args.processes,
        on_done=done,
    )
    out = _out_dir(args.out, Path("out") / f"sweep_{Path(args.scene).stem}")
    p = results.save(ds, out / "sweep.nc")
    print(f"  wrote {p} (dims: {dict(ds.sizes)})")
    failed = [str(e) for e in ds["error"].values.ravel() if e]
    for e in failed:
        print(f"  failed: {e}", file=sys.stderr)
    return 1 if failed else 0


# --- the parser -------------------------------------------------------------------------------------


def _fill(text: str) -> float:
    """``--fill``: a volume fraction within :data:`railslosh.limits.FILL`."""
    try:
        return limits.check("fill", float(text), "--fill")
    except ValueError as exc:
        raise argparse.ArgumentTypeError(f"{text!r}: expected {limits.FILL.expected()}") from exc


def _positive_int(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: expected a whole number ≥ 1")
    return n


def _positive_float(text: str) -> float:
    try:
        x = float(text)
    except ValueError:
        x = math.nan
    if not (math.isfinite(x) and x > 0):
        raise argparse.ArgumentTypeError(f"{text!r}: expected a number > 0")
    return x


def _command(sub: Any, name: str, help: str, description: str, examples: str) -> argparse.ArgumentParser:
    return sub.add_parser(
        name,
        help=help,
        description=description,
        epilog="examples:\n" + examples,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )


_SET_HELP = (
    "override a scene field, e.g. --set train.t_end=0.5 or --set 'mesh.counts=[3,2,2]' (a TOML value; "
    "repeat --set for more fields)"
)


def _add_demo(sub: Any) -> None:
    """``railslosh demo``."""
    d = _command(
        sub,
        "demo",
        "build the crude-oil tank car model, run a short braking case and check it",
        "Builds the tank car of Grossi & Shabana (2018), prints its mesh and oil, runs a braking\n"
        "case (-0.1 g from t = 0.2 s) and three quick element checks. Takes a few seconds.",
        "  railslosh demo\n  railslosh demo --oil heavy --fill 0.7 --t-end 1",
    )
    d.add_argument(
        "--oil",
        default="light",
        choices=["light", "medium", "heavy"],
        help="crude oil of seed 000 Table 2 (default: light)",
    )
    d.add_argument(
        "--fill",
        type=_fill,
        default=0.5,
        help=f"liquid volume fraction of the tank, {limits.FILL.lo:g} to {limits.FILL.hi:g} (default: 0.5)",
    )
    d.add_argument(
        "--n-length", type=_positive_int, default=6, help="elements along the tank in the braking run (default: 6)"
    )
    d.add_argument(
        "--t-end", type=_positive_float, default=2.0, help="simulated time of the braking run, s (default: 2)"
    )
    d.set_defaults(func=_cmd_demo)


def _add_run(sub: Any) -> None:
    """``railslosh run``."""
    r = _command(
        sub,
        "run",
        "run a scene file (TOML) and write results, plots, ParaView files",
        "Runs a scene and writes results.nc, run.json, plots/ and (fluid snapshots) fluid.pvd to the\n"
        "output directory; a progress line shows the simulated time and the ETA. Every key of a\n"
        "scene and its limits: docs/scenes.md. The shipped scenes run from seconds (rigid lading) to\n"
        "several minutes (the paper's 10.5 s ECP braking with ANCF oil); --t-end shortens a run.",
        "  railslosh run examples/scenes/two_car_ecp_braking_rigid.toml\n"
        "  railslosh run examples/scenes/crude_ecp_braking_light.toml -o out/ecp --t-end 1\n"
        "  railslosh run examples/scenes/crude_curve_60kmh.toml --set fluid.oil=heavy --set fluid.fill=0.7\n"
        "  railslosh run examples/scenes/crude_ecp_braking_light.toml --checkpoint out/ecp.ckpt   (Ctrl-C, then)\n"
        "  railslosh run examples/scenes/crude_ecp_braking_light.toml --resume-from out/ecp.ckpt -o out/ecp_rest",
    )
    r.add_argument("scene", help="scene file, e.g. examples/scenes/crude_ecp_braking_light.toml")
    r.add_argument("-o", "--out", help="output directory (default: out/<scene name>)")
    r.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE", help=_SET_HELP)
    r.add_argument("--t-end", type=_positive_float, help="override the simulated time, s (train.t_end or solver.t_end)")
    r.add_argument("-q", "--quiet", action="store_true", help="no progress line")
    r.add_argument(
        "--checkpoint", metavar="FILE", help="keep the run's whole state in FILE as it goes (replaced atomically)"
    )
    r.add_argument(
        "--checkpoint-every",
        type=_positive_int,
        default=50,
        metavar="N",
        help="recorded samples between two checkpoints (default 50)",
    )
    r.add_argument(
        "--resume-from",
        metavar="FILE",
        help="continue the same scene from a checkpoint; the results start there, bit for bit the uninterrupted run's",
    )
    r.set_defaults(func=_cmd_run)


def _add_plot_and_report(sub: Any) -> None:
    """``railslosh plot`` and ``railslosh report``."""
    pl = _command(
        sub,
        "plot",
        "PNG plots of a results.nc file",
        "Plots the main time series of one run's results.nc (loads, wheel loads, L/V, ...).",
        "  railslosh plot out/ecp/results.nc\n  railslosh plot out/ecp/results.nc -o figures",
    )
    pl.add_argument("results", help="results.nc written by `railslosh run`")
    pl.add_argument("-o", "--out", help="directory of the PNGs (default: plots/ next to the file)")
    pl.set_defaults(func=_cmd_plot)

    rp = _command(
        sub,
        "report",
        "self-contained HTML report of a results directory",
        "Writes one HTML file with the scene, the solver statistics, peak values and the figures of a\n"
        "directory written by `railslosh run`.",
        "  railslosh report out/ecp\n  railslosh report out/ecp -o ecp.html",
    )
    rp.add_argument("results_dir", help="directory written by `railslosh run` (holds results.nc)")
    rp.add_argument("-o", "--out", help="HTML file (default: results_dir/report.html)")
    rp.set_defaults(func=_cmd_report)


def _add_sweep(sub: Any) -> None:
    """``railslosh sweep``."""
    sw = _command(
        sub,
        "sweep",
        "run a scene over a parameter grid on Dask, gather one Dataset",
        "Runs every point of the grid (the product of the --grid values) as one run of the scene,\n"
        "on a local Dask cluster or a scheduler, and writes sweep.nc with one dimension per grid\n"
        "name. Every point is checked before anything runs. Grid names: oil, fill, braking\n"
        "(ecp/conventional), bulkheads (a count), speed (km/h), or any scene field section.key.",
        "  railslosh sweep examples/scenes/crude_ecp_braking_light.toml --grid oil=light,heavy --grid bulkheads=0,2\n"
        "  railslosh sweep examples/scenes/swri_lane_change_20mph.toml --grid speed=30,60 --set solver.t_end=2 "
        "--workers 2",
    )
    sw.add_argument("scene", help="scene file (TOML) every grid point starts from")
    sw.add_argument(
        "--grid",
        action="append",
        default=[],
        metavar="NAME=V1,V2",
        required=True,
        help="a grid dimension: oil, fill, braking (ecp/conventional), bulkheads (count), speed (km/h) or "
        "section.key, with its values (repeat --grid for more dimensions)",
    )
    sw.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="SECTION.KEY=VALUE",
        help="override a scene field for every run (a TOML value; repeat --set for more fields)",
    )
    sw.add_argument("--scheduler", help="address of a Dask scheduler (default: a local cluster)")
    sw.add_argument("--workers", type=_positive_int, help="local cluster workers (default: CPU count)")
    sw.add_argument("--processes", action="store_true", help="local cluster of processes instead of threads")
    sw.add_argument("-o", "--out", help="output directory (default: out/sweep_<scene name>)")
    sw.set_defaults(func=_cmd_sweep)


def _add_validate_and_bench(sub: Any) -> None:
    """``railslosh validate`` and ``railslosh bench``."""
    v = _command(
        sub,
        "validate",
        "run physics validation cases (JSON records)",
        "Runs validation cases against analytic results, invariants and published values; one JSON\n"
        "record per check (case, quantity, measured, reference, tolerance, passed). Exit 1 if a check\n"
        "fails. Without --quick some cases run for many minutes (docs/validation.md).",
        "  railslosh validate --list\n  railslosh validate element-mass hydrostatic-cylinder --quick\n"
        "  railslosh validate --quick --json > records.json",
    )
    v.add_argument("cases", nargs="*", help="case names, see --list (default: all)")
    v.add_argument("--list", action="store_true", help="list the cases and exit")
    v.add_argument("--json", action="store_true", help="one machine-readable JSON document on stdout")
    v.add_argument("--quick", action="store_true", help="quick forms (fewer samples), as run in CI")
    v.set_defaults(func=_cmd_validate)

    b = _command(
        sub,
        "bench",
        "work-precision sweeps: run time against error (CSV, JSON, PNG)",
        "Runs each sweep over step sizes and meshes and writes work_precision.csv, .json and one PNG\n"
        "per sweep. --quick takes about a minute or two on two cores; the full sweeps take far longer.",
        "  railslosh bench --list\n  railslosh bench slosh-tank --quick -o bench-results",
    )
    b.add_argument("cases", nargs="*", help="sweep names, see --list (default: all)")
    b.add_argument("--list", action="store_true", help="list the sweeps and exit")
    b.add_argument("--quick", action="store_true", help="small grids (about a minute or two), as run in CI")
    b.add_argument("-o", "--output", default="bench-results", help="output directory (default: bench-results)")
    b.add_argument("--no-plot", action="store_true", help="skip the PNG plots")
    b.set_defaults(func=_cmd_bench)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``railslosh`` command."""
    p = argparse.ArgumentParser(
        prog="railslosh",
        description=_DESCRIPTION,
        epilog=_EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--version", action="version", version=f"railslosh {__version__}")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")

    _add_demo(sub)
    _add_run(sub)
    _add_plot_and_report(sub)
    _add_sweep(sub)
    _add_validate_and_bench(sub)
    robustness.add_subparser(sub)
    return p


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``railslosh`` command; returns the exit status: 0 done, 1 a run or check
    failed, 2 bad input (said in one line on stderr), 130 interrupted."""
    args = build_parser().parse_args(argv)
    where = f"railslosh {args.command}"
    try:
        return int(args.func(args))
    except BrokenPipeError:
        # output piped into e.g. `head`: stop quietly, like other command-line tools
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except (ValueError, OSError) as exc:  # bad input: a field, a path, a file that is not what it should be
        msg = str(exc) if not isinstance(exc, OSError) or str(exc).startswith("invalid `") else _os_error(exc)
        print(f"{where}: {msg}", file=sys.stderr)
        return 2
    except RailsloshError as exc:  # a computation the kernels could not do
        print(f"{where}: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"\n{where}: interrupted", file=sys.stderr)
        return 130


def _os_error(exc: OSError) -> str:
    """An operating-system error as one line: what failed and on which path."""
    name = exc.filename if exc.filename is not None else ""
    return f"{exc.strerror or exc}: {name}" if name else str(exc.strerror or exc)


if __name__ == "__main__":
    sys.exit(main())
