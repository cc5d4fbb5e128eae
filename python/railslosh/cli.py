"""The ``railslosh`` command-line tool."""

from __future__ import annotations

import argparse
import json
import sys
import time


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
    tank = rs.slosh.cylinder_tank(rs.mesh.TANK_CAR_LENGTH, rs.mesh.TANK_CAR_RADIUS, rs.mesh.TANK_CAR_HEAD_DEPTH)
    motion = rs.slosh.Motion().pulse("x", -0.1 * 9.81, 0.2, 100.0, ramp=0.2)
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


def build_parser() -> argparse.ArgumentParser:
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

    d = sub.add_parser("demo", help="build the crude-oil tank car model and check it")
    d.add_argument("--oil", default="light", choices=["light", "medium", "heavy"])
    d.add_argument("--fill", type=float, default=0.5)
    d.add_argument("--n-length", type=int, default=6, help="elements along the tank in the braking run")
    d.add_argument("--t-end", type=float, default=2.0, help="simulated time of the braking run (s)")
    d.set_defaults(func=_cmd_demo)
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args))
    except ValueError as exc:
        print(f"railslosh {args.command}: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        # output piped into e.g. `head`: stop quietly, like other command-line tools
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


if __name__ == "__main__":
    sys.exit(main())
