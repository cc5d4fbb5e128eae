"""Validation cases of the co-simulation (``railslosh validate cosim-explicit-vs-monolithic
centrifuge-added-mass``). Records have the keys of :mod:`railslosh.validate`."""

from __future__ import annotations

import math

import numpy as np

from railslosh.cosim import monolithic
from railslosh.cosim.centrifuge import (
    CentrifugeCase,
    compare_schemes,
    critical_ratio,
    divergence_growth,
    measured_threshold,
    predicted_threshold,
)
from railslosh.cosim.emulators import PendulumSlosh, TankOnSprings, rectangular_tank
from railslosh.cosim.masters import couple
from railslosh.records import Record, at_most, less_than, within


def springs_pair(tank_mass: float = 2000.0):
    """Tank on a lateral spring (ω_s = 3 rad/s with the liquid, ζ ≈ 0.002) released from 5 cm, with a
    1 m x 0.5 m rectangular tank, 0.4 m of water sloshing along y (f1 = 0.815 Hz, damping 1 %)."""
    P = rectangular_tank(1.0, 0.5, 0.4, direction="y")
    k = (tank_mass + P.fluid_mass) * 9.0
    return TankOnSprings(tank_mass, k, 20.0, axes="y", q0=[0.05]), PendulumSlosh(P, damping_ratio=0.01)


def springs_errors(scheme: str, windows: list[float], t_end: float, **kw) -> list[float]:
    """Max |q - q_monolithic| over the window ends, divided by max |q_monolithic|, per window size."""
    out = []
    for H in windows:
        n = int(round(t_end / H))
        v, s = springs_pair()
        ref = monolithic.solve(v, s, t_end=t_end, t_eval=np.linspace(0.0, t_end, n + 1))
        v, s = springs_pair()
        res = couple(v, s, t_end=t_end, window=H, scheme=scheme, **kw)
        q, qr = res.vehicle_state[:, 0], ref.vehicle_state[:, 0]
        out.append(float(np.max(np.abs(q - qr[: len(q)])) / np.max(np.abs(qr))) if not res.diverged else math.inf)
    return out


def case_explicit_vs_monolithic(quick: bool) -> list[Record]:
    name = "cosim-explicit-vs-monolithic"
    t_end = 2.0 if quick else 6.0
    windows = [0.04, 0.02] if quick else [0.04, 0.02, 0.01]
    recs: list[Record] = []
    for scheme in ("explicit", "iqn-ils") if quick else ("explicit", "aitken", "iqn-ils"):
        errs = springs_errors(scheme, windows, t_end)
        recs.append(
            at_most(
                name,
                f"{scheme}: max |q - q_mono| / max |q_mono|, tank on spring + rectangular-tank pendulum, "
                f"window {windows[-1]} s, {t_end} s",
                errs[-1],
                2e-3,
            )
        )
        orders = [math.log2(errs[i] / errs[i + 1]) for i in range(len(errs) - 1)]
        recs.append(
            within(
                name,
                f"{scheme}: convergence order of that error, windows {windows[-2]} -> {windows[-1]} s",
                orders[-1],
                2.0,
                0.3,
            )
        )
    return recs


def case_centrifuge_added_mass(quick: bool) -> list[Record]:
    name = "centrifuge-added-mass"
    case = CentrifugeCase()
    recs: list[Record] = []
    rc = critical_ratio(2)
    recs.append(
        within(
            name,
            "critical added-mass ratio m_a/m_t of explicit 3-sample extrapolation (root solve vs 1/7)",
            rc,
            1 / 7,
            1e-9,
        )
    )
    mu_p = predicted_threshold(case)
    window = 0.01
    if quick:
        for f, expect in ((0.9, True), (1.1, False)):
            v, s = case.build(f * mu_p, steady=True, perturbation=0.02)
            g = divergence_growth(couple(v, s, t_end=3.0, window=window, scheme="explicit"))
            q = (
                f"explicit, steady spin, tank/liquid mass {f:g} x predicted threshold {mu_p:.3f}: "
                "growth of the load oscillation"
            )
            recs.append(less_than(name, q + " (> 10 = diverges)", -g, -10.0) if expect else less_than(name, q, g, 10.0))
    else:
        mu_m = measured_threshold(case, window=window, t_end=4.0, lo=2.0, hi=10.0, rel_tol=0.005)
        recs.append(
            within(
                name,
                f"explicit threshold tank/liquid mass ratio, steady spin, window {window} s: bisection vs linear "
                "theory (r* = 1/7 at the steady added mass)",
                mu_m,
                mu_p,
                0.05 * mu_p,
            )
        )
        mu_s = measured_threshold(case, window=window, t_end=6.0, steady=False, lo=2.0, hi=10.0, rel_tol=0.005)
        recs.append(
            within(
                name,
                "explicit threshold with seed 003's spin-up (45 deg), window 0.01 s, vs linear theory",
                mu_s,
                mu_p,
                0.1 * mu_p,
            )
        )
    mu_light = 1.0
    t_end = 2.0 if quick else 6.0
    res = compare_schemes(case, mu_light, window=0.02 if quick else 0.01, t_end=t_end, rtol=1e-9)
    recs.append(
        within(
            name,
            f"explicit diverges with tank mass = liquid mass (1 = diverged), spin-up, {t_end} s",
            float(res["explicit"]["diverged"]),
            1.0,
            0.0,
        )
    )
    for scheme in ("aitken", "iqn-ils", "explicit+added-mass"):
        recs.append(
            at_most(
                name,
                f"{scheme}, tank mass = liquid mass: max |s - s_mono| (m), spin-up, {t_end} s "
                f"(s_max = {res['monolithic']['s_max']:.3f} m; mean iterations {res[scheme]['iterations']:.2f})",
                res[scheme]["error"],
                2e-3 if quick else 1e-3,
            )
        )
    return recs


PY_CASES = {
    "cosim-explicit-vs-monolithic": (
        "explicit (seed 003 three-sample extrapolation), Aitken and IQN-ILS coupling of a tank on a spring with a "
        "pendulum slosh emulator vs the monolithic ODE: error and second-order convergence in the window size",
        case_explicit_vs_monolithic,
    ),
    "centrifuge-added-mass": (
        "seed 003 sec. 4.2 centrifuge: explicit coupling diverges below the tank/liquid mass ratio predicted by the "
        "linear theory (r* = 1/7); Aitken, IQN-ILS and added-mass splitting stay stable and match the monolithic "
        "solution",
        case_centrifuge_added_mass,
    ),
}
