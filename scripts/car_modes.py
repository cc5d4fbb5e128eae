"""Frequency and damping of the two-car train's vertical modes with the ANCF liquid on several
meshes and with the same mass as rigid lading: whether the car-liquid dynamics that carry the
identical-brake ECP coupler force are resolved by the mesh (docs/validation.md,
"coupler-force-convergence").

The two cars of the ECP scenes (light crude, half full, critically damped adhesive walls,
stabilized rest state) coast on tangent track at 40 km/h; the front car alone is braked with
`--torque` N m per wheelset from 0.5 to 0.7 s, which jolts the coupler and sets the cars bouncing
and pitching. From the wheel loads, after a 4th-order zero-phase band-pass around each mode:
- antisymmetric bounce: (sum of car 1's wheel loads) - (sum of car 2's), 1.2-4 s;
- symmetric pitch: (front - rear bogie wheel loads) of car 1 plus that of car 2, 1-3 s.
Frequency from the zero crossings (railslosh.fmu.dominant_period), damping ratio from the slope
of the log of the Hilbert envelope (the fits end at 4 s, so --t-end is at least 5 s: the band-pass
bends the last second). One JSON line per model.

Usage: python scripts/car_modes.py [--meshes 4x4x2 6x4x2 8x4x2] [--torque 15000] [--t-end 8]
"""

import argparse
import json
import time

import numpy as np
from scipy.signal import butter, hilbert, sosfiltfilt

from railslosh import vehicle
from railslosh.fmu import dominant_period

TANGENT = [[0.0] * 6, [4000.0, 0.0, 0.0, 0.0, 0.0, 0.0]]
STEP = 2e-3  # s, the ECP scenes' largest step
MODES = {  # name: (band, Hz), (fit window, s)
    "antisymmetric_bounce": ((1.2, 3.5), (1.2, 4.0)),
    "symmetric_pitch": ((1.5, 6.0), (1.0, 3.0)),
}


def channels(res: dict) -> dict[str, np.ndarray]:
    """The two modal channels from the wheel loads (wheelsets 1-4 are car 1's, front first)."""
    q = np.asarray(res["wheel_vertical"])  # (time, wheelset, side)
    n = q.shape[1] // 2

    def load(a: int, b: int) -> np.ndarray:
        return q[:, a:b].sum(axis=(1, 2))

    pitch = [load(c * n, c * n + n // 2) - load(c * n + n // 2, (c + 1) * n) for c in (0, 1)]
    return {
        "antisymmetric_bounce": load(0, n) - load(n, 2 * n),
        "symmetric_pitch": pitch[0] + pitch[1],
    }


def fit(t: np.ndarray, x: np.ndarray, band: tuple[float, float], window: tuple[float, float]) -> dict:
    """Frequency (Hz) and damping ratio of the decaying oscillation of x in band over window."""
    sos = butter(4, band, btype="band", fs=1.0 / (t[1] - t[0]), output="sos")
    y = sosfiltfilt(sos, x - x.mean())
    m = (t >= window[0]) & (t <= window[1])
    f = 1.0 / dominant_period(t[m], y[m])
    slope = np.polyfit(t[m], np.log(np.abs(hilbert(y))[m]), 1)[0]
    return {"frequency_hz": round(f, 4), "damping_ratio": round(-slope / (2 * np.pi * f), 4)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--meshes", nargs="+", default=["4x4x2", "6x4x2", "8x4x2"])
    ap.add_argument("--torque", type=float, default=15e3, help="N m per wheelset, front car, 0.5-0.7 s")
    ap.add_argument("--t-end", type=float, default=8.0)
    a = ap.parse_args()
    if a.t_end < 5.0:
        # the fits end at 4 s; the zero-phase band-pass needs a second beyond them
        ap.error(f"--t-end {a.t_end:g}: expected at least 5 s")
    pulse = ([0.0, 0.5, 0.51, 0.7, 0.71, 1e3], [0.0, 0.0, a.torque, a.torque, 0.0, 0.0])
    common = {
        "cars": 2,
        "station": 300.0,
        "speed": 40 / 3.6,
        "t_end": a.t_end,
        "step": STEP,
        "record_every": 0.01,
        "brake": pulse,
        "brake_scope": "front",
    }
    fluid_mass = None
    for model in [*a.meshes, "rigid"]:
        tic = time.perf_counter()
        if model == "rigid":
            res = vehicle.run(TANGENT, lading_mass=fluid_mass, **common)
        else:
            counts = tuple(int(k) for k in model.split("x"))
            res = vehicle.run_fluid(
                TANGENT,
                counts=counts,
                oil="light",
                wall_damping_ratio=1.0,
                wall_adhesion=4.0,
                shear_stabilization=True,
                **common,
            )
            fluid_mass = res["fluid_mass"]
        t = np.asarray(res["t"])
        ch = channels(res)
        out = {"model": model if model == "rigid" else f"ancf {model}"}
        for name, (band, window) in MODES.items():
            out[name] = fit(t, ch[name], band, window)
        out["wall_s"] = round(time.perf_counter() - tic, 1)
        print(json.dumps(out), flush=True)


if __name__ == "__main__":
    main()
