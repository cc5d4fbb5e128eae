"""Peak load of the liquid on the tank in a SwRI bump scene, raw and through EN 14363's 20 Hz
low-pass, under refinement of the mesh and the step and under stiffer penalties: which of the two
peaks is a property of the liquid and which of the discretization.

Each variant is the scene as shipped with one change: the mesh refined (2x, 3x), the largest step
cut to 2 ms, the volumetric penalty x4, the wall stiffness x4, or critically damped walls replaced
by doubly critical ones. One JSON line per variant: raw peak |F| after 0.2 s and its time, peak of
the 20 Hz low-passed |F| and its time, the ringing's frequency (resolution 2.5 Hz), steps.

Usage: python scripts/swri_peak_loads.py [SCENE] [--quick]
SCENE defaults to examples/scenes/swri_bump_half_round_12in_5mph.toml; --quick skips the 3x mesh.
"""

import argparse
import dataclasses
import json
import pathlib

import numpy as np

from railslosh import scene, slosh
from railslosh.swri_cases import PEAK_AFTER, peak_loads

ROOT = pathlib.Path(__file__).resolve().parent.parent


def peaks(sc: scene.SloshScene, penalty_factor: float = 1.0) -> dict:
    (mesh, fluid, tank, motion), kw = sc.run_args()
    if penalty_factor != 1.0:
        # the scene's own penalty (railslosh.scene.SloshScene.run_args), scaled
        custom = {**sc.fluid.custom, "bulk_penalty": fluid.bulk_penalty * penalty_factor}
        sc = dataclasses.replace(sc, fluid=dataclasses.replace(sc.fluid, custom=custom))
        (mesh, fluid, tank, motion), kw = sc.run_args()
    res = slosh.run(mesh, fluid, tank, motion, **kw)
    p = peak_loads(res)  # as railslosh validate swri-maneuvers reads them
    # the ringing: the strongest frequency above 20 Hz of |F| less its centred 20 ms moving average,
    # over 0.2-0.6 s (the front wheel meets the bump at 0.2 s)
    t = np.asarray(res["t"])
    raw = np.linalg.norm(np.asarray(res["force_tank"]), axis=1)
    tu = np.arange(PEAK_AFTER, PEAK_AFTER + 0.4, 2e-4)
    fu = np.interp(tu, t, raw)
    wide = np.interp(np.arange(PEAK_AFTER - 0.01, PEAK_AFTER + 0.41, 2e-4), t, raw)
    avg = np.convolve(wide, np.ones(100) / 100, mode="same")[50 : 50 + tu.size]
    spec = np.abs(np.fft.rfft((fu - avg) * np.hanning(tu.size)))
    freq = np.fft.rfftfreq(tu.size, 2e-4)
    ring = freq[freq > 20.0][np.argmax(spec[freq > 20.0])]
    return {
        "raw_peak_N": round(p.raw, 1),
        "raw_peak_t": round(p.raw_time, 4),
        "lowpass_peak_N": round(p.filtered, 1),
        "lowpass_peak_t": round(p.filtered_time, 3),
        "ringing_Hz": round(float(ring), 1),
        "steps": int(t.size),
    }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scene", nargs="?", default=str(ROOT / "examples/scenes/swri_bump_half_round_12in_5mph.toml"))
    p.add_argument("--quick", action="store_true", help="leave out the 3x mesh")
    a = p.parse_args()
    base = scene.load_scene(a.scene)
    if not isinstance(base, scene.SloshScene):
        raise SystemExit(f"{a.scene}: not a slosh scene (a [maneuver] scene with prescribed tank motion)")

    def refined(n: int) -> scene.SloshScene:
        counts = tuple(n * c for c in base.fluid.counts)
        return dataclasses.replace(base, fluid=dataclasses.replace(base.fluid, counts=counts))

    variants = [("shipped", base, 1.0), ("mesh x2", refined(2), 1.0)]
    if not a.quick:
        variants.append(("mesh x3", refined(3), 1.0))
    variants += [
        ("step 2 ms", dataclasses.replace(base, step=0.002), 1.0),
        ("penalty x4", base, 4.0),
        ("wall stiffness x4", dataclasses.replace(base, contact_stiffness_factor=4.0), 1.0),
        (
            "wall damping ratio 2",
            dataclasses.replace(base, fluid=dataclasses.replace(base.fluid, wall_damping_ratio=2.0)),
            1.0,
        ),
    ]
    for name, sc, kfac in variants:
        print(json.dumps({"variant": name, "mesh": list(sc.fluid.counts), **peaks(sc, kfac)}), flush=True)


if __name__ == "__main__":
    main()
