"""The ``railslosh`` command-line tool."""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path
from typing import Any

from railslosh.constants import GRAVITY


def _cmd_validate(args: argparse.Namespace) -> int:
    from railslosh import validate

    if args.list:
        for c in validate.CASES.values():
            print(f"{c.name:28s} {c.description}")
        return 0
    skipped: list[dict[str, str]] = []
    try:
        records = validate.run(args.cases, quick=args.quick, skipped=skipped)
    except ValueError as exc:
        print(f"railslosh validate: {exc}", file=sys.stderr)
        return 2
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
    from railslosh import bench

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
    import numpy as np

    import railslosh as rs
    from railslosh import validate

    print("railslosh demo: the crude-oil tank car of Grossi & Shabana (2018), seed 000 §8")
    mesh = rs.mesh.cylinder_tank(fill=args.fill, n_length=6, n_width=4, n_height=2)
    depth = mesh.free_surface_z + rs.mesh.TANK_CAR_RADIUS
    oil = rs.fluids.crude_oil(args.oil, depth=depth)
    body = rs.FluidBody(mesh, oil)
    m_exact = oil.density * mesh.exact_volume
    print(
        f"  tank: shell {rs.mesh.TANK_CAR_LENGTH} m, radius {rs.mesh.TANK_CAR_RADIUS} m, "
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
    tank = rs.slosh.TankGeometry.cylinder(rs.mesh.TANK_CAR_LENGTH, rs.mesh.TANK_CAR_RADIUS, rs.mesh.TANK_CAR_HEAD_DEPTH)
    motion = rs.slosh.Motion().pulse("x", -0.1 * GRAVITY, 0.2, 100.0, ramp=0.2)
    print(
        f"  braking run: -0.1 g from t = 0.2 s for {args.t_end} s, {run_mesh.n_elements} bricks "
        f"({run_mesh.n_coords} coordinates), HHT, penalty wall contact"
    )
    t0 = time.perf_counter()
    res = rs.slosh.run(run_mesh, oil, tank, motion, t_end=args.t_end, h=0.01)
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


class ProgressBar:
    """A one-line progress display on stderr: simulated time, wall time, ETA and Newton statistics.
    Called as ``bar(t, t_end, steps, newton_iterations, rejected_steps)`` (the ``progress`` callback
    of the run functions). On a terminal the line is redrawn; otherwise a line is printed at most
    every ``every`` seconds."""

    def __init__(self, stream: Any = None, width: int = 24, every: float = 5.0) -> None:
        self.stream = stream if stream is not None else sys.stderr
        self.width = width
        self.every = every
        self.start = time.perf_counter()
        self.last_print = -math.inf
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.calls = 0
        self.last = ""

    def line(self, t: float, t_end: float, steps: int, newton: int, rejected: int) -> str:
        """The progress line: bar, percentage, simulated and wall time, ETA (wall time so far
        scaled by the remaining fraction of simulated time), steps and Newton iterations per step."""
        wall = time.perf_counter() - self.start
        frac = min(max(t / t_end, 0.0), 1.0) if t_end > 0 else 1.0
        eta = wall * (1.0 - frac) / frac if frac > 0 else math.inf
        n = int(round(frac * self.width))
        eta_s = f"{eta:6.1f} s" if math.isfinite(eta) else "     ? s"
        return (
            f"[{'#' * n}{'.' * (self.width - n)}] {100 * frac:5.1f}% t = {t:.3f}/{t_end:g} s | wall {wall:6.1f} s | "
            f"ETA {eta_s} | {steps} steps ({rejected} rejected) | Newton {newton / max(steps, 1):.2f}/step"
        )

    def __call__(self, t: float, t_end: float, steps: int, newton: int, rejected: int) -> None:
        self.calls += 1
        self.last = self.line(t, t_end, steps, newton, rejected)
        now = time.perf_counter()
        done = t >= t_end * (1 - 1e-12)
        if self.tty:
            self.stream.write("\r" + self.last + ("\n" if done else ""))
            self.stream.flush()
        elif done or now - self.last_print >= self.every:
            self.last_print = now
            print(self.last, file=self.stream, flush=True)


def _overrides(sets: list[str]) -> dict[str, Any]:
    from railslosh.sweep import parse_value

    over: dict[str, Any] = {}
    for item in sets:
        key, sep, value = item.partition("=")
        parts = key.strip().split(".")
        if not sep or len(parts) != 2 or not all(parts):
            raise ValueError(f"invalid parameter `--set` = {item!r}: allowed section.key=VALUE (TOML value)")
        over.setdefault(parts[0], {})[parts[1]] = parse_value(value)
    return over


def _cmd_run(args: argparse.Namespace) -> int:
    from railslosh import plots, results, scene
    from railslosh.slosh import SimulationError

    over = _overrides(args.set)
    sc = scene.load_scene(args.scene, over or None)
    if args.t_end is not None:
        over.setdefault("solver" if sc.kind == "slosh" else "train", {})["t_end"] = args.t_end
        sc = scene.load_scene(args.scene, over)
    out = Path(args.out) if args.out else Path("out") / Path(args.scene).stem
    out.mkdir(parents=True, exist_ok=True)
    print(f"railslosh run: {sc.name or Path(args.scene).stem} ({sc.kind}, t_end = {sc.t_end:g} s) -> {out}")
    if sc.kind != "slosh":
        from railslosh import fluid_model

        choice = fluid_model.decide(sc)
        print(f"  fluid model: {choice.model} ({choice.reason})")
    bar = None if args.quiet else ProgressBar()
    status = 0
    t0 = time.perf_counter()
    try:
        res = scene.run_scene(sc, progress=bar)
    except SimulationError as exc:
        print(f"\nrailslosh run: {exc}", file=sys.stderr)
        res = dict(exc.results)
        res["scene"] = sc
        status = 1
    except KeyboardInterrupt:
        print("\nrailslosh run: interrupted", file=sys.stderr)
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
    # the model the run used (run_scene records it, also on a failed run)
    summary |= {k: res[k] for k in ("fluid_model", "fluid_model_reason", "stepper", "stepper_reason") if k in res}
    (out / "run.json").write_text(json.dumps(summary, indent=1, default=str), encoding="utf-8")
    print(
        f"  {st.get('steps', 0)} steps, {st.get('newton_iterations', 0)} Newton iterations, "
        f"{st.get('rejected_steps', 0)} rejected, {wall:.1f} s wall"
    )
    for p in written:
        print(f"  wrote {p}")
    print(f"  next: railslosh report {out}")
    return status


def _cmd_plot(args: argparse.Namespace) -> int:
    from railslosh import plots, results

    src = Path(args.results)
    if not src.is_file():
        raise ValueError(f"invalid parameter `results` = {str(src)!r}: allowed an existing results .nc file")
    ds = results.load(src)
    if "time" not in ds.dims:
        raise ValueError(f"invalid parameter `results` = {str(src)!r}: allowed the results of one run")
    paths = plots.plot_dataset(ds, Path(args.out) if args.out else src.parent / "plots")
    for p in paths:
        print(f"wrote {p}")
    return 0 if paths else 1


def _cmd_report(args: argparse.Namespace) -> int:
    from railslosh import report

    p = report.write_report(args.results_dir, args.out)
    print(f"wrote {p}")
    return 0


def _cmd_sweep(args: argparse.Namespace) -> int:
    from railslosh import results, sweep

    grid = sweep.parse_grid(args.grid)
    over = _overrides(args.set)
    n = math.prod(len(v) for v in grid.values())
    where = args.scheduler or f"a local Dask cluster ({args.workers or 'all'} workers)"
    print(f"railslosh sweep: {n} runs of {args.scene} on {where}")
    t0 = time.perf_counter()

    def done(k: int, total: int) -> None:
        print(f"  {k}/{total} runs done, {time.perf_counter() - t0:.1f} s", file=sys.stderr, flush=True)

    ds = sweep.run_sweep(
        args.scene,
        grid,
        overrides=over or None,
        scheduler=args.scheduler,
        workers=args.workers,
        processes=args.processes,
        on_done=done,
    )
    out = Path(args.out) if args.out else Path("out") / f"sweep_{Path(args.scene).stem}"
    p = results.save(ds, out / "sweep.nc")
    print(f"  wrote {p} (dims: {dict(ds.sizes)})")
    failed = [str(e) for e in ds["error"].values.ravel() if e]
    for e in failed:
        print(f"  failed: {e}", file=sys.stderr)
    return 1 if failed else 0


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``railslosh`` command."""
    from railslosh import __version__

    p = argparse.ArgumentParser(prog="railslosh", description=__doc__)
    p.add_argument("--version", action="version", version=f"railslosh {__version__}")
    sub = p.add_subparsers(dest="command", required=True)

    v = sub.add_parser("validate", help="run physics validation cases (JSON records)")
    v.add_argument("cases", nargs="*", help="case names (default: all)")
    v.add_argument("--list", action="store_true", help="list the cases and exit")
    v.add_argument("--json", action="store_true", help="one machine-readable JSON document on stdout")
    v.add_argument("--quick", action="store_true", help="quick forms (fewer samples), as run in CI")
    v.set_defaults(func=_cmd_validate)

    b = sub.add_parser("bench", help="work-precision sweeps: run time against error (CSV, JSON, PNG)")
    b.add_argument("cases", nargs="*", help="sweep names (default: all)")
    b.add_argument("--list", action="store_true", help="list the sweeps and exit")
    b.add_argument("--quick", action="store_true", help="small grids (seconds), as run in CI")
    b.add_argument("-o", "--output", default="bench-results", help="output directory (default: bench-results)")
    b.add_argument("--no-plot", action="store_true", help="skip the PNG plots")
    b.set_defaults(func=_cmd_bench)

    d = sub.add_parser("demo", help="build the crude-oil tank car model and check it")
    d.add_argument("--oil", default="light", choices=["light", "medium", "heavy"])
    d.add_argument("--fill", type=float, default=0.5)
    d.add_argument("--n-length", type=int, default=6, help="elements along the tank in the braking run")
    d.add_argument("--t-end", type=float, default=2.0, help="simulated time of the braking run (s)")
    d.set_defaults(func=_cmd_demo)

    r = sub.add_parser("run", help="run a scene file (TOML) and write results, plots, ParaView files")
    r.add_argument("scene", help="scene file, e.g. examples/scenes/crude_ecp_braking_light.toml")
    r.add_argument("-o", "--out", help="output directory (default out/<scene name>)")
    r.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE", help="override a scene field")
    r.add_argument("--t-end", type=float, help="override the simulated time (s)")
    r.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    r.set_defaults(func=_cmd_run)

    pl = sub.add_parser("plot", help="PNG plots of a results.nc file")
    pl.add_argument("results", help="results.nc written by `railslosh run`")
    pl.add_argument("-o", "--out", help="directory of the PNGs (default: plots/ next to the file)")
    pl.set_defaults(func=_cmd_plot)

    rp = sub.add_parser("report", help="self-contained HTML report of a results directory")
    rp.add_argument("results_dir", help="directory written by `railslosh run`")
    rp.add_argument("-o", "--out", help="HTML file (default results_dir/report.html)")
    rp.set_defaults(func=_cmd_report)

    sw = sub.add_parser("sweep", help="run a scene over a parameter grid on Dask, gather one Dataset")
    sw.add_argument("scene")
    sw.add_argument(
        "--grid",
        action="append",
        default=[],
        metavar="NAME=V1,V2",
        required=True,
        help="sweep parameter: oil, fill, braking (ecp/conventional), bulkheads (count), speed (km/h) or section.key",
    )
    sw.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE", help="override for every run")
    sw.add_argument("--scheduler", help="address of a Dask scheduler (default: a local cluster)")
    sw.add_argument("--workers", type=int, help="local cluster workers (default: CPU count)")
    sw.add_argument("--processes", action="store_true", help="local cluster of processes instead of threads")
    sw.add_argument("-o", "--out", help="output directory (default out/sweep_<scene name>)")
    sw.set_defaults(func=_cmd_sweep)

    from railslosh import robustness

    robustness.add_subparser(sub)
    return p


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``railslosh`` command; returns the exit status (2 for bad input)."""
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args))
    except (ValueError, FileNotFoundError) as exc:
        print(f"railslosh {args.command}: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        # output piped into e.g. `head`: stop quietly, like other command-line tools
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


if __name__ == "__main__":
    sys.exit(main())
