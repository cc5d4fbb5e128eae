"""Monolithic reference: a vehicle emulator and the pendulum slosh emulator as one ODE system.

State (q, q', θ, θ'). At each right-hand side the slosh load is split exactly as
L = L0(θ, θ', ω, g) - M_a(θ) [a, α] (:meth:`PendulumSlosh.load_split`) and the tank kinematics
as [a, α] = J q'' + j0, so the accelerations solve the *coupled* system

    (M + Jᵀ M_a J) q'' = Q + Jᵀ (L0 - M_a j0),

after which θ'' follows from the pendulum equation with the resulting tank motion. No coupling
error is left; the ODE is integrated by scipy's ``solve_ivp`` (DOP853 by default, Radau for
stiff variants) with tight tolerances.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from railslosh.cosim.emulators import PendulumSlosh, RigidTankVehicle
from railslosh.cosim.protocol import check_positive, invalid, motion_to_vector


@dataclass
class MonolithicResult:
    """Histories at ``t``: vehicle state (q, q'), pendulum state (θ, θ'), fluid load (6) and
    tank motion (12, order of protocol.MOTION_KEYS)."""

    t: np.ndarray
    vehicle_state: np.ndarray
    slosh_state: np.ndarray
    load: np.ndarray
    motion: np.ndarray


def _accelerations(vehicle: RigidTankVehicle, slosh: PendulumSlosh, t: float, y: np.ndarray):
    n = vehicle.n_dof
    q, qd, ys = y[:n], y[n : 2 * n], y[2 * n :]
    J, j0, w, g = vehicle.kinematics(t, q, qd)
    L0, ma = slosh.load_split(ys, w, g)
    M = vehicle.mass(q) + J.T @ ma @ J
    qdd = np.linalg.solve(M, vehicle.applied(t, q, qd) + J.T @ (L0 - ma @ j0))
    motion = vehicle.motion_from(t, y[: 2 * n], qdd)
    return qdd, motion


def rhs(vehicle: RigidTankVehicle, slosh: PendulumSlosh, t: float, y: np.ndarray) -> np.ndarray:
    n = vehicle.n_dof
    qdd, motion = _accelerations(vehicle, slosh, t, y)
    ys = y[2 * n :]
    return np.concatenate([y[n : 2 * n], qdd, [ys[1], slosh.theta_ddot(ys, motion)]])


def solve(
    vehicle: RigidTankVehicle,
    slosh: PendulumSlosh,
    *,
    t_end: float,
    t_eval: np.ndarray | None = None,
    method: str = "DOP853",
    rtol: float = 1e-11,
    atol: float = 1e-11,
) -> MonolithicResult:
    """Integrate the coupled system from the emulators' current states to ``t_end``."""
    if method not in ("DOP853", "Radau", "RK45", "LSODA", "BDF"):
        raise invalid("method", method, "one of DOP853, Radau, RK45, LSODA, BDF")
    check_positive("rtol", rtol)
    check_positive("atol", atol)
    from scipy.integrate import solve_ivp  # imported here: keeps `import railslosh.cosim` light

    t0 = vehicle.time
    if not t_end > t0:
        raise invalid("t_end", t_end, f"> start time {t0}")
    y0 = np.concatenate([vehicle.state, slosh.state])
    sol = solve_ivp(
        lambda t, y: rhs(vehicle, slosh, t, y), (t0, t_end), y0, method=method, rtol=rtol, atol=atol, t_eval=t_eval
    )
    if not sol.success:
        raise RuntimeError(f"monolithic solve failed: {sol.message}")
    n = vehicle.n_dof
    loads, motions = [], []
    for t, y in zip(sol.t, sol.y.T, strict=True):
        _, motion = _accelerations(vehicle, slosh, t, y)
        loads.append(slosh.load(y[2 * n :], motion))
        motions.append(motion_to_vector(motion))
    return MonolithicResult(sol.t, sol.y[: 2 * n].T, sol.y[2 * n :].T, np.array(loads), np.array(motions))
