"""Seed 003 §4.2: a liquid tank on a centrifuge arm, free to slide radially on an undamped spring.

"When the mass of the tank is small relative to the mass of the fluid the solution quickly becomes
unstable": the explicit Glue Code hands the vehicle code an *extrapolated* fluid load, and the part
of that load that reacts instantaneously to the tank acceleration (the carried, "added" mass) is
then one window late.

**Linear stability of the explicit scheme.** Along the slider the fluid load is
F_r = -m_a a_r + (smooth terms), m_a the radial added mass (:meth:`PendulumSlosh.added_mass`:
m_a = m0 + m1 sin²θ, the rigid mass plus the bob's share along the rod). The vehicle computes
its window-end acceleration from the extrapolated load, m_t a_{n+1} = E(F)_{n+1} + (smooth), and
the slosh participant returns F_{n+1} = -m_a a_{n+1} + (smooth). A perturbation δF therefore obeys

    δF_{n+1} = -r Σ_j c_j δF_{n-j},   r = m_a / m_t,

with the extrapolation weights c = (1), (2, -1), (3, -3, 1) for 1, 2, 3 samples. Its
characteristic polynomial z^{p+1} + r Σ_j c_j z^{p-j} has spectral radius 1 first at z = -1
(the sign-alternating mode), where r Σ|c_j| = 1: the scheme is stable for

    r < r* = 1 / (2^{p+1} - 1) = 1, 1/3, 1/7     (constant, linear, quadratic extrapolation).

Seed 003's three-sample extrapolation therefore needs a tank **at least 7 times heavier than the
liquid it carries rigidly**; the threshold is independent of the window size to leading order
(the smooth terms only enter at O(H²)). :func:`explicit_spectral_radius` computes the roots,
:func:`predicted_threshold` turns r* into a tank/liquid mass ratio at the steady spin state, and
:func:`measured_threshold` bisects over the mass ratio with real co-simulation runs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from railslosh.constants import GRAVITY
from railslosh.cosim import monolithic
from railslosh.cosim.emulators import (
    CentrifugeArm,
    PendulumSlosh,
    SloshParameters,
    horizontal_cylinder,
)
from railslosh.cosim.masters import CouplingResult, couple
from railslosh.cosim.protocol import check_positive, invalid

EXTRAPOLATION_WEIGHTS = {0: (1.0,), 1: (2.0, -1.0), 2: (3.0, -3.0, 1.0)}


def explicit_spectral_radius(r: float, order: int = 2) -> float:
    """Largest |z| of z^{p+1} + r Σ c_j z^{p-j} = 0 (p = ``order``): the per-window amplification of
    a load perturbation in explicit coupling with added-mass ratio r = m_a / m_t."""
    if order not in EXTRAPOLATION_WEIGHTS:
        raise invalid("order", order, "0, 1 or 2")
    c = EXTRAPOLATION_WEIGHTS[order]
    return float(np.max(np.abs(np.roots([1.0, *(r * cj for cj in c)]))))


def critical_ratio(order: int = 2, *, overestimate: bool = False) -> float:
    """Smallest r > 0 where :func:`explicit_spectral_radius` reaches 1 (root solve; analytically
    1/(2^{p+1}-1) for the plain scheme).

    ``overestimate``: added-mass splitting with an estimate M_s larger than the true m_a leaves the
    exchanged load L + M_s a = (M_s - m_a) a + ..., a perturbation ratio of the opposite sign,
    -r with r = (M_s - m_a)/(m_t + M_s); the polynomial is then z^{p+1} - r Σ c_j z^{p-j}
    (thresholds 1, 1, 1/2 for p = 0, 1, 2)."""
    from scipy.optimize import brentq

    sign = -1.0 if overestimate else 1.0
    rs = np.linspace(1e-3, 2.0, 2000)
    rho = np.array([explicit_spectral_radius(sign * r, order) for r in rs])
    i = int(np.argmax(rho >= 1.0 - 1e-12))
    if i == 0:
        return float(rs[0])
    return brentq(lambda r: explicit_spectral_radius(sign * r, order) - 1.0, rs[i - 1], rs[i], xtol=1e-14)


@dataclass(frozen=True)
class CentrifugeCase:
    """The centrifuge of seed 003 §4.2 with a short horizontal cylinder (axis tangential) instead of
    the sphere: radius 0.5 m, length 1 m, half full of water (M = 392.7 kg, λ = 1.3557, f1 = 0.82 Hz);
    arm radius 2 m, spin-up to 2 rad/s within the first 45° (seed 003), undamped radial spring with
    k = (m_t + M) ω_s², ω_s = 6 rad/s; pendulum damping ratio 0.02."""

    tank_radius: float = 0.5
    tank_length: float = 1.0
    fill: float = 0.5
    arm_radius: float = 2.0
    spin_rate: float = 2.0
    spinup_angle: float = math.pi / 4
    spring_frequency: float = 6.0
    damping_ratio: float = 0.02
    lam: float | None = 1.3557

    def slosh_parameters(self) -> SloshParameters:
        return horizontal_cylinder(self.tank_radius, self.tank_length, self.fill, lam=self.lam)

    @property
    def fluid_mass(self) -> float:
        return self.slosh_parameters().fluid_mass

    def build(self, mass_ratio: float, *, steady: bool = False, perturbation: float = 0.0):
        """(vehicle, slosh) for tank mass = ``mass_ratio`` x liquid mass. ``steady``: start at the
        steady spin equilibrium (constant rate from t = 0), pendulum angle offset by ``perturbation``."""
        mass_ratio = check_positive("mass_ratio", mass_ratio)
        P = self.slosh_parameters()
        mt = mass_ratio * P.fluid_mass
        k = (mt + P.fluid_mass) * self.spring_frequency**2
        if steady:
            s, th = self.steady_state(mass_ratio)
            v = CentrifugeArm(mt, self.arm_radius, k, self.spin_rate, spinup_angle=0.0, s0=s)
            return v, PendulumSlosh(P, damping_ratio=self.damping_ratio, theta0=th + perturbation)
        v = CentrifugeArm(mt, self.arm_radius, k, self.spin_rate, spinup_angle=self.spinup_angle)
        return v, PendulumSlosh(P, damping_ratio=self.damping_ratio, theta0=perturbation)

    def steady_state(self, mass_ratio: float) -> tuple[float, float]:
        """Radial displacement s and pendulum angle θ of the steady spin (s'' = θ'' = 0)."""
        from scipy.optimize import fsolve

        P = self.slosh_parameters()
        mt = mass_ratio * P.fluid_mass
        k = (mt + P.fluid_mass) * self.spring_frequency**2
        v = CentrifugeArm(mt, self.arm_radius, k, self.spin_rate, spinup_angle=0.0)
        sl = PendulumSlosh(P)
        acc0 = self.arm_radius * self.spin_rate**2

        def f(x):
            y = np.array([x[0], 0.0, x[1], 0.0])
            d = monolithic.rhs(v, sl, 1.0, y)
            return [d[1], d[3]]

        x = fsolve(f, [acc0 / self.spring_frequency**2, -math.atan2(acc0, GRAVITY)], xtol=1e-13)
        return float(x[0]), float(x[1])

    def added_mass_ratio(self, mass_ratio: float, theta: float | None = None) -> float:
        """r = m_a / m_t along the slider (J^T M_a J / m_t) at angle θ (default: steady state)."""
        _, slosh = self.build(mass_ratio)
        if theta is None:
            theta = self.steady_state(mass_ratio)[1]
        ma = slosh.added_mass_at(theta)[1, 1]
        return float(ma / (mass_ratio * slosh.params.fluid_mass))


def predicted_threshold(case: CentrifugeCase, order: int = 2) -> float:
    """Tank/liquid mass ratio μ* below which explicit coupling is unstable at the steady spin:
    r(μ*) = r*, i.e. μ* = m_a(θ_ss(μ*)) / (M r*)."""
    from scipy.optimize import brentq

    rc = critical_ratio(order)
    return brentq(lambda mu: case.added_mass_ratio(mu) - rc, 0.05, 100.0, xtol=1e-8)


def divergence_growth(result: CouplingResult) -> float:
    """Growth of the window-to-window oscillation of the radial load: ratio of the largest third
    difference |Δ³F_y| over the last quarter of the run to that over the second quarter
    (the first quarter holds the start-up). Large (>> 1) or infinite for an unstable run."""
    if result.diverged:
        return math.inf
    d = np.abs(np.diff(result.load[:, 1], 3))
    n = len(d)
    early = np.max(d[n // 4 : n // 2]) if n >= 8 else np.max(d)
    late = np.max(d[3 * n // 4 :]) if n >= 8 else np.max(d)
    return float(late / max(early, 1e-300))


def explicit_diverges(
    case: CentrifugeCase, mass_ratio: float, *, window: float, t_end: float, steady: bool = True, order: int = 2
) -> bool:
    """One explicit run; diverged if it blew up or its alternating load component grew > 10x."""
    v, s = case.build(mass_ratio, steady=steady, perturbation=0.02 if steady else 0.0)
    res = couple(v, s, t_end=t_end, window=window, scheme="explicit", extrapolation_order=order)
    return divergence_growth(res) > 10.0


def measured_threshold(
    case: CentrifugeCase,
    *,
    window: float = 0.01,
    t_end: float = 4.0,
    steady: bool = True,
    lo: float = 1.0,
    hi: float = 20.0,
    rel_tol: float = 0.01,
    order: int = 2,
) -> float:
    """Bisection (in log μ) for the tank/liquid mass ratio where explicit coupling turns unstable."""
    if explicit_diverges(case, hi, window=window, t_end=t_end, steady=steady, order=order):
        raise invalid("hi", hi, "a mass ratio at which explicit coupling is stable")
    if not explicit_diverges(case, lo, window=window, t_end=t_end, steady=steady, order=order):
        raise invalid("lo", lo, "a mass ratio at which explicit coupling diverges")
    while hi / lo > 1 + rel_tol:
        mid = math.sqrt(lo * hi)
        if explicit_diverges(case, mid, window=window, t_end=t_end, steady=steady, order=order):
            lo = mid
        else:
            hi = mid
    return math.sqrt(lo * hi)


def compare_schemes(case: CentrifugeCase, mass_ratio: float, *, window: float, t_end: float, **kw) -> dict:
    """Run explicit, Aitken, IQN-ILS and explicit with added-mass splitting against the monolithic
    solution; return per scheme: diverged, max radial-position error (m), mean iterations."""
    v, s = case.build(mass_ratio)
    n = int(round(t_end / window))
    ref = monolithic.solve(v, s, t_end=t_end, t_eval=np.linspace(0.0, t_end, n + 1))
    out = {"monolithic": {"s_max": float(np.max(ref.vehicle_state[:, 0]))}}
    for name, scheme, am in (
        ("explicit", "explicit", False),
        ("explicit+added-mass", "explicit", True),
        ("aitken", "aitken", False),
        ("iqn-ils", "iqn-ils", False),
    ):
        v, s = case.build(mass_ratio)
        res = couple(v, s, t_end=t_end, window=window, scheme=scheme, added_mass=am, **kw)
        m = len(res.t)
        err = float(np.max(np.abs(res.vehicle_state[:, 0] - ref.vehicle_state[:m, 0])))
        out[name] = {
            "diverged": bool(res.diverged or divergence_growth(res) > 10.0),
            "error": err if np.isfinite(err) else math.inf,
            "iterations": res.mean_iterations,
            "converged": res.converged,
        }
    return out


def main(argv: list[str] | None = None) -> int:
    """``python -m railslosh.cosim.centrifuge``: the threshold table of docs/cosim.md."""
    import argparse
    import time

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--windows", type=float, nargs="+", default=[0.005, 0.01, 0.02, 0.04])
    ap.add_argument("--t-end", type=float, default=4.0)
    ap.add_argument("--rel-tol", type=float, default=0.005)
    args = ap.parse_args(argv)
    case = CentrifugeCase()
    for order in (2, 1):
        rc = critical_ratio(order)
        mu_p = predicted_threshold(case, order)
        print(f"extrapolation order {order}: r* = {rc:.6f}; predicted tank/liquid mass threshold {mu_p:.4f}")
        for H in args.windows:
            t = time.perf_counter()
            kw = dict(window=H, t_end=args.t_end, lo=0.3 * mu_p, hi=3 * mu_p, rel_tol=args.rel_tol, order=order)
            mu_s = measured_threshold(case, steady=True, **kw)
            mu_u = measured_threshold(case, steady=False, **kw)
            print(
                f"  window {H:g} s: measured steady spin {mu_s:.4f} ({mu_s / mu_p - 1:+.2%}), "
                f"seed spin-up {mu_u:.4f} ({mu_u / mu_p - 1:+.2%})  [{time.perf_counter() - t:.1f} s]"
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())


__all__ = [
    "CentrifugeCase",
    "compare_schemes",
    "critical_ratio",
    "explicit_spectral_radius",
    "measured_threshold",
    "predicted_threshold",
]
