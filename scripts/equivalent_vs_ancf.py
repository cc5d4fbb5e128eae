"""Cost against error of the cheaper fluid models (issue 7): the same scene run with the ANCF
continuum, the equivalent pendulum (spring-mass) model and rigid lading.

Scene: two tank cars half full of light crude, conventional braking (front car only, the designed
torque of seed 000 §8.2 from 40 km/h; ``--scope ecp``: both cars), tangent track. Printed per
model: the mean coupler force after the brake build-up (t >= --t-settled), the peak |coupler
force|, the peak forward shift of each car's oil centre of mass (tank frame x; rigid lading: 0 by
construction), the wall time and the wall-time ratio to ANCF.

    python scripts/equivalent_vs_ancf.py                    # 3 s, ANCF mesh 3x2x2 (a minute or two)
    python scripts/equivalent_vs_ancf.py --scope ecp --t-end 10.5 --counts 6 4 2
    python scripts/equivalent_vs_ancf.py --t-end 1 --json out/equivalent_vs_ancf.json

Not part of the default test run (the ANCF run takes tens of seconds).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from railslosh import vehicle

TRACK = [[0, 0, 0, 0, 0, 0], [4000, 0, 0, 0, 0, 0]]


def compare(
    t_end: float = 3.0, counts: tuple[int, int, int] = (3, 2, 2), t_settled: float = 2.0, scope: str = "front"
) -> dict:
    """Runs the three models and returns their metrics (see the module docs)."""
    params = vehicle.tank_car_parameters()
    geo = vehicle.equivalent_model(0.5, oil="light", slosh_axis="longitudinal")
    brake = vehicle.design_brake_torque(params["total_mass"] + geo["mass"])
    common = dict(cars=2, station=300.0, speed=40 / 3.6, t_end=t_end, step=4e-3, record_every=0.02)
    common |= dict(brake=brake, brake_scope=scope)
    runs = {}
    t0 = time.perf_counter()
    runs["ancf"] = vehicle.run_fluid(TRACK, **common, oil="light", counts=counts, fill=0.5)
    runs["ancf"]["wall"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    runs["pendulum"] = vehicle.run_equivalent(TRACK, **common, oil="light", fill=0.5, slosh_axis="longitudinal")
    runs["pendulum"]["wall"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    runs["rigid"] = vehicle.run(TRACK, **common, lading_mass=geo["mass"], lading_height=geo["centroid"][2])
    runs["rigid"]["wall"] = time.perf_counter() - t0
    out = {"t_end": t_end, "counts": list(counts), "t_settled": t_settled, "scope": scope, "models": {}}
    out["liquid_mass"] = geo["mass"]
    for name, r in runs.items():
        t = np.asarray(r["t"])
        late = t >= t_settled
        com = r.get("oil_com_tank")
        shift = (com[:, :, 0] - com[0, :, 0]).max(axis=0).tolist() if com is not None else [0.0, 0.0]
        out["models"][name] = {
            "mean_coupler_force_N": float(np.mean(np.asarray(r["coupler_force"])[late, 0])),
            "peak_abs_coupler_force_N": float(np.max(np.abs(np.asarray(r["coupler_force"])[:, 0]))),
            "peak_oil_com_x_shift_m": shift,
            "wall_s": r["wall"],
            "steps": r["stats"]["steps"],
        }
    ref = out["models"]["ancf"]
    for m in out["models"].values():
        m["wall_ratio_to_ancf"] = m["wall_s"] / ref["wall_s"]
        m["coupler_force_error"] = m["mean_coupler_force_N"] / ref["mean_coupler_force_N"] - 1.0
        m["peak_coupler_force_error"] = m["peak_abs_coupler_force_N"] / ref["peak_abs_coupler_force_N"] - 1.0
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--t-end", type=float, default=3.0)
    ap.add_argument("--counts", type=int, nargs=3, default=(3, 2, 2))
    ap.add_argument("--t-settled", type=float, default=2.0)
    ap.add_argument("--scope", choices=("front", "ecp"), default="front", help="braked cars (default: front)")
    ap.add_argument("--json", type=Path, default=None, help="also write the metrics to this file")
    a = ap.parse_args()
    scope = "all" if a.scope == "ecp" else "front"
    out = compare(a.t_end, tuple(a.counts), a.t_settled, scope)
    kind = "ECP" if scope == "all" else "conventional"
    print(f"two cars, light crude, {kind} braking, {a.t_end:g} s; ANCF mesh {a.counts}")
    print(
        f"{'model':9s} {'coupler (t>=' + format(a.t_settled, 'g') + ' s)':>22s} {'err':>7s} "
        f"{'peak |coupler|':>15s} {'err':>7s} {'peak com-x car1/car2 (mm)':>26s} {'wall s':>8s} {'ratio':>6s}"
    )
    for name, m in out["models"].items():
        s1, s2 = (1e3 * x for x in m["peak_oil_com_x_shift_m"])
        print(
            f"{name:9s} {m['mean_coupler_force_N'] / 1e3:19.2f} kN {100 * m['coupler_force_error']:6.1f}% "
            f"{m['peak_abs_coupler_force_N'] / 1e3:12.2f} kN {100 * m['peak_coupler_force_error']:6.1f}% "
            f"{s1:12.1f} / {s2:<12.1f} {m['wall_s']:8.2f} {m['wall_ratio_to_ancf']:6.3f}"
        )
    if a.json:
        a.json.parent.mkdir(parents=True, exist_ok=True)
        a.json.write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
