"""Coupling masters: explicit serial coupling (seed 003's Glue Code) and implicit coupling per
window with Aitken relaxation or interface quasi-Newton (IQN-ILS), optional added-mass splitting.

Time is cut into windows of length ``window``; each window has ``substeps`` exchange nodes
τ_j = t_n + j H/m (j = 1..m). Data between nodes vary linearly (the participants' ``advance``
contract).

**explicit** (serial, vehicle first: "the MSS code is always ahead of the CFD code", seed 003
§2.3.1). The vehicle advances over the window under loads *extrapolated* at the nodes by the
polynomial through the last three window-end loads; the slosh participant then advances under
motions *interpolated* through the last three window-end motions (t_{n-1}, t_n, t_{n+1}). One
pass per window; the error of the extrapolated load is O(H³) per node, the scheme is
second-order overall with the linear-in-window data (measured in the tests).

**aitken**, **iqn-ils** (implicit, serial Gauss–Seidel). Per window both participants are
checkpointed (``save_state``); the unknown is the vector X of exchanged loads at the m nodes. One
iteration: restore, vehicle under X, slosh under the resulting motions, giving X̃ = H(X) and the
residual r = X̃ - X. Converged when ‖r‖ ≤ atol + rtol ‖X̃‖. Updates:

* Aitken (Küttler & Wall 2008): X ← X + ω_k r_k, ω_k = -ω_{k-1} r_{k-1}·(r_k - r_{k-1}) / ‖r_k - r_{k-1}‖²,
  ω_0 = ``relaxation``;
* IQN-ILS (Degroote et al. 2009): with V = [r_k - r_i], W = [X̃_k - X̃_i] (this window, plus the
  last ``reuse`` converged windows), c = argmin ‖V c + r_k‖, X ← X̃_k + W c; the first iteration
  of a window without reused columns is a relaxation step with ``relaxation``.

**Added-mass splitting** (``added_mass=True``): at each window start the slosh participant's
``added_mass()`` M_a is moved to the vehicle (``set_added_mass``), which then carries M + Jᵀ M_a J;
the exchanged load is L_x = L + M_a [a, α] (the part of the load that does not react
instantaneously to the tank acceleration), so the instability driven by M_a disappears when
the estimate is good.

Every scheme starts from a consistent initial pair (load, motion) at t0, found by the IQN-ILS
iteration on a zero-length window (``slosh.set_initial_input(motion)`` where the participant has
it, as ``railslosh._core.SloshParticipant`` does, else ``slosh.advance(t0, motion, motion)``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from railslosh.cosim.interp import ThreeSampleHistory
from railslosh.cosim.protocol import (
    SloshParticipant,
    VehicleParticipant,
    check_positive,
    invalid,
    motion_acceleration6,
    motion_to_vector,
    vector_to_motion,
)

SCHEMES = ("explicit", "aitken", "iqn-ils")


@dataclass
class CouplingResult:
    """Histories at the window ends (index 0 = t0). ``load``: fluid load on the tank (6);
    ``motion``: tank-motion 12-vectors (order of protocol.MOTION_KEYS); ``vehicle_state``: the
    vehicle's ``state`` attribute when it has one. Per window: ``iterations`` (1 for explicit),
    ``residual`` (final residual norm; NaN for explicit) and ``residual_history``. ``diverged``:
    the run stopped on a non-finite or exploding load (``t_stop``), or an implicit window did not
    converge within ``max_iterations`` (``converged`` False, the run goes on)."""

    scheme: str
    window: float
    t: np.ndarray
    load: np.ndarray
    motion: np.ndarray
    vehicle_state: np.ndarray
    iterations: np.ndarray
    residual: np.ndarray
    residual_history: list[list[float]] = field(default_factory=list)
    diverged: bool = False
    converged: bool = True
    t_stop: float = math.nan

    @property
    def mean_iterations(self) -> float:
        return float(np.mean(self.iterations)) if len(self.iterations) else 0.0


def _state_of(vehicle) -> np.ndarray:
    s = getattr(vehicle, "state", None)
    return np.asarray(s, float).copy() if s is not None else np.zeros(0)


class Accelerator:
    """Aitken or IQN-ILS update of a fixed-point iteration X -> H(X) (see the module docstring).

    ``start()`` begins a new fixed-point problem (a window); ``update(x, H(x))`` returns the next
    iterate; ``end_window()`` keeps the window's IQN columns for ``reuse`` later windows."""

    def __init__(self, scheme: str, relaxation: float = 0.1, reuse: int = 0, filter_eps: float = 1e-8):
        if scheme not in ("aitken", "iqn-ils"):
            raise invalid("scheme", scheme, '"aitken" or "iqn-ils"')
        self.scheme = scheme
        self.omega0 = relaxation
        self.reuse = reuse
        self.eps = filter_eps
        self.old: list[tuple[np.ndarray, np.ndarray]] = []  # (V, W) of previous windows

    def start(self) -> None:
        self.r_prev: np.ndarray | None = None
        self.omega = self.omega0
        self.R: list[np.ndarray] = []
        self.Xt: list[np.ndarray] = []

    def update(self, x: np.ndarray, xt: np.ndarray) -> np.ndarray:
        r = xt - x
        if self.scheme == "aitken":
            if self.r_prev is not None:
                dr = r - self.r_prev
                den = float(dr @ dr)
                if den > 0:
                    self.omega = -self.omega * float(self.r_prev @ dr) / den
            self.r_prev = r
            return x + self.omega * r
        # IQN-ILS
        self.R.append(r)
        self.Xt.append(xt)
        cols_v = [r - ri for ri in self.R[:-1]]
        cols_w = [xt - xi for xi in self.Xt[:-1]]
        V = np.column_stack(cols_v[::-1]) if cols_v else np.zeros((len(r), 0))
        W = np.column_stack(cols_w[::-1]) if cols_w else np.zeros((len(r), 0))
        for Vo, Wo in self.old:
            V = np.hstack([V, Vo])
            W = np.hstack([W, Wo])
        if V.shape[1] == 0:
            return x + self.omega0 * r
        # QR filter: drop columns that add less than eps of their norm (newest columns first)
        keep: list[int] = []
        Q = np.zeros((len(r), 0))
        for j in range(V.shape[1]):
            v = V[:, j]
            nv = np.linalg.norm(v)
            if nv == 0:
                continue
            res = v - Q @ (Q.T @ v)
            nres = np.linalg.norm(res)
            if nres > self.eps * nv:
                Q = np.column_stack([Q, res / nres])
                keep.append(j)
        if not keep:
            return x + self.omega0 * r
        c, *_ = np.linalg.lstsq(V[:, keep], -r, rcond=None)
        return xt + W[:, keep] @ c

    def end_window(self) -> None:
        if self.scheme != "iqn-ils" or self.reuse <= 0 or len(self.R) < 2:
            return
        r, xt = self.R[-1], self.Xt[-1]
        V = np.column_stack([r - ri for ri in self.R[:-1]])
        W = np.column_stack([xt - xi for xi in self.Xt[:-1]])
        self.old.insert(0, (V, W))
        del self.old[self.reuse :]


def _checked_options(
    scheme: str,
    window: float,
    substeps: int,
    rtol: float,
    atol: float,
    max_iterations: int,
    relaxation: float,
    reuse: int,
    filter_eps: float,
    blowup: float,
) -> tuple[float, float, float, float, float, float]:
    """:func:`couple`'s options checked: (window, rtol, atol, relaxation, filter_eps, blowup)."""
    if scheme not in SCHEMES:
        raise invalid("scheme", scheme, f"one of {list(SCHEMES)}")
    window = check_positive("window", window)
    rtol = check_positive("rtol", rtol, allow_zero=True)
    atol = check_positive("atol", atol, allow_zero=True)
    relaxation = check_positive("relaxation", relaxation)
    filter_eps = check_positive("filter_eps", filter_eps, allow_zero=True)
    blowup = check_positive("blowup", blowup)
    if not isinstance(substeps, int | np.integer) or substeps < 1:
        raise invalid("substeps", substeps, "an integer >= 1")
    if not isinstance(max_iterations, int | np.integer) or max_iterations < 1:
        raise invalid("max_iterations", max_iterations, "an integer >= 1")
    if not isinstance(reuse, int | np.integer) or reuse < 0:
        raise invalid("reuse", reuse, "an integer >= 0")
    if rtol == 0 and atol == 0:
        raise invalid("rtol, atol", (rtol, atol), "at least one > 0")
    return window, rtol, atol, relaxation, filter_eps, blowup


def _windows(vehicle: VehicleParticipant, slosh: SloshParticipant, t_end: float, window: float) -> tuple[float, int]:
    """The common start time of the participants and the number of windows to ``t_end``."""
    t0 = float(vehicle.time)
    if abs(float(slosh.time) - t0) > 1e-12:
        raise invalid("slosh.time", slosh.time, f"equal to vehicle.time = {t0}")
    t_end = float(t_end)
    if not math.isfinite(t_end) or t_end <= t0:
        raise invalid("t_end", t_end, f"a finite time > start time {t0}")
    n_win = max(1, int(round((t_end - t0) / window)))
    if abs(n_win * window - (t_end - t0)) > 1e-9 * max(1.0, t_end - t0):
        raise invalid("window", window, f"a divisor of t_end - t0 = {t_end - t0}")
    return t0, n_win


def _consistent_start(
    vehicle: VehicleParticipant, slosh: SloshParticipant, t0: float, ma: np.ndarray | None, filter_eps: float
) -> tuple[np.ndarray, np.ndarray]:
    """Consistent start: the zero-length window at ``t0`` solved by IQN-ILS; (fluid load L,
    vehicle motion m) at ``t0``."""
    init = Accelerator("iqn-ils", 0.5, 0, filter_eps)
    init.start()
    sv, ss = vehicle.save_state(), slosh.save_state()
    x = np.zeros(6)
    for _ in range(50):
        vehicle.restore_state(sv)
        slosh.restore_state(ss)
        m = motion_to_vector(vehicle.advance(t0, x, x))
        if hasattr(slosh, "set_initial_input"):  # participants that reject zero-length advances (the Rust one)
            f, mo = slosh.set_initial_input(vector_to_motion(m))
        else:
            f, mo = slosh.advance(t0, vector_to_motion(m), vector_to_motion(m))
        L = np.concatenate([np.asarray(f, float), np.asarray(mo, float)])
        xt = L if ma is None else L + ma @ motion_acceleration6(vector_to_motion(m))
        if np.linalg.norm(xt - x) <= 1e-12 * max(1.0, np.linalg.norm(xt)):
            break
        x = init.update(x, xt)
    return L, m


def couple(
    vehicle: VehicleParticipant,
    slosh: SloshParticipant,
    *,
    t_end: float,
    window: float,
    scheme: str = "explicit",
    substeps: int = 1,
    added_mass: bool = False,
    rtol: float = 1e-10,
    atol: float = 1e-8,
    max_iterations: int = 50,
    relaxation: float = 0.1,
    reuse: int = 0,
    filter_eps: float = 1e-8,
    extrapolation_order: int = 2,
    blowup: float = 1e3,
) -> CouplingResult:
    """Run the co-simulation of ``vehicle`` and ``slosh`` from their common current time to
    ``t_end`` with the given scheme (see the module docstring).

    ``blowup``: the run stops as diverged when a load exceeds ``blowup`` times the largest load of
    the first window (or is not finite). ``extrapolation_order``: 2 = seed 003's three samples;
    0 and 1 use fewer samples (used for the stability analysis)."""
    window, rtol, atol, relaxation, filter_eps, blowup = _checked_options(
        scheme, window, substeps, rtol, atol, max_iterations, relaxation, reuse, filter_eps, blowup
    )
    t0, n_win = _windows(vehicle, slosh, t_end, window)

    acc = Accelerator(scheme if scheme != "explicit" else "iqn-ils", relaxation, reuse, filter_eps)

    def current_ma() -> np.ndarray | None:
        if not added_mass:
            return None
        ma = np.asarray(slosh.added_mass(), dtype=float)
        if ma.shape != (6, 6) or not np.all(np.isfinite(ma)):
            raise invalid("slosh.added_mass()", ma, "a finite 6x6 matrix")
        return ma

    def vehicle_window(nodes: list[float], x_start: np.ndarray, loads_x: np.ndarray) -> list[np.ndarray]:
        """Vehicle under the exchanged loads (m x 6) at the nodes; its motions (12) at the nodes."""
        motions = []
        prev_l = x_start
        for tj, lj in zip(nodes, loads_x, strict=True):
            motions.append(motion_to_vector(vehicle.advance(tj, prev_l, lj)))
            prev_l = lj
        return motions

    def slosh_window(nodes: list[float], m_start: np.ndarray, motions: list[np.ndarray], ma):
        """Slosh participant under the motions at the nodes: (loads, exchanged loads), m x 6 each."""
        loads, exch = [], []
        prev_m = m_start
        for tj, mj in zip(nodes, motions, strict=True):
            f, mo = slosh.advance(tj, vector_to_motion(prev_m), vector_to_motion(mj))
            L = np.concatenate([np.asarray(f, float), np.asarray(mo, float)])
            loads.append(L)
            exch.append(L if ma is None else L + ma @ motion_acceleration6(vector_to_motion(mj)))
            prev_m = mj
        return np.array(loads), np.array(exch)

    # ---- consistent start: zero-length window solved by IQN-ILS ---------------------------
    ma = current_ma()
    if added_mass:
        vehicle.set_added_mass(ma)
    L, m = _consistent_start(vehicle, slosh, t0, ma, filter_eps)
    load_hist = ThreeSampleHistory(extrapolation_order)  # fluid loads L at window ends
    acc_hist = ThreeSampleHistory(extrapolation_order)  # [a, α] at window ends
    motion_hist = ThreeSampleHistory(2)
    load_hist.push(t0, L)
    acc_hist.push(t0, motion_acceleration6(vector_to_motion(m)))
    motion_hist.push(t0, m)
    scale = max(float(np.max(np.abs(L))), 1.0)

    ts, loads, motions, states = [t0], [L], [m], [_state_of(vehicle)]
    iters, resid, rhist = [], [], []
    out = CouplingResult(
        scheme, window, np.array([]), np.array([]), np.array([]), np.array([]), np.array([]), np.array([])
    )

    def exchanged_extrapolation(tau: float, ma) -> np.ndarray:
        Lp = load_hist(tau)
        return Lp if ma is None else Lp + ma @ acc_hist(tau)

    for k in range(n_win):
        ta = t0 + k * window
        tb = t0 + (k + 1) * window
        nodes = [ta + (j + 1) * (tb - ta) / substeps for j in range(substeps)]
        nodes[-1] = tb
        ma = current_ma()
        if ma is not None:
            vehicle.set_added_mass(ma)
        L_a, m_a = loads[-1], motions[-1]
        x_start = L_a if ma is None else L_a + ma @ np.concatenate([m_a[0:3], m_a[6:9]])
        X = np.array([exchanged_extrapolation(tj, ma) for tj in nodes])
        if scheme == "explicit":
            mot = vehicle_window(nodes, x_start, X)
            motion_hist.push(tb, mot[-1])
            mot_i = [motion_hist(tj) for tj in nodes[:-1]] + [mot[-1]]
            Ls, _ = slosh_window(nodes, m_a, mot_i, ma)
            iters.append(1)
            resid.append(math.nan)
            rhist.append([])
        else:
            sv, ss = vehicle.save_state(), slosh.save_state()
            acc.start()
            hist = []
            ok = False
            for it in range(1, max_iterations + 1):
                if it > 1:
                    vehicle.restore_state(sv)
                    slosh.restore_state(ss)
                mot = vehicle_window(nodes, x_start, X)
                Ls, Xt = slosh_window(nodes, m_a, mot, ma)
                r = float(np.linalg.norm(Xt - X))
                hist.append(r)
                if not np.all(np.isfinite(Xt)):
                    break
                if r <= atol + rtol * float(np.linalg.norm(Xt)):
                    ok = True
                    break
                if it == max_iterations:
                    break
                X = acc.update(X.ravel(), Xt.ravel()).reshape(X.shape)
            acc.end_window()
            if not ok:
                out.converged = False
            motion_hist.push(tb, mot[-1])
            iters.append(it)
            resid.append(hist[-1])
            rhist.append(hist)
        L_b, m_b = Ls[-1], mot[-1]
        load_hist.push(tb, L_b)
        acc_hist.push(tb, np.concatenate([m_b[0:3], m_b[6:9]]))
        ts.append(tb)
        loads.append(L_b)
        motions.append(np.asarray(m_b))
        states.append(_state_of(vehicle))
        if not np.all(np.isfinite(L_b)) or np.max(np.abs(L_b)) > blowup * scale:
            out.diverged = True
            out.t_stop = tb
            break
    out.t = np.array(ts)
    out.load = np.array(loads)
    out.motion = np.array(motions)
    out.vehicle_state = np.array(states)
    out.iterations = np.array(iters, dtype=int)
    out.residual = np.array(resid)
    out.residual_history = rhist
    return out
