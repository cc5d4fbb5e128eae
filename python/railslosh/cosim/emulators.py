"""Emulators (seed 003 §2.3): fast stand-ins for the vehicle code and for the slosh code.

Vehicle emulators (:class:`TankOnSprings`, :class:`CentrifugeArm`) are rigid tanks with a few
generalized coordinates q; the slosh emulator (:class:`PendulumSlosh`) is an equivalent
mechanical model: a rigidly carried mass m0 plus one pendulum (mass m1, length l1) for the first
sloshing mode. Its parameters come from the tank geometry through :func:`rectangular_tank` and
:func:`horizontal_cylinder`.

All emulators implement the participant protocols of :mod:`railslosh.cosim.protocol` and, for
the monolithic reference (:mod:`railslosh.cosim.monolithic`), expose their equations in split
form. Frames: tank axes K of docs/frames.md (x along the tank axis, y left, z up).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from railslosh import _core
from railslosh.constants import GRAVITY
from railslosh.cosim.protocol import (
    check_load,
    check_motion,
    check_positive,
    check_vector,
    invalid,
    motion_to_vector,
    vector_to_motion,
)


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b for 3-vectors (np.cross is ~20x slower for single vectors)."""
    a0, a1, a2 = a
    b0, b1, b2 = b
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def skew(p: np.ndarray) -> np.ndarray:
    """[p]x with [p]x v = p x v."""
    return np.array([[0.0, -p[2], p[1]], [p[2], 0.0, -p[0]], [-p[1], p[0], 0.0]])


def point_added_mass(mass: float, p: np.ndarray, free: np.ndarray | None = None) -> np.ndarray:
    """6x6 rigidly carried mass of a point mass at ``p`` (about the origin) whose acceleration
    follows the tank except along the unit directions in ``free`` (rows), which it does not
    feel instantaneously (the swing direction of a pendulum bob).

    With P = I - Σ f fᵀ and S = [p]x: M_a = m [[P, -P S], [S P, -S P S]] (load = -M_a [a, α])."""
    P = np.eye(3)
    if free is not None:
        for f in np.atleast_2d(free):
            P -= np.outer(f, f)
    S = skew(np.asarray(p, float))
    return mass * np.block([[P, -P @ S], [S @ P, -S @ P @ S]])


# --------------------------------------------------------------------------------------------
# Equivalent-model parameters from the tank geometry
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SloshParameters:
    """First-mode equivalent model: total liquid mass, sloshing mass m1 on a pendulum of length
    l1 (l1 = g/ω1²) hinged at ``hinge``, rigid mass m0 = M - m1 at ``rigid_point`` (tank axes),
    swinging about ``hinge_axis``."""

    fluid_mass: float
    sloshing_mass: float
    length: float
    hinge: tuple[float, float, float]
    rigid_point: tuple[float, float, float]
    hinge_axis: tuple[float, float, float]
    frequency: float
    """First-mode angular frequency ω1 = sqrt(g/l1), rad/s."""

    @property
    def rigid_mass(self) -> float:
        return self.fluid_mass - self.sloshing_mass


def rectangular_modes(length: float, depth: float, n_modes: int = 1, g: float = GRAVITY) -> list[tuple[float, float]]:
    """Antisymmetric sloshing modes of a rectangular tank, linear potential flow, per unit of
    liquid mass: list of (ω_n, m_n/M), n' = 2n - 1 (n = 1..n_modes).

    ω_n² = (g n'π/L) tanh(n'π h/L) (Lamb; seed 003 Fig. 4 computes f = 1.436 Hz for L = 0.324 m,
    h = 0.132 m with this formula); m_n/M = 8 tanh(n'π h/L) / (n'³ π³ h/L) (Graham & Rodriguez
    1952; Abramson NASA SP-106 ch. 6; Dodge 2000 ch. 3 — marked [mem] in
    notes/sloshing-validation-and-cosimulation.md §3, checked here by two exact identities that the
    tests assert: Σ m_n l_n = M L²/(12 h), the static-tilt shift of the liquid centroid, and
    Σ m_n -> M in the shallow limit, where all the liquid sloshes)."""
    length = check_positive("length", length)
    depth = check_positive("depth", depth)
    out = []
    for n in range(1, n_modes + 1):
        k = (2 * n - 1) * math.pi / length
        th = math.tanh(k * depth)
        out.append((math.sqrt(g * k * th), 8.0 * th / ((2 * n - 1) ** 3 * math.pi**3 * depth / length)))
    return out


def rectangular_tank(
    length: float, width: float, depth: float, *, direction: str = "y", density: float = 1000.0, g: float = GRAVITY
) -> SloshParameters:
    """Equivalent pendulum of a rectangular tank (liquid depth ``depth``, bottom at z = 0, centred
    in x and y), sloshing along ``direction`` ("x" or "y") whose tank dimension is ``length``.

    First mode of :func:`rectangular_modes`; all higher modes are lumped into the rigid mass.
    Placement (a choice, affects only moments): the rigid mass and the pendulum bob at rest both sit
    at the liquid centroid (0, 0, h/2), so the static weight moment and, to first order in the tilt,
    the static-tilt moment of mode 1 are exact; the Graham–Rodriguez heights are not used because we
    could not verify them."""
    length = check_positive("length", length)
    width = check_positive("width", width)
    depth = check_positive("depth", depth)
    density = check_positive("density", density)
    if direction not in ("x", "y"):
        raise invalid("direction", direction, '"x" or "y"')
    ((w1, frac),) = rectangular_modes(length, depth, 1, g)
    mass = density * length * width * depth
    l1 = g / w1**2
    zc = depth / 2
    axis = (0.0, 1.0, 0.0) if direction == "x" else (1.0, 0.0, 0.0)
    return SloshParameters(mass, frac * mass, l1, (0.0, 0.0, zc + l1), (0.0, 0.0, zc), axis, w1)


def segment_geometry(radius: float, depth: float) -> dict[str, float]:
    """Circular segment of liquid depth ``depth`` in a horizontal cylinder of radius R.

    cos α = (R - h)/R; free-surface half-width w = R sin α; area A = (R²/2)(2α - sin 2α);
    centroid depth below the axis d = 4 R sin³α / (3 (2α - sin 2α)) (notes §1b [derived]);
    metacentric radius BM = (2w)³ / (12 A), which equals d for a circle (metacentre on the axis)."""
    radius = check_positive("radius", radius)
    if not 0 < depth < 2 * radius:
        raise invalid("depth", depth, f"0 < depth < 2 R = {2 * radius}")
    alpha = math.acos((radius - depth) / radius)
    area = radius**2 / 2 * (2 * alpha - math.sin(2 * alpha))
    w = radius * math.sin(alpha)
    d = 4 * radius * math.sin(alpha) ** 3 / (3 * (2 * alpha - math.sin(2 * alpha)))
    return {
        "alpha": alpha,
        "area": area,
        "half_width": w,
        "centroid_depth": d,
        "metacentric_radius": (2 * w) ** 3 / (12 * area),
    }


def cylinder_lambda(fill: float, resolution: int = 24) -> float:
    """First antisymmetric transverse sloshing eigenvalue λ = ω1² R / g of a horizontal circular
    cylinder filled to depth h = fill · 2R (2D linear potential flow; no closed form exists).

    Solved as the Steklov problem Δφ = 0 in the circular segment, ∂φ/∂n = κ φ on the free
    surface, ∂φ/∂n = 0 on the wall, with P1 finite elements on a Delaunay mesh of the segment
    (``resolution`` elements across the diameter), Dirichlet-to-Neumann condensation onto the
    free surface and Richardson extrapolation over two meshes (error O(h²)). Checked in the tests
    against λ = 1.3557 at half fill (Budiansky 1960; McIver 1989; notes §1b [checked]) and the
    low-fill limit λ -> 1 (notes §1b [derived])."""
    if not 0 < fill < 1:
        raise invalid("fill", fill, "0 < fill < 1 (liquid depth / diameter)")
    if int(resolution) < 8:
        raise invalid("resolution", resolution, ">= 8")
    coarse = _steklov_lambda(fill, int(resolution))
    fine = _steklov_lambda(fill, 2 * int(resolution))
    return fine + (fine - coarse) / 3.0


def _steklov_lambda(fill: float, n: int) -> float:
    import scipy.sparse as sp  # imported here: scipy is slow to import and only this solve needs it
    import scipy.sparse.linalg as spla
    from scipy.linalg import eigh
    from scipy.spatial import Delaunay

    R = 1.0
    zs = 2 * R * fill - R
    hmesh = 2 * R / n
    alpha = math.acos(-zs / R)
    # boundary arc, free-surface row and interior rows
    n_arc = max(8, int(math.ceil(2 * alpha * R / hmesh)))
    phis = -math.pi / 2 + np.linspace(-alpha, alpha, n_arc + 1)
    pts = [np.column_stack([R * np.cos(phis), R * np.sin(phis)])]
    w = math.sqrt(max(R**2 - zs**2, 0.0))
    n_s = max(4, int(math.ceil(2 * w / hmesh)))
    xs = np.linspace(-w, w, n_s + 1)[1:-1]
    pts.append(np.column_stack([xs, np.full_like(xs, zs)]))
    for z in np.arange(zs - hmesh, -R + 0.5 * hmesh, -hmesh * math.sqrt(3) / 2):
        wz = math.sqrt(R**2 - z**2)
        m = int(math.floor(2 * wz / hmesh))
        if m >= 2:
            x = np.linspace(-wz, wz, m + 1)[1:-1]
            keep = np.abs(x) < wz - 0.3 * hmesh
            pts.append(np.column_stack([x[keep], np.full(keep.sum(), z)]))
    p = np.vstack(pts)
    tri = Delaunay(p).simplices
    a, b, c = p[tri[:, 0]], p[tri[:, 1]], p[tri[:, 2]]
    area2 = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    ok = np.abs(area2) > 1e-12 * hmesh**2
    tri, area2 = tri[ok], area2[ok]
    # P1 stiffness
    x, y = p[tri, 0], p[tri, 1]
    bgrad = np.stack([y[:, 1] - y[:, 2], y[:, 2] - y[:, 0], y[:, 0] - y[:, 1]], axis=1) / area2[:, None]
    cgrad = np.stack([x[:, 2] - x[:, 1], x[:, 0] - x[:, 2], x[:, 1] - x[:, 0]], axis=1) / area2[:, None]
    area = np.abs(area2) / 2
    ke = (bgrad[:, :, None] * bgrad[:, None, :] + cgrad[:, :, None] * cgrad[:, None, :]) * area[:, None, None]
    rows = np.repeat(tri, 3, axis=1).ravel()
    cols = np.tile(tri, (1, 3)).ravel()
    K = sp.csr_matrix((ke.ravel(), (rows, cols)), shape=(len(p), len(p)))
    # free-surface nodes, ordered in x, and their 1D P1 mass
    surf = np.where(np.abs(p[:, 1] - zs) < 1e-12)[0]
    surf = surf[np.argsort(p[surf, 0])]
    xs = p[surf, 0]
    dx = np.diff(xs)
    B = np.zeros((len(surf), len(surf)))
    for i, L in enumerate(dx):
        B[i : i + 2, i : i + 2] += L / 6 * np.array([[2.0, 1.0], [1.0, 2.0]])
    inner = np.setdiff1d(np.arange(len(p)), surf)
    Kss = K[surf][:, surf].toarray()
    Ksi = K[surf][:, inner]
    Kii = K[inner][:, inner].tocsc()
    S = Kss - Ksi @ spla.splu(Kii).solve(Ksi.T.toarray())
    kappa = eigh(0.5 * (S + S.T), B, eigvals_only=True)
    return float(kappa[1] * R)  # kappa[0] = 0 (constant potential); kappa[1]: first antisymmetric mode


def horizontal_cylinder(
    radius: float, length: float, fill: float, *, density: float = 1000.0, g: float = GRAVITY, lam: float | None = None
) -> SloshParameters:
    """Equivalent pendulum of a horizontal circular cylinder (axis x, centred on the tank origin,
    flat ends) for transverse (y) sloshing, filled to depth h = fill · 2R.

    Model of notes §3 [derived]: the wall pressure is radial, so the inviscid liquid exerts no
    moment about the axis and its load passes through the axis; hence a pendulum **hinged on the
    axis** with the rigid mass m0 **on the axis**. Its length l1 = R/λ sets ω1² = λ g/R with
    λ from the vehicle model's table (``_core.equivalent_lambda``, the one the vehicle runs and the
    FMU use; :func:`cylinder_lambda` is the independent Steklov solve that checks it) or ``lam``,
    for liquid depths of 1–95 % of the diameter; static-tilt matching (Σ m l = M BM, BM = d for a
    circle) gives m1 = M d λ / R, d the centroid depth of :func:`segment_geometry`. Half full:
    λ = 1.3557, l1 = 0.738 R, m1 = 0.575 M. Longitudinal sloshing is not modelled (rigid along x)."""
    radius = check_positive("radius", radius)
    length = check_positive("length", length)
    density = check_positive("density", density)
    if not 0 < fill < 1:
        raise invalid("fill", fill, "0 < fill < 1 (liquid depth / diameter)")
    seg = segment_geometry(radius, fill * 2 * radius)
    lam = _core.equivalent_lambda(fill) if lam is None else check_positive("lam", lam)
    mass = density * seg["area"] * length
    m1 = min(mass * seg["centroid_depth"] * lam / radius, mass)
    l1 = radius / lam
    return SloshParameters(mass, m1, l1, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), math.sqrt(g / l1))


# --------------------------------------------------------------------------------------------
# Slosh emulator
# --------------------------------------------------------------------------------------------


def _rk4(
    f: Callable[[float, np.ndarray], np.ndarray], t0: float, y0: np.ndarray, t1: float, max_step: float
) -> np.ndarray:
    n = max(1, int(math.ceil((t1 - t0) / max_step - 1e-9)))
    h = (t1 - t0) / n
    y = np.array(y0, dtype=float)
    t = t0
    for _ in range(n):
        k1 = f(t, y)
        k2 = f(t + h / 2, y + h / 2 * k1)
        k3 = f(t + h / 2, y + h / 2 * k2)
        k4 = f(t + h, y + h * k3)
        y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        t += h
    return y


def _check_t_end(t_end: float, time: float) -> float:
    try:
        t = float(t_end)
    except (TypeError, ValueError):
        raise invalid("t_end", t_end, f"a finite time >= current time {time}") from None
    if not math.isfinite(t) or t < time - 1e-12:
        raise invalid("t_end", t_end, f"a finite time >= current time {time}")
    return t


class _OdeState:
    """Time ``_t`` and ODE state ``_y`` of an emulator, with the save/restore part of the
    participant protocol (a saved state is a copy: restoring it replays a window exactly)."""

    _t: float
    _y: np.ndarray

    @property
    def time(self) -> float:
        return self._t

    @property
    def state(self) -> np.ndarray:
        """The ODE state: (θ, θ') of a pendulum, (q, q') of a vehicle."""
        return self._y.copy()

    def save_state(self) -> tuple[float, np.ndarray]:
        return (self._t, self._y.copy())

    def restore_state(self, s: tuple[float, np.ndarray]) -> None:
        self._t, y = s
        self._y = np.array(y, dtype=float)


class PendulumSlosh(_OdeState):
    """Slosh emulator: rigid mass m0 at ``rigid_point`` plus a planar pendulum (point mass m1,
    length l1) hinged at ``hinge`` on the tank, swinging about ``hinge_axis`` n, with linear
    damping ratio ζ at the nominal frequency ω1.

    The pendulum angle θ is a right-handed rotation about n of the rod direction
    e(θ) = cos θ e0 + sin θ (n x e0), e0 = -z (tank axes). In the (non-inertial) tank frame the bob
    at p = hinge + l1 e obeys (Jacman report eq. 7.40 with a rigid rod)

        l1 θ'' = (g - a - α x p - ω x (ω x p)) · t - 2 ζ ω1 l1 θ',   t = ∂e/∂θ = n x e,

    and its load on the tank is F1 = m1 (g - a_bob), M1 = p x F1 with the bob's inertial
    acceleration a_bob = a + α x p + ω x (ω x p) + 2 ω x v_rel + a_rel. The rigid mass adds
    F0 = m0 (g - a - α x p0 - ω x (ω x p0)), M0 = p0 x F0. The load is affine in (a, α): see
    :meth:`load_split`; :meth:`added_mass` is its exact 6x6 acceleration coefficient."""

    def __init__(
        self,
        params: SloshParameters,
        *,
        damping_ratio: float = 0.0,
        theta0: float = 0.0,
        theta_dot0: float = 0.0,
        max_step: float | None = None,
        t0: float = 0.0,
    ):
        self.params = params
        self.m1 = check_positive("sloshing_mass", params.sloshing_mass, allow_zero=True)
        self.m0 = check_positive("rigid_mass", params.rigid_mass, allow_zero=True)
        self.l1 = check_positive("length", params.length)
        self.hinge = check_vector("hinge", params.hinge)
        self.p0 = check_vector("rigid_point", params.rigid_point)
        n = check_vector("hinge_axis", params.hinge_axis)
        if abs(np.linalg.norm(n) - 1) > 1e-9 or abs(n[2]) > 1e-9:
            raise invalid("hinge_axis", params.hinge_axis, "a horizontal unit vector (tank axes)")
        self.n = n
        self.e0 = np.array([0.0, 0.0, -1.0])
        self.b = cross(n, self.e0)
        self.zeta = check_positive("damping_ratio", damping_ratio, allow_zero=True)
        self.w1 = check_positive("frequency", params.frequency)
        self.max_step = check_positive("max_step", max_step) if max_step is not None else 2 * math.pi / self.w1 / 200
        self._y = np.array([float(theta0), float(theta_dot0)])
        check_vector("theta0, theta_dot0", self._y, 2)
        self._t = float(t0)

    # -- kinematics of the model ----------------------------------------------------------
    def rod(self, theta: float) -> tuple[np.ndarray, np.ndarray]:
        """(e, t): rod direction and swing direction at angle θ."""
        e = math.cos(theta) * self.e0 + math.sin(theta) * self.b
        t = math.cos(theta) * self.b - math.sin(theta) * self.e0
        return e, t

    def theta_ddot(self, y: np.ndarray, motion: Mapping[str, np.ndarray]) -> float:
        theta, thd = y
        e, t = self.rod(theta)
        p = self.hinge + self.l1 * e
        w, al = motion["angular_velocity"], motion["angular_acceleration"]
        f = motion["gravity"] - motion["acceleration"] - cross(al, p) - cross(w, cross(w, p))
        return float(f @ t) / self.l1 - 2 * self.zeta * self.w1 * thd

    def load(self, y: np.ndarray, motion: Mapping[str, np.ndarray]) -> np.ndarray:
        """Load of the liquid on the tank, 6-vector (force, moment about the tank origin)."""
        theta, thd = y
        e, t = self.rod(theta)
        p = self.hinge + self.l1 * e
        a, w, al, g = (motion[k] for k in ("acceleration", "angular_velocity", "angular_acceleration", "gravity"))
        thdd = self.theta_ddot(y, motion)
        v_rel = self.l1 * thd * t
        a_rel = self.l1 * thdd * t - self.l1 * thd**2 * e
        a_bob = a + cross(al, p) + cross(w, cross(w, p)) + 2 * cross(w, v_rel) + a_rel
        f1 = self.m1 * (g - a_bob)
        f0 = self.m0 * (g - a - cross(al, self.p0) - cross(w, cross(w, self.p0)))
        return np.concatenate([f0 + f1, cross(self.p0, f0) + cross(p, f1)])

    def added_mass_at(self, theta: float) -> np.ndarray:
        """Exact 6x6 acceleration coefficient of the load at angle θ: the rigid mass follows the
        tank; the bob follows it except along its swing direction t (see :func:`point_added_mass`)."""
        e, t = self.rod(theta)
        p = self.hinge + self.l1 * e
        return point_added_mass(self.m0, self.p0) + point_added_mass(self.m1, p, free=t)

    def load_split(
        self, y: np.ndarray, angular_velocity: np.ndarray, gravity: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """(L0, M_a) with load = L0 - M_a @ [a, α] (exact: the load is affine in the accelerations)."""
        zero = np.zeros(3)
        m = {
            "acceleration": zero,
            "angular_velocity": angular_velocity,
            "angular_acceleration": zero,
            "gravity": gravity,
        }
        return self.load(y, m), self.added_mass_at(y[0])

    # -- participant protocol (time, state, save_state, restore_state: _OdeState) ----------
    def added_mass(self) -> np.ndarray:
        return self.added_mass_at(self._y[0])

    def advance(
        self, t_end: float, input_start: Mapping[str, Any], input_end: Mapping[str, Any]
    ) -> tuple[np.ndarray, np.ndarray]:
        t_end = _check_t_end(t_end, self._t)
        m0 = motion_to_vector(check_motion(input_start, "input_start"))
        m1 = motion_to_vector(check_motion(input_end, "input_end"))
        t0 = self._t
        if t_end > t0:
            span = t_end - t0

            def rhs(t: float, y: np.ndarray) -> np.ndarray:
                s = (t - t0) / span
                return np.array([y[1], self.theta_ddot(y, vector_to_motion((1 - s) * m0 + s * m1))])

            self._y = _rk4(rhs, t0, self._y, t_end, self.max_step)
        self._t = t_end
        L = self.load(self._y, vector_to_motion(m1))
        return L[:3], L[3:]


# --------------------------------------------------------------------------------------------
# Vehicle emulators
# --------------------------------------------------------------------------------------------


class RigidTankVehicle(_OdeState):
    """Base of the vehicle emulators: a rigid tank driven by n generalized coordinates q.

    Subclasses give the mass M(q), the applied forces Q(t, q, q'), the tank kinematics
    [a, α] = J q'' + j0 (tank axes; J also maps q' to the tank velocity and angular velocity, so
    J^T L is the generalized force of the fluid load L), ω and gravity in tank axes. The equations
    of motion with the fluid load L and, for added-mass splitting, the carried mass M_a are

        (M + Jᵀ M_a J) q'' = Q + Jᵀ (L_x - M_a j0),   L_x = L + M_a [a, α]   (exchanged load).
    """

    n_dof: int = 1

    def __init__(self, q0: Sequence[float], qd0: Sequence[float], *, max_step: float = 5e-3, t0: float = 0.0):
        self._y = np.concatenate([check_vector("q0", q0, self.n_dof), check_vector("qd0", qd0, self.n_dof)])
        self._t = float(t0)
        self.max_step = check_positive("max_step", max_step)
        self._ma: np.ndarray | None = None

    # -- to be provided -------------------------------------------------------------------
    def mass(self, q: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def applied(self, t: float, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def kinematics(
        self, t: float, q: np.ndarray, qd: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(J 6xn, j0 6, ω 3, gravity 3), tank axes."""
        raise NotImplementedError

    # -- dynamics -------------------------------------------------------------------------
    def accelerations(self, t: float, y: np.ndarray, load: np.ndarray, added: np.ndarray | None) -> np.ndarray:
        n = self.n_dof
        q, qd = y[:n], y[n:]
        J, j0, _, _ = self.kinematics(t, q, qd)
        M = self.mass(q)
        rhs = self.applied(t, q, qd) + J.T @ load
        if added is not None:
            M = M + J.T @ added @ J
            rhs = rhs - J.T @ added @ j0
        return np.linalg.solve(M, rhs)

    def motion_from(self, t: float, y: np.ndarray, qdd: np.ndarray) -> dict[str, np.ndarray]:
        n = self.n_dof
        J, j0, w, g = self.kinematics(t, y[:n], y[n:])
        acc = J @ qdd + j0
        return {"acceleration": acc[:3], "angular_velocity": w, "angular_acceleration": acc[3:], "gravity": g}

    # -- participant protocol (time, state, save_state, restore_state: _OdeState) ----------
    def set_added_mass(self, added_mass: np.ndarray | None) -> None:
        if added_mass is None:
            self._ma = None
            return
        ma = np.asarray(added_mass, dtype=float)
        if ma.shape != (6, 6) or not np.all(np.isfinite(ma)):
            raise invalid("added_mass", added_mass, "None or a finite 6x6 matrix")
        self._ma = ma

    def advance(self, t_end: float, load_start: Sequence[float], load_end: Sequence[float]) -> dict[str, np.ndarray]:
        t_end = _check_t_end(t_end, self._t)
        l0 = check_load(load_start, "load_start")
        l1 = check_load(load_end, "load_end")
        t0, n = self._t, self.n_dof
        if t_end > t0:
            span = t_end - t0

            def rhs(t: float, y: np.ndarray) -> np.ndarray:
                s = (t - t0) / span
                return np.concatenate([y[n:], self.accelerations(t, y, (1 - s) * l0 + s * l1, self._ma)])

            self._y = _rk4(rhs, t0, self._y, t_end, self.max_step)
        self._t = t_end
        return self.motion_from(t_end, self._y, self.accelerations(t_end, self._y, l1, self._ma))


_AXES = {"x": 0, "y": 1, "z": 2}


class TankOnSprings(RigidTankVehicle):
    """Tank (mass ``mass``, no rotation) on linear springs and dampers along 1–3 global axes
    (``axes``, e.g. "y" or "xyz"); tank axes = global axes. q = displacement along those axes from
    the unloaded spring position. Optional ``external_force(t) -> 3-vector`` (global axes).

        m q'' = -k q - c q' + m g_axes + f_ext(t)_axes + (fluid load)_axes"""

    def __init__(
        self,
        mass: float,
        stiffness: Sequence[float] | float,
        damping: Sequence[float] | float = 0.0,
        *,
        axes: str = "y",
        gravity: Sequence[float] = (0.0, 0.0, -GRAVITY),
        external_force: Callable[[float], Sequence[float]] | None = None,
        q0: Sequence[float] | None = None,
        qd0: Sequence[float] | None = None,
        max_step: float = 5e-3,
    ):
        if not axes or any(a not in _AXES for a in axes) or len(set(axes)) != len(axes):
            raise invalid("axes", axes, 'distinct letters of "xyz", e.g. "y" or "xyz"')
        self.n_dof = len(axes)
        self.idx = [_AXES[a] for a in axes]
        self.m = check_positive("mass", mass)
        k = np.broadcast_to(np.asarray(stiffness, float), (self.n_dof,)).copy()
        c = np.broadcast_to(np.asarray(damping, float), (self.n_dof,)).copy()
        for i, (ki, ci) in enumerate(zip(k, c, strict=True)):
            check_positive(f"stiffness[{i}]", ki)
            check_positive(f"damping[{i}]", ci, allow_zero=True)
        self.k, self.c = k, c
        self.g = check_vector("gravity", gravity)
        self.external_force = external_force
        self._J = np.zeros((6, self.n_dof))
        self._J[self.idx, np.arange(self.n_dof)] = 1.0
        zeros = np.zeros(self.n_dof)
        super().__init__(zeros if q0 is None else q0, zeros if qd0 is None else qd0, max_step=max_step)

    def mass(self, q: np.ndarray) -> np.ndarray:
        return self.m * np.eye(self.n_dof)

    def applied(self, t: float, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        f = -self.k * q - self.c * qd + self.m * self.g[self.idx]
        if self.external_force is not None:
            f = f + np.asarray(self.external_force(t), float)[self.idx]
        return f

    def kinematics(self, t, q, qd):
        return self._J, np.zeros(6), np.zeros(3), self.g


def smooth_spinup(t: float, rate: float, angle: float) -> tuple[float, float, float]:
    """(φ, φ', φ'') of an arm that spins up from rest to the constant rate ω_f while turning
    ``angle`` (seed 003 §4.2: "accelerates to a constant angular velocity within the first 45° of
    rotation"), with φ' = ω_f S(t/T), S = 10s³ - 15s⁴ + 6s⁵ (C² start and end), T = 2·angle/ω_f.
    ``angle`` = 0: constant rate from t = 0."""
    T = 2 * angle / rate
    if t >= T:
        return angle + rate * (t - T), rate, 0.0
    if t <= 0:
        return 0.0, 0.0, 0.0
    s = t / T
    S = 10 * s**3 - 15 * s**4 + 6 * s**5
    dS = 30 * s**2 - 60 * s**3 + 30 * s**4
    intS = 2.5 * s**4 - 3 * s**5 + s**6
    return rate * T * intS, rate * S, rate * dS / T


class CentrifugeArm(RigidTankVehicle):
    """Centrifuge of seed 003 §4.2: a tank on an arm that turns about the vertical axis with the
    prescribed angle φ(t) (:func:`smooth_spinup`), free to slide radially on an undamped spring.

    q = s, the radial slider displacement; the tank origin is at radius ρ = R0 + s. Tank axes:
    x = e_φ (tangential, forward), y = -e_r (towards the spin axis, "left" as in a left-hand
    curve), z = up. Kinematics: a = (ρ φ'' + 2 ρ' φ', ρ φ'² - ρ'', 0), ω = (0, 0, φ'),
    α = (0, 0, φ''), gravity (0, 0, -g). Radial equation (the arm takes the tangential load):

        m_t ρ'' = m_t ρ φ'² - k s - F_y."""

    n_dof = 1

    def __init__(
        self,
        tank_mass: float,
        arm_radius: float,
        stiffness: float,
        spin_rate: float,
        *,
        spinup_angle: float = math.pi / 4,
        g: float = GRAVITY,
        s0: float = 0.0,
        sd0: float = 0.0,
        max_step: float = 5e-3,
    ):
        self.m = check_positive("tank_mass", tank_mass)
        self.R0 = check_positive("arm_radius", arm_radius)
        self.k = check_positive("stiffness", stiffness)
        self.rate = check_positive("spin_rate", spin_rate)
        self.spinup_angle = check_positive("spinup_angle", spinup_angle, allow_zero=True)
        self.g = check_positive("g", g)
        self._J = np.zeros((6, 1))
        self._J[1, 0] = -1.0
        super().__init__([s0], [sd0], max_step=max_step)

    def arm(self, t: float) -> tuple[float, float, float]:
        return smooth_spinup(t, self.rate, self.spinup_angle)

    def mass(self, q):
        return np.array([[self.m]])

    def applied(self, t, q, qd):
        _, w, _ = self.arm(t)
        return np.array([self.m * (self.R0 + q[0]) * w**2 - self.k * q[0]])

    def kinematics(self, t, q, qd):
        _, w, wd = self.arm(t)
        rho = self.R0 + q[0]
        j0 = np.array([rho * wd + 2 * qd[0] * w, rho * w**2, 0.0, 0.0, 0.0, wd])
        return self._J, j0, np.array([0.0, 0.0, w]), np.array([0.0, 0.0, -self.g])

    def radius(self) -> float:
        return self.R0 + self._y[0]
