"""Figures of the crude-oil studies (seed 000 §8.2-8.5) on the coupled car-oil model.

Usage: python scripts/crude_oil_figures.py [--out DIR] [--quick] [--workers N]

Runs, in parallel threads (the solver releases the GIL):
  * ECP braking of the two-car train, 40 -> 5 km/h in 10 s, light / medium / heavy crude;
  * conventional braking (front car only), light and heavy crude;
  * ECP braking with two bulkheads (light crude);
  * one car on the Table 1 curve at 60 and 100 km/h, three crudes (outward inertia vs gravity);
  * mesh convergence: one car braking with light crude, 32 / 48 / 64 elements;
and writes DIR/*.png (coupler forces, oil centre of mass, wheel loads, outward inertia, mesh
snapshots, mesh convergence) and DIR/crude_oil_studies.npz with every time history.

The full form (48-element tanks, 10.5 s) takes about an hour on 2 cores; --quick (8-element
tanks, 3 s) a few minutes.
"""

from __future__ import annotations

import argparse
import pathlib
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from railslosh import rail, vehicle
from railslosh.slosh import SimulationError

OILS = ("light", "medium", "heavy")


def table1() -> rail.Track:
    d = [0, 100, 300, 600, 800, 1000, 1200, 1500, 1700, 2800]
    c = [0, 0, 3, 3, 0, 0, -3, -3, 0, 0]
    return rail.Track.from_us(d, c, c, cant_right=0.025, cant_left=-0.025)


TANGENT = [[0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [4000.0, 0.0, 0.0, 0.0, 0.0, 0.0]]


def braking(oil: str, counts, t_end: float, *, cars: int = 2, scope: str = "all", bulkheads=None) -> dict:
    mass = vehicle.tank_car_parameters()["total_mass"] + 36_000.0
    brake = vehicle.design_brake_torque(mass)
    return vehicle.run_fluid(
        TANGENT,
        cars=cars,
        speed=40 / 3.6,
        t_end=t_end,
        oil=oil,
        counts=counts,
        brake=brake,
        brake_scope=scope,
        bulkheads=bulkheads,
        snapshot_every=1.0,
    )


def curve(oil: str, speed_kmh: float, counts, t_end: float) -> dict:
    return vehicle.run_fluid(
        table1(), station=110.0, speed=speed_kmh / 3.6, drive=True, t_end=t_end, oil=oil, counts=counts
    )


def outward_inertia(res: dict, track: rail.Track, t_avg: float) -> tuple[float, float]:
    t, x = res["t"], res["oil_com_global"][:, 0, :]
    m = res["fluid_mass"]
    h = np.diff(t).mean()
    a = (x[2:] - 2 * x[1:-1] + x[:-2]) / h**2
    s = res["tank_station"][1:-1, 0]
    keep = t[1:-1] >= t[-1] - t_avg
    if len(t) < 3 or not keep.any():
        return float("nan"), float("nan")
    fc, gc = [], []
    for ak, sk in zip(a[keep], s[keep], strict=True):
        _, axes = track.frame(sk)
        lat = np.asarray(axes)[:, 1]
        inward = np.array([lat[0], lat[1], 0.0])
        inward /= np.linalg.norm(inward)
        fc.append(m * ak @ inward)
        gc.append(m * 9.80665 * abs(lat[2]))
    return float(np.mean(fc)), float(np.mean(gc))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", default="out/crude_oil")
    p.add_argument("--quick", action="store_true", help="8-element tanks, 3 s of braking")
    p.add_argument("--workers", type=int, default=2)
    a = p.parse_args()
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    counts = (2, 2, 2) if a.quick else (6, 4, 2)
    t_brake = 3.0 if a.quick else 10.5
    t_curve = 2.0 if a.quick else 3.0
    meshes = [(2, 2, 2), (3, 2, 2), (4, 2, 2)] if a.quick else [(4, 4, 2), (6, 4, 2), (8, 4, 2)]
    third = (12.0 - 1.0) / 6.0
    jobs = {f"ecp_{o}": (braking, (o, counts, t_brake)) for o in OILS}
    jobs |= {f"conv_{o}": (braking, (o, counts, t_brake)) for o in ("light", "heavy")}
    jobs |= {"ecp_light_bulkheads": (braking, ("light", counts, t_brake))}
    jobs |= {f"curve_{o}_{v}": (curve, (o, v, counts, t_curve)) for o in OILS for v in (60, 100)}
    jobs |= {f"mesh_{m[0]}x{m[1]}x{m[2]}": (braking, ("light", m, t_brake)) for m in meshes}
    kwargs = {k: {} for k in jobs}
    for o in ("light", "heavy"):
        kwargs[f"conv_{o}"] = {"scope": "front"}
    kwargs["ecp_light_bulkheads"] = {"bulkheads": [(-third, 0.02), (third, 0.02)]}
    for m in meshes:
        kwargs[f"mesh_{m[0]}x{m[1]}x{m[2]}"] = {"cars": 1}

    def guarded(f, *args, **kw):
        # A run that stops early keeps what it computed; the failure is reported and plotted as far as it got.
        try:
            return f(*args, **kw)
        except SimulationError as exc:
            print(f"run stopped: {exc}")
            return exc.results

    with ThreadPoolExecutor(max_workers=a.workers) as pool:
        futures = {k: pool.submit(guarded, f, *args, **kwargs[k]) for k, (f, args) in jobs.items()}
        res = {k: f.result() for k, f in futures.items()}
        for k, r in res.items():
            stop = f", STOPPED at t = {r['t'][-1]:.2f} s" if "error" in r else ""
            print(f"{k}: {r['stats']['wall_time']:.0f} s wall, {r['stats']['steps']} steps{stop}")
    np.savez_compressed(
        out / "crude_oil_studies.npz",
        **{f"{k}__{f}": np.asarray(v[f]) for k, v in res.items() for f in ("t", "coupler_force", "oil_com_tank")},
    )
    track = table1()
    summary = {}
    for o in OILS:
        for v in (60, 100):
            summary[(o, v)] = outward_inertia(res[f"curve_{o}_{v}"], track, 1.0)
            print(f"curve {o} {v} km/h: F_c = {summary[(o, v)][0]:.0f} N, gravity component {summary[(o, v)][1]:.0f} N")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not installed: wrote only the .npz")
        return

    def save(fig, name):
        fig.tight_layout()
        fig.savefig(out / name, dpi=120)
        plt.close(fig)

    fig, ax = plt.subplots(figsize=(7, 4))
    for o in OILS:
        r = res[f"ecp_{o}"]
        ax.plot(r["t"], r["coupler_force"][:, 0] / 1e3, label=f"{o} crude")
    ax.set(xlabel="time (s)", ylabel="coupler force (kN, tension +)", title="ECP braking, two cars")
    ax.legend()
    save(fig, "ecp_coupler_force.png")

    fig, ax = plt.subplots(figsize=(7, 4))
    for o in ("light", "heavy"):
        for kind in ("ecp", "conv"):
            r = res[f"{kind}_{o}"]
            ax.plot(r["t"], r["coupler_force"][:, 0] / 1e3, label=f"{'ECP' if kind == 'ecp' else 'conventional'}, {o}")
    ax.set(xlabel="time (s)", ylabel="coupler force (kN)", title="ECP vs conventional braking")
    ax.legend()
    save(fig, "conventional_vs_ecp.png")

    fig, axs = plt.subplots(1, 2, figsize=(10, 4))
    for k, lab in (("ecp_light", "open tank"), ("ecp_light_bulkheads", "two bulkheads")):
        r = res[k]
        axs[0].plot(r["t"], r["coupler_force"][:, 0] / 1e3, label=lab)
        q = r["wheel_vertical"]
        front, rear = q[:, 0:2, :].sum(axis=(1, 2)), q[:, 2:4, :].sum(axis=(1, 2))
        axs[1].plot(r["t"], (front - rear) / 1e3, label=lab)
    axs[0].set(xlabel="time (s)", ylabel="coupler force (kN)", title="light crude, ECP")
    axs[1].set(xlabel="time (s)", ylabel="front - rear bogie normal force (kN)", title="front car")
    axs[0].legend()
    save(fig, "bulkheads.png")

    fig, ax = plt.subplots(figsize=(7, 4))
    for o in OILS:
        r = res[f"ecp_{o}"]
        ax.plot(r["t"], r["oil_com_tank"][:, 0, 0], label=f"{o}, front car")
    ax.set(xlabel="time (s)", ylabel="oil centre of mass x, tank frame (m)", title="ECP braking")
    ax.legend()
    save(fig, "oil_centre_of_mass.png")

    fig, ax = plt.subplots(figsize=(7, 4))
    for m in meshes:
        r = res[f"mesh_{m[0]}x{m[1]}x{m[2]}"]
        ax.plot(r["t"], r["oil_com_tank"][:, 0, 0], label=f"{r['elements']} elements")
    ax.set(xlabel="time (s)", ylabel="oil centre of mass x (m)", title="mesh convergence, light crude")
    ax.legend()
    save(fig, "mesh_convergence.png")

    fig, ax = plt.subplots(figsize=(7, 4))
    x = np.arange(len(OILS))
    for j, v in enumerate((60, 100)):
        ax.bar(x + 0.35 * j, [summary[(o, v)][0] / 1e3 for o in OILS], 0.35, label=f"outward inertia, {v} km/h")
    ax.plot(x + 0.175, [summary[(o, 60)][1] / 1e3 for o in OILS], "k_", ms=30, mew=2, label="gravity component")
    ax.set_xticks(x + 0.175, OILS)
    ax.set(ylabel="force on the oil (kN)", title="Table 1 curve (3 deg, 3 in)")
    ax.legend()
    save(fig, "curve_outward_inertia.png")

    r = res["ecp_light"]
    fig, axs = plt.subplots(len(r["snapshots"]), 1, figsize=(7, 1.6 * len(r["snapshots"])), sharex=True)
    for axk, (t, cars) in zip(np.atleast_1d(axs), r["snapshots"], strict=True):
        nodes = cars[0][:, 0, :]
        x0 = nodes[:, 0] - nodes[:, 0].mean()
        axk.plot(x0, nodes[:, 2] - nodes[:, 2].max(), ".", ms=3)
        axk.set(ylabel=f"t = {t:.1f} s")
    np.atleast_1d(axs)[-1].set(xlabel="x relative to the fluid's mean (m)")
    fig.suptitle("light crude, front car, ECP braking: fluid nodes (side view)")
    save(fig, "fluid_snapshots.png")
    print(f"wrote figures to {out}")


if __name__ == "__main__":
    main()
