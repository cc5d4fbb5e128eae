"""The indicators a rail-vehicle engineer reads off a run (issue 20 §2), in SI units, each naming
its standard: ride (Sperling's ride index Wz, ISO 2631-1 frequency-weighted RMS acceleration),
derailment (Nadal's flange-climb limit, per-wheel L/V against it, Weinstock's axle sum, wheel
unloading ΔQ/Q₀, AAR's 50 ms duration rule), roll-over (load transfer ratio LTR per bogie and per
car) and load spectra (ASTM E1049-85 rainflow cycles, damage-equivalent load, level crossings).

The functions take plain arrays; :func:`add_indicators` computes every indicator a results Dataset
(:func:`railslosh.results.to_dataset`) supports, after the settling phase
(:func:`railslosh.results.settling`), and stores them as variables with ``units``, ``long_name`` and
``standard`` attributes::

    >>> from railslosh import indicators, results
    >>> ds = indicators.add_indicators(results.load("out/results.nc"), wohler_exponent=3.0)
    >>> float(ds["weinstock_max"].max()), ds["weinstock_max"].attrs["standard"]
    >>> indicators.nadal_limit(70.0, 0.5)          # 0.947: S1002 flange, dry rail
    >>> indicators.damage_equivalent_load(x, wohler_exponent=5.0, n_eq=1e7)

Bad input raises :class:`ValueError` in the form of :func:`railslosh.limits.invalid`.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from railslosh import _core
from railslosh.limits import invalid

__all__ = [
    "ACCELERATION_VARIABLE",
    "FLANGE_ANGLE",
    "ISO2631_WEIGHTINGS",
    "L_OVER_V_LIMIT",
    "L_OVER_V_STANDARD",
    "LOAD_CUTOFF",
    "MIN_DURATION",
    "NADAL_FRICTION",
    "SPERLING_BAND",
    "UNLOADING_LIMIT",
    "UNLOADING_STANDARD",
    "WEINSTOCK_LIMIT",
    "add_indicators",
    "damage_equivalent_load",
    "exceedances",
    "flange_angle",
    "iso2631_weighted_rms",
    "iso2631_weighting",
    "level_crossings",
    "load_spectrum",
    "load_transfer_ratio",
    "low_pass",
    "nadal_limit",
    "rainflow_cycles",
    "sperling_weighting",
    "sperling_wz",
    "time_over_limit",
    "weinstock_sum",
    "wheel_profile",
    "wheel_unloading",
]

# --- limits of the standards ---------------------------------------------------------------------

L_OVER_V_LIMIT = 0.8
"""Derailment quotient limit (Y/Q)lim = 0.8: UIC 518 (4th ed., 2009) and EN 14363:2016, where it
applies to the 2 m sliding mean of Y/Q; the plots show the unfiltered quotient against it."""
L_OVER_V_STANDARD = "UIC 518, EN 14363"

UNLOADING_LIMIT = 0.6
"""Wheel unloading limit ΔQ/Q₀ = 0.6: UIC 530-2 and EN 14363:2016 (safety against derailment on
twisted track, quasi-static wheel unloading)."""
UNLOADING_STANDARD = "UIC 530-2, EN 14363"

FLANGE_ANGLE = {"s1002": 70.0, "aar1b": 75.0}
"""Flange angles of the wheel profiles (deg): S1002 (EN 13715) 70°, the AAR-1B-style profile 75°
(``rail_mbs::profile::analytic``), for Nadal's single-wheel flange-climb limit."""

NADAL_FRICTION = 0.5
"""Flange friction coefficient μ of Nadal's limit: 0.5, dry rail (the conservative value of the
AAR and FRA practice; 0.25–0.3 is lubricated)."""

WEINSTOCK_LIMIT = 1.5
"""Axle-sum L/V limit (Weinstock's criterion): 1.5, AAR Manual of Standards and Recommended
Practices, Section C, Part II (M-1001), Chapter XI, "sum of L/V ratios on any axle". Weinstock
(1984) derived it as Nadal's limit of the flanging wheel plus μ of the other wheel (for μ = 0.5
and 75°: 1.13 + 0.5 ≈ 1.6)."""

MIN_DURATION = 0.05
"""s: AAR Chapter XI's duration rule: a wheel L/V, axle-sum L/V or wheel-load criterion counts as
exceeded only when the quantity stays beyond its limit for 50 ms or longer (:func:`exceedances`)."""

LOAD_CUTOFF = 20.0
"""Hz: cut-off of the low-pass through which force peaks are read (:func:`low_pass`): EN 14363:2016
(UIC 518) filters the vertical wheel–rail force Q at 20 Hz before taking its peak (its 99.85 %
percentile). In railslosh it also keeps the penalty liquid's heave and compression modes out of
a fluid-load peak: they ring at 20–60 Hz on a step of the tank's acceleration, and their overshoot
does not depend on the penalty stiffnesses (docs/validation.md, "Peak loads through EN 14363's
20 Hz low-pass")."""

SPERLING_BAND = (0.5, 40.0)
"""Hz: the frequencies summed in Sperling's ride index (:func:`sperling_wz`); Sperling's
correction factor F(f) starts at 0.5 Hz."""

ISO2631_WEIGHTINGS: dict[str, dict[str, float]] = {
    "k": {"f3": 12.5, "f4": 12.5, "q4": 0.63, "f5": 2.37, "q5": 0.91, "f6": 3.35, "q6": 0.91},
    "d": {"f3": 2.0, "f4": 2.0, "q4": 0.63},
}
"""Parameters of the ISO 2631-1:1997 frequency weightings (Annex A, Table A.2; Hz and quality
factors): W_k (vertical z, seated) and W_d (horizontal x, y); both also band-limited by a
2nd-order Butterworth high-pass at f1 = 0.4 Hz and low-pass at f2 = 100 Hz."""
_ISO_BAND = (0.4, 100.0)
_ISO_AXES = {"x": "d", "y": "d", "z": "k"}

# Sperling's frequency correction factor F(f), piecewise: (upper frequency, a, power) -> F = a f^power
_SPERLING_F: dict[str, tuple[tuple[float, float, float], ...]] = {
    "vertical": ((5.9, 0.325, 2.0), (20.0, 400.0, -2.0), (math.inf, 1.0, 0.0)),
    "lateral": ((5.4, 0.8, 2.0), (26.0, 650.0, -2.0), (math.inf, 1.0, 0.0)),
}
_SPERLING_STANDARD = (
    "Sperling (1941) ride index Wz = 0.896 (a^3 F(f) / f)^(1/10), a in cm/s^2: Garg & Dukkipati, "
    "Dynamics of Railway Vehicle Systems (1984); GB 5599-85 (W = 7.08 (A^3 F(f)/f)^(1/10), A in g)"
)
_ISO_STANDARD = "ISO 2631-1:1997, frequency weightings W_k (z) and W_d (x, y), Annex A"
_AAR_DURATION = "AAR MSRP Section C Part II (M-1001) Chapter XI: exceedances of 50 ms or longer"
_RAINFLOW_STANDARD = "ASTM E1049-85 (2017) §5.4.4 rainflow counting (Python package rainflow)"


# --- input checks --------------------------------------------------------------------------------


def _positive(field: str, value: Any, noun: str, *, zero: bool = False) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        x = math.nan
    if isinstance(value, bool) or not math.isfinite(x) or x < 0 or (x == 0 and not zero):
        raise invalid(field, value, f"{noun} {'≥' if zero else '>'} 0")
    return x


def _series(field: str, values: Any, n: int | None = None) -> np.ndarray:
    try:
        x = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise invalid(field, values, "a 1-D array of numbers") from None
    if x.ndim != 1:
        raise invalid(field, f"array of shape {x.shape}", "a 1-D array of numbers")
    if n is not None and x.size != n:
        raise invalid(field, f"array of {x.size} samples", f"{n} samples, one per time")
    return x


def _uniform(t: Any, acc: Any) -> tuple[float, np.ndarray]:
    """``(dt, samples)`` of an acceleration history on a uniform time grid: the samples as given
    when the times are uniformly spaced (to 1e-6 of the step), else linearly interpolated onto the
    grid of the median step."""
    tt = _series("t", t)
    a = _series("acc", acc, tt.size)
    if tt.size < 8:
        raise invalid("t", f"array of {tt.size} samples", "at least 8 samples")
    if not np.isfinite(tt).all() or not (np.diff(tt) > 0).all():
        raise invalid("t", "array", "finite, strictly increasing times (s)")
    if not np.isfinite(a).all():
        raise invalid("acc", "array with NaN or inf", "finite accelerations (m/s²)")
    dt = np.diff(tt)
    step = float(np.median(dt))
    if np.abs(dt - step).max() <= 1e-6 * step:
        return float(dt.mean()), a
    n = int(round((tt[-1] - tt[0]) / step)) + 1
    grid = np.linspace(tt[0], tt[-1], n)
    return float(grid[1] - grid[0]), np.interp(grid, tt, a)


def low_pass(t: Any, x: Any, cutoff: float = LOAD_CUTOFF, order: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """``(grid, y)``: the record ``x`` (one value per time, or one row of components per time)
    taken at times ``t`` (s, strictly increasing, not necessarily uniform), linearly interpolated
    onto a uniform grid of ``1/(50 cutoff)`` s and passed forward and backward through a Butterworth
    low-pass of ``order`` at ``cutoff`` Hz (``scipy.signal.sosfiltfilt``: zero phase, so a peak
    stays where it happened; the pair's gain is the square of the filter's, 0.5 at ``cutoff``).
    The default is EN 14363's 20 Hz for wheel–rail forces (:data:`LOAD_CUTOFF`); the peak of a
    load is ``np.abs(y).max()``, or the largest norm of its filtered components."""
    from scipy import signal

    fc = _positive("cutoff", cutoff, "frequency (Hz)")
    if isinstance(order, bool) or not isinstance(order, int | np.integer) or not 1 <= order <= 8:
        raise invalid("order", order, "an integer from 1 to 8")
    tt = _series("t", t)
    xx = np.asarray(x, dtype=float)
    if xx.ndim not in (1, 2) or xx.shape[0] != tt.size:
        raise invalid("x", f"array of shape {xx.shape}", f"{tt.size} values or rows, one per time")
    if tt.size < 2 or not np.isfinite(tt).all() or not (np.diff(tt) > 0).all():
        raise invalid("t", "array", "at least 2 finite, strictly increasing times (s)")
    if not np.isfinite(xx).all():
        raise invalid("x", "array with NaN or inf", "finite values")
    n = int(math.ceil((tt[-1] - tt[0]) * 50.0 * fc)) + 1
    grid = np.linspace(tt[0], tt[-1], max(n, 2))
    cols = xx.reshape(tt.size, -1)
    y = np.column_stack([np.interp(grid, tt, c) for c in cols.T])
    sos = signal.butter(int(order), fc, fs=1.0 / (grid[1] - grid[0]), output="sos")
    pad = min(3 * (2 * sos.shape[0] + 1), grid.size - 1)
    if grid.size > 3:
        y = signal.sosfiltfilt(sos, y, axis=0, padlen=pad)
    return grid, (y[:, 0] if xx.ndim == 1 else y)


# --- ride ----------------------------------------------------------------------------------------


def sperling_weighting(f: Any, direction: str = "vertical") -> np.ndarray:
    """Sperling's frequency correction factor F(f) (dimensionless) of a vertical or lateral
    car-body vibration at frequency ``f`` (Hz), as tabulated by Garg & Dukkipati (1984) and
    GB 5599-85: vertical F = 0.325 f² (0.5–5.9 Hz), 400/f² (5.9–20 Hz), 1 (above 20 Hz); lateral
    F = 0.8 f² (0.5–5.4 Hz), 650/f² (5.4–26 Hz), 1 (above 26 Hz). 0 below 0.5 Hz, where the
    index is not defined."""
    if direction not in _SPERLING_F:
        raise invalid("direction", direction, "'vertical' or 'lateral'")
    f = np.asarray(f, dtype=float)
    out = np.zeros_like(f)
    lo = SPERLING_BAND[0]
    for hi, a, p in _SPERLING_F[direction]:
        m = (f >= lo) & (f < hi)
        out[m] = a * f[m] ** p
        lo = hi
    return out


def sperling_wz(t: Any, acc: Any, direction: str = "vertical", *, band: Sequence[float] = SPERLING_BAND) -> float:
    """Sperling's ride index Wz (dimensionless) of a car-body acceleration history ``acc`` (m/s²)
    sampled at times ``t`` (s), vertical or lateral.

    Sperling (1941) rates a harmonic vibration of acceleration amplitude a (cm/s²) at frequency
    f (Hz) by Wz = 0.896 (a³ F(f)/f)^(1/10), F(f) the frequency correction factor
    (:func:`sperling_weighting`); a spectrum of components sums as Wz = (Σ_i Wz_i¹⁰)^(1/10)
    (Garg & Dukkipati, *Dynamics of Railway Vehicle Systems*, 1984, ch. 12; GB 5599-85 writes the
    same index as W = 7.08 (A³ F(f)/f)^(1/10) with A in g). Here the components are the one-sided
    amplitude spectrum a_i = 2|X_i|/N of the record (the mean removed, rectangular window, one
    FFT over the whole record) at the frequencies f_i within ``band`` (default 0.5–40 Hz). The
    value of this amplitude-spectrum (cubic) form depends on the record length for broadband
    signals; the root-mean-square variant with a continuous weighting B_S(f),
    Wz = (∫ B_S² G_a df)^(1/6.67), gives other values and is not this function. For a sine of
    amplitude a (an integer number of periods in the record) the index is exactly the formula.

    Scale (ride quality of the vehicle): 1 very good, 2 good, 3 satisfactory, 4 acceptable for
    running, 4.5 not acceptable for running, 5 dangerous."""
    if direction not in _SPERLING_F:
        raise invalid("direction", direction, "'vertical' or 'lateral'")
    dt, a = _uniform(t, acc)
    lo, hi = (float(v) for v in band)
    if not (0 < lo < hi):
        raise invalid("band", tuple(band), "(f_low, f_high) in Hz with 0 < f_low < f_high")
    n = a.size
    spec = np.abs(np.fft.rfft(a - a.mean())) / n
    spec[1:] *= 2.0
    if n % 2 == 0:
        spec[-1] /= 2.0  # the Nyquist bin is not folded
    f = np.fft.rfftfreq(n, dt)
    m = (f >= lo) & (f <= hi)
    amp_cm = 100.0 * spec[m]
    terms = 0.896**10 * amp_cm**3 * sperling_weighting(f[m], direction) / f[m]
    return float(terms.sum() ** 0.1)


def iso2631_weighting(f: Any, axis: str = "z") -> np.ndarray:
    """The complex frequency weighting W(f) of ISO 2631-1:1997 (Annex A) at frequencies ``f``
    (Hz) for a seated person's translational axis: W_k for ``"z"`` (vertical), W_d for ``"x"`` and
    ``"y"`` (horizontal). It is the product of

    * band limiting: 2nd-order Butterworth high-pass at f1 = 0.4 Hz and low-pass at f2 = 100 Hz,
      H_h = s²/(s² + ω1 s/Q1 + ω1²), H_l = ω2²/(s² + ω2 s/Q2 + ω2²), Q1 = Q2 = 1/√2;
    * acceleration–velocity transition H_t = (1 + s/ω3)/(1 + s/(Q4 ω4) + s²/ω4²);
    * upward step (W_k only) H_s = (1 + s/(Q5 ω5) + s²/ω5²)/(1 + s/(Q6 ω6) + s²/ω6²) · (f5/f6)²,

    s = j2πf, ω_i = 2π f_i, with the parameters of :data:`ISO2631_WEIGHTINGS`. Its magnitude
    reproduces the standard's Table 3 (W_k: 0.482 at 1 Hz, 0.967 at 4 Hz, 1.036 at 8 Hz; W_d:
    1.011 at 1 Hz, 0.890 at 2 Hz)."""
    if axis not in _ISO_AXES:
        raise invalid("axis", axis, "'x', 'y' or 'z'")
    p = ISO2631_WEIGHTINGS[_ISO_AXES[axis]]
    s = 2j * np.pi * np.asarray(f, dtype=float)
    w1, w2 = (2 * np.pi * v for v in _ISO_BAND)
    q = 1 / math.sqrt(2)
    h = s**2 / (s**2 + s * w1 / q + w1**2) * w2**2 / (s**2 + s * w2 / q + w2**2)
    w3, w4 = 2 * np.pi * p["f3"], 2 * np.pi * p["f4"]
    h = h * (1 + s / w3) / (1 + s / (p["q4"] * w4) + (s / w4) ** 2)
    if "f5" in p:
        w5, w6 = 2 * np.pi * p["f5"], 2 * np.pi * p["f6"]
        step = (1 + s / (p["q5"] * w5) + (s / w5) ** 2) / (1 + s / (p["q6"] * w6) + (s / w6) ** 2)
        h = h * step * (p["f5"] / p["f6"]) ** 2
    return h


def iso2631_weighted_rms(t: Any, acc: Any, axis: str = "z") -> float:
    """The frequency-weighted RMS acceleration a_w (m/s²) of ISO 2631-1:1997 §6.4.2 of an
    acceleration history ``acc`` (m/s²) sampled at times ``t`` (s), along ``axis`` ``"z"``
    (vertical, weighting W_k) or ``"x"``/``"y"`` (horizontal, W_d): a_w = (1/T ∫ a_w(t)² dt)^(1/2)
    with a_w(t) the acceleration weighted by :func:`iso2631_weighting`. The weighting is applied
    in the frequency domain (one FFT of the record, exact at the discrete frequencies, the record
    taken as periodic); frequencies above the record's Nyquist frequency are not seen.

    Comfort reactions in public transport (ISO 2631-1 Annex C.2.3): below 0.315 m/s² not
    uncomfortable, 0.315–0.63 a little uncomfortable, 0.5–1 fairly uncomfortable, 0.8–1.6
    uncomfortable, 1.25–2.5 very uncomfortable, above 2 extremely uncomfortable."""
    if axis not in _ISO_AXES:
        raise invalid("axis", axis, "'x', 'y' or 'z'")
    dt, a = _uniform(t, acc)
    n = a.size
    x = np.fft.rfft(a)
    power = np.abs(x * iso2631_weighting(np.fft.rfftfreq(n, dt), axis)) ** 2
    fold = np.full(power.shape, 2.0)
    fold[0] = 1.0
    if n % 2 == 0:
        fold[-1] = 1.0
    return float(math.sqrt((fold * power).sum()) / n)  # Parseval: mean square = Σ |X_k|² (one-sided) / N²


# --- derailment ----------------------------------------------------------------------------------


def nadal_limit(flange_angle: float = 70.0, friction: float = NADAL_FRICTION) -> float:
    """Nadal's flange-climb limit Y/Q = (tan δ − μ)/(1 + μ tan δ) (M. J. Nadal, *Locomotives à
    vapeur*, 1908: the single-wheel L/V at which a flanging wheel starts to climb the rail) for
    flange angle δ (deg) and flange friction μ (0.5: dry rail, conservative); 0.947 for 70° and
    μ = 0.5, 1.128 for 75°."""
    d = _positive("flange_angle", flange_angle, "an angle in degrees")
    if d >= 90.0:
        raise invalid("flange_angle", flange_angle, "an angle in degrees > 0 and < 90")
    mu = _positive("friction", friction, "a friction coefficient", zero=True)
    return _core.nadal_limit(math.radians(d), mu)


def wheel_profile(ds: Any) -> str:
    """The wheel profile of a results Dataset's scene (``scene_json`` attribute, ``car.wheel_profile``);
    ``"s1002"`` (the default profile) when the Dataset does not say."""
    try:
        return str(json.loads(ds.attrs.get("scene_json", "{}")).get("car", {}).get("wheel_profile", "s1002"))
    except (ValueError, AttributeError):
        return "s1002"


def flange_angle(ds: Any) -> float:
    """Flange angle (deg) of the wheel profile of a results Dataset (:data:`FLANGE_ANGLE`, 70° when unknown)."""
    return FLANGE_ANGLE.get(wheel_profile(ds), 70.0)


def weinstock_sum(l_over_v: Any) -> np.ndarray:
    """Weinstock's axle sum Σ|Y/Q| = |Y_left|/Q_left + |Y_right|/Q_right (dimensionless) of
    per-wheel L/V ratios, array ``(..., 2)`` with the two wheels of an axle on the last axis.
    Weinstock (1984) limits it to Nadal's limit of the flanging wheel plus the friction
    coefficient of the other; AAR Chapter XI to :data:`WEINSTOCK_LIMIT` = 1.5."""
    lv = np.asarray(l_over_v, dtype=float)
    if lv.ndim == 0 or lv.shape[-1] != 2:
        raise invalid("l_over_v", f"array of shape {lv.shape}", "an array (..., 2): left and right wheel of each axle")
    return np.abs(lv).sum(axis=-1)


def wheel_unloading(q: Any, q0: Any) -> np.ndarray:
    """Wheel unloading ΔQ/Q₀ = (Q₀ − Q)/Q₀ (dimensionless) of wheel loads ``q`` (N) against the
    static wheel loads ``q0`` (N, > 0, broadcast against ``q``); 1 is a wheel off the rail.
    Limit :data:`UNLOADING_LIMIT` = 0.6 (UIC 530-2, EN 14363)."""
    q0 = np.asarray(q0, dtype=float)
    if not (np.isfinite(q0).all() and (q0 > 0).all()):
        raise invalid("q0", q0.tolist() if q0.size <= 8 else "array", "static wheel loads > 0 N")
    return (q0 - np.asarray(q, dtype=float)) / q0


def exceedances(t: Any, x: Any, limit: float, min_duration: float = MIN_DURATION) -> np.ndarray:
    """The intervals ``[[start, end], ...]`` (s) in which ``x`` stays above ``limit`` for at
    least ``min_duration`` (default 50 ms: AAR Chapter XI's duration rule; exceedances shorter
    than that are ignored). The crossing times are interpolated linearly between samples; an
    exceedance at the start or end of the record starts or ends there. NaN samples count as not
    above the limit (a spell next to one starts or ends at its own sample, as next to an infinite
    one)."""
    tt = _series("t", t)
    xx = _series("x", x, tt.size)
    if not np.isfinite(tt).all() or (np.diff(tt) <= 0).any():
        raise invalid("t", "array", "finite, strictly increasing times (s)")
    lim = float(limit)
    dur = _positive("min_duration", min_duration, "a duration in s", zero=True)
    over = np.nan_to_num(xx, nan=-np.inf) > lim
    edges = np.diff(np.concatenate(([0], over.astype(np.int8), [0])))
    starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1
    out = []
    for i, j in zip(starts, ends, strict=True):
        t0, t1 = tt[i], tt[j]  # where a neighbour is not finite, the spell starts or ends at its own sample
        if i == 0:
            t0 = tt[0]
        elif np.isfinite(xx[i - 1]) and np.isfinite(xx[i]):
            t0 = tt[i - 1] + (lim - xx[i - 1]) / (xx[i] - xx[i - 1]) * (tt[i] - tt[i - 1])
        if j == tt.size - 1:
            t1 = tt[-1]
        elif np.isfinite(xx[j + 1]) and np.isfinite(xx[j]):
            t1 = tt[j] + (xx[j] - lim) / (xx[j] - xx[j + 1]) * (tt[j + 1] - tt[j])
        if t1 - t0 >= dur * (1 - 1e-9):
            out.append((float(t0), float(t1)))
    return np.array(out, dtype=float).reshape(-1, 2)


def time_over_limit(t: Any, x: Any, limit: float, min_duration: float = MIN_DURATION) -> float:
    """Total time (s) of the :func:`exceedances` of ``x`` above ``limit`` lasting ``min_duration`` or longer."""
    ex = exceedances(t, x, limit, min_duration)
    return float((ex[:, 1] - ex[:, 0]).sum())


# --- roll-over -----------------------------------------------------------------------------------


def load_transfer_ratio(wheel_vertical: Any) -> np.ndarray:
    """Load transfer ratio LTR = (ΣQ_right − ΣQ_left)/(ΣQ_right + ΣQ_left) (dimensionless) of a
    group of wheels (a bogie, a car): ``wheel_vertical`` (N) is an array ``(..., wheelsets, 2)``
    with sides [left, right] (looking forward) on the last axis; the result drops the last two
    axes. Positive: load moved to the right side; ±1: one side lifted off (roll-over threshold;
    the roll-over indicator of vehicle dynamics, no railway standard sets a limit short of 1)."""
    q = np.asarray(wheel_vertical, dtype=float)
    if q.ndim < 2 or q.shape[-1] != 2:
        raise invalid("wheel_vertical", f"array of shape {q.shape}", "an array (..., wheelsets, 2): left, right")
    left, right = q[..., 0].sum(axis=-1), q[..., 1].sum(axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return (right - left) / (right + left)


# --- load spectra --------------------------------------------------------------------------------


def rainflow_cycles(x: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(ranges, means, counts)`` of the rainflow cycles of a load history ``x`` (ASTM
    E1049-85, §5.4.4, counted by the ``rainflow`` package): every cycle's range (peak to valley,
    in the units of ``x``), mean, and count (1 for a full cycle, 0.5 for a half cycle of the
    residue). Non-finite samples are left out."""
    import rainflow

    xx = _series("x", x)
    xx = xx[np.isfinite(xx)]
    cycles = list(rainflow.extract_cycles(xx)) if xx.size >= 2 else []
    if not cycles:
        return np.zeros(0), np.zeros(0), np.zeros(0)
    c = np.asarray([cy[:3] for cy in cycles], dtype=float)
    return c[:, 0], c[:, 1], c[:, 2]


def _binned(ranges: np.ndarray, counts: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Cycle counts summed into range bins (the last bin closed)."""
    return np.histogram(ranges, bins=edges, weights=counts)[0]


def _equivalent_amplitude(ranges: np.ndarray, counts: np.ndarray, m: float, n_eq: float) -> float:
    """(Σ n_i (range_i/2)^m / N_eq)^(1/m): the damage-equivalent amplitude of rainflow cycles."""
    return float(((counts * (ranges / 2.0) ** m).sum() / n_eq) ** (1.0 / m))


def load_spectrum(x: Any, bins: int | Sequence[float] = 20) -> tuple[np.ndarray, np.ndarray]:
    """``(edges, counts)``: the rainflow cycle counts (:func:`rainflow_cycles`, half cycles 0.5)
    of ``x`` binned by range; ``bins`` is a number of equal bins from 0 to the largest range, or
    the bin edges (as :func:`numpy.histogram`)."""
    ranges, _, counts = rainflow_cycles(x)
    if np.ndim(bins) == 0:
        nb = int(bins) if isinstance(bins, int | np.integer) and not isinstance(bins, bool) else 0
        if nb < 1:
            raise invalid("bins", bins, "a whole number ≥ 1 or increasing bin edges")
        top = float(ranges.max()) if ranges.size and ranges.max() > 0 else 1.0
        edges = np.linspace(0.0, top, nb + 1)
    else:
        edges = np.asarray(bins, dtype=float)
        if edges.ndim != 1 or edges.size < 2 or (np.diff(edges) <= 0).any():
            raise invalid("bins", bins, "a whole number ≥ 1 or increasing bin edges")
    return edges, _binned(ranges, counts, edges)


def damage_equivalent_load(x: Any, wohler_exponent: float, n_eq: float) -> float:
    """Damage-equivalent load amplitude of a load history ``x`` for a Wöhler (S–N) curve
    N S_a^m = const of exponent m = ``wohler_exponent``: the constant amplitude that does the
    same Palmgren–Miner damage in ``n_eq`` cycles as the rainflow cycles of ``x``
    (:func:`rainflow_cycles`): DEL = (Σ_i n_i S_a,i^m / N_eq)^(1/m), S_a,i = range_i/2 the cycle
    amplitude and n_i its count (0.5 for half cycles). Convention: an amplitude (the equivalent
    range is 2 DEL), no mean-stress correction, in the units of ``x``. A sine of amplitude A
    over N whole cycles (starting at a peak) has DEL = A for n_eq = N."""
    m = _positive("wohler_exponent", wohler_exponent, "a Wöhler exponent")
    neq = _positive("n_eq", n_eq, "an equivalent cycle count")
    ranges, _, counts = rainflow_cycles(x)
    return _equivalent_amplitude(ranges, counts, m, neq)


def level_crossings(x: Any, levels: Any, reference: float | None = None) -> np.ndarray:
    """Level-crossing counts of a load history ``x`` (ASTM E1049-85 §5.1.1): for each level at
    or above the ``reference`` load (default: the mean of ``x``) the number of times ``x`` rises
    above it (a positive-slope crossing, x_i ≤ level < x_i+1), for each level below it the number
    of times ``x`` falls below it (x_i ≥ level > x_i+1). Non-finite samples are left out."""
    xx = _series("x", x)
    xx = xx[np.isfinite(xx)]
    lv = np.atleast_1d(np.asarray(levels, dtype=float))
    if lv.ndim != 1:
        raise invalid("levels", levels, "a 1-D array of load levels")
    ref = float(np.mean(xx)) if reference is None and xx.size else float(reference or 0.0)
    a, b = xx[:-1, None], xx[1:, None]
    up = ((a <= lv) & (b > lv)).sum(axis=0)
    down = ((a >= lv) & (b < lv)).sum(axis=0)
    return np.where(lv >= ref, up, down).astype(float)


# --- the indicators of a results Dataset ---------------------------------------------------------

ACCELERATION_VARIABLE = "car_acceleration"
"""Name of a car-body acceleration variable ``(time, car, component)`` in m/s² (tank/car frame:
x forward, y left, z up) that :func:`add_indicators` rates for ride; every vehicle run records it
(``rail_mbs::vehicle::TrainRecord::car_acceleration``, filtered like the loads)."""

_SPECTRA = ("coupler_force", "wheel_vertical", "fluid_force_tank", "force_tank")


def _attrs(units: str, long_name: str, standard: str, **extra: Any) -> dict[str, Any]:
    out: dict[str, Any] = {"units": units, "long_name": long_name, "standard": standard}
    out.update({k: (float(v) if isinstance(v, bool | np.bool_) else v) for k, v in extra.items()})
    return out


def _per_channel(da: Any, fn: Any) -> np.ndarray:
    """``fn(series)`` of every channel of a DataArray with dims (time, ...) → array of the channel shape (+ fn's)."""
    v = np.asarray(da.transpose("time", ...).values, dtype=float)
    flat = v.reshape(v.shape[0], -1)
    out = np.array([fn(flat[:, k]) for k in range(flat.shape[1])])
    return out.reshape(v.shape[1:] + out.shape[1:])


def _time_over(t: np.ndarray, da: Any, limit: float, min_duration: float) -> np.ndarray:
    return _per_channel(da, lambda x: time_over_limit(t, x, limit, min_duration))


def _add_peak_and_time_over(
    out: Any,
    name: str,
    da: Any,
    t: np.ndarray,
    dur: float,
    standard: str,
    limit_attrs: dict[str, Any],
    *,
    peak: str,
    over: str,
    peak_only: dict[str, Any] | None = None,
) -> None:
    """``{name}_max``, the largest value of ``da`` (time, ...) per channel, and
    ``{name}_time_over_limit``, the time it stays above ``limit_attrs["limit"]`` in spells of at
    least ``dur`` s (:func:`time_over_limit`), both with ``limit_attrs`` among their attributes."""
    dims = tuple(d for d in da.dims if d != "time")
    out[f"{name}_max"] = (
        dims,
        np.asarray(da.max("time").values, dtype=float),
        _attrs("1", peak, standard, **(peak_only or {}), **limit_attrs),
    )
    out[f"{name}_time_over_limit"] = (
        dims,
        _time_over(t, da, limit_attrs["limit"], dur),
        _attrs("s", f"time {over} in spells ≥ {dur * 1e3:g} ms", standard, min_duration=dur, **limit_attrs),
    )


def _add_derailment(
    out: Any,
    ds: Any,
    part: Any,
    t: np.ndarray,
    within: str,
    *,
    friction: float,
    dur: float,
    static_load: Any,
    settle: Any,
) -> tuple[Any, Any]:
    """Derailment: L/V against Nadal's limit, the Weinstock sum and the wheel unloading
    (:func:`add_indicators`); returns the Dataset and the wheel loads (time, wheelset, side)."""
    import xarray as xr

    from railslosh import results

    delta = flange_angle(ds)
    nadal = nadal_limit(delta, friction)
    if "l_over_v" in ds:
        lv_all, lv = ds["l_over_v"], part["l_over_v"]
        lv_note = "the run's l_over_v"
    else:
        q_lv = ds["wheel_vertical"]
        lv_all = xr.where(q_lv > 0, abs(ds["wheel_lateral"]) / q_lv.where(q_lv > 0), 0.0)
        lv = lv_all.sel(time=part["time"])
        lv_note = "|wheel_lateral| / wheel_vertical (0 where the wheel is off the rail)"
    nadal_std = f"Nadal (1908) flange-climb limit (tan δ − μ)/(1 + μ tan δ); {_AAR_DURATION}"
    lim_attrs = {
        "limit": nadal,
        "flange_angle": delta,
        "friction": float(friction),
        "wheel_profile": wheel_profile(ds),
    }
    _add_peak_and_time_over(
        out,
        "l_over_v",
        lv,
        t,
        dur,
        nadal_std,
        lim_attrs,
        peak=f"largest wheel L/V = |Y|/Q {within}",
        over=f"the wheel L/V stays above Nadal's limit {nadal:.3f}",
        peak_only={"source": lv_note},
    )
    ws = weinstock_sum(np.asarray(lv_all.transpose("time", "wheelset", "side").values, dtype=float))
    wstd = f"Weinstock (1984) axle-sum L/V; limit {WEINSTOCK_LIMIT:g}: AAR MSRP C-II Chapter XI; {_AAR_DURATION}"
    out["weinstock"] = (
        ("time", "wheelset"),
        ws,
        _attrs("1", "axle sum of the wheel L/V ratios |Y_l|/Q_l + |Y_r|/Q_r (Weinstock)", wstd, limit=WEINSTOCK_LIMIT),
    )
    _add_peak_and_time_over(
        out,
        "weinstock",
        out["weinstock"].sel(time=part["time"]),
        t,
        dur,
        wstd,
        {"limit": WEINSTOCK_LIMIT},
        peak=f"largest axle-sum L/V (Weinstock) {within}",
        over=f"the axle-sum L/V stays above {WEINSTOCK_LIMIT:g}",
    )
    q_all = ds["wheel_vertical"].transpose("time", "wheelset", "side")
    if static_load is not None:
        q0 = np.broadcast_to(np.asarray(static_load, dtype=float), q_all.shape[1:]).copy()
        q0_note = "given (static_load)"
    elif settle.time > 0:
        q0 = np.asarray(results.after_settling(ds, settle)["wheel_vertical"].transpose("time", ...).values[0])
        q0_note = f"each wheel's load at the end of the settling phase (t = {settle.time:g} s, {settle.source})"
    elif "static_wheel_load" in ds.attrs:
        q0 = np.full(q_all.shape[1:], float(ds.attrs["static_wheel_load"]))
        q0_note = "the run's static wheel load (static_wheel_load attribute)"
    else:
        q0 = np.asarray(q_all.values[0], dtype=float)
        q0_note = "each wheel's first recorded load"
    unl_lim = float(ds.attrs.get("unloading_limit", UNLOADING_LIMIT))
    unl = wheel_unloading(np.asarray(part["wheel_vertical"].transpose("time", "wheelset", "side").values), q0)
    unl_da = xr.DataArray(unl, dims=("time", "wheelset", "side"))
    ustd = f"{UNLOADING_STANDARD} (limit {unl_lim:g}); {_AAR_DURATION}"
    out["wheel_load_reference"] = (
        ("wheelset", "side"),
        q0,
        _attrs("N", "static wheel load Q0 of the unloading ΔQ/Q0", UNLOADING_STANDARD, source=q0_note),
    )
    _add_peak_and_time_over(
        out,
        "unloading",
        unl_da,
        t,
        dur,
        ustd,
        {"limit": unl_lim, "reference": q0_note},
        peak=f"largest wheel unloading (Q0 − Q)/Q0 {within}",
        over=f"the wheel unloading stays above {unl_lim:g}",
    )
    return out, q_all


def _add_load_transfer(out: Any, ds: Any, q_all: Any, after: float, within: str, skipped: list[str]) -> Any:
    """Roll-over: the load transfer ratio of each bogie and car (:func:`add_indicators`)."""
    nw, ncar = ds.sizes["wheelset"], ds.sizes.get("car", 1)
    per = nw // ncar if ncar and nw % ncar == 0 else 0
    if per >= 2 and per % 2 == 0:
        q = np.asarray(q_all.values, dtype=float)
        ltr_std = "load transfer ratio (ΣQ_right − ΣQ_left)/(ΣQ_right + ΣQ_left); |LTR| = 1: one side lifted off"
        bogie = load_transfer_ratio(q.reshape(q.shape[0], 2 * ncar, per // 2, 2))
        car = load_transfer_ratio(q.reshape(q.shape[0], ncar, per, 2))
        out = out.assign_coords(
            bogie=("bogie", np.arange(1, 2 * ncar + 1), {"long_name": "bogie, front to rear over all cars"})
        )
        if "car" not in out.coords:
            out = out.assign_coords(car=("car", np.arange(1, ncar + 1), {"long_name": "car, front to rear"}))
        keep = np.flatnonzero(np.asarray(ds["time"].values) >= after - 1e-12)
        for name, val, dim, what in (
            ("load_transfer_bogie", bogie, "bogie", "bogie"),
            ("load_transfer_car", car, "car", "car"),
        ):
            out[name] = (
                ("time", dim),
                val,
                _attrs("1", f"load transfer ratio of each {what} (positive: to the right)", ltr_std, limit=1.0),
            )
            out[f"{name}_max"] = (
                (dim,),
                np.fmax.reduce(np.abs(val[keep]), axis=0),
                _attrs("1", f"largest |load transfer ratio| of each {what} {within}", ltr_std, limit=1.0),
            )
    else:
        skipped.append(f"load transfer ratio: {nw} wheelsets on {ncar} car(s) do not split into two-axle bogies")
    return out


def _add_load_spectra(
    out: Any, ds: Any, part: Any, within: str, *, m: float, neq: float, neq_note: str, bins: int
) -> Any:
    """Load spectra: rainflow counts, damage-equivalent loads and level crossings (:func:`add_indicators`)."""
    for name in _SPECTRA:
        if name not in part or not part[name].size or "time" not in part[name].dims:
            continue
        da = part[name].transpose("time", ...)
        chan = list(da.dims[1:])
        units = ds[name].attrs.get("units", "")
        what = ds[name].attrs.get("long_name", name)
        flat = np.asarray(da.values, dtype=float).reshape(da.shape[0], -1)
        cyc = [rainflow_cycles(flat[:, k]) for k in range(flat.shape[1])]
        top = max((float(c[0].max()) for c in cyc if c[0].size), default=0.0)
        edges = np.linspace(0.0, top if top > 0 else 1.0, bins + 1)
        counts = np.array([_binned(c[0], c[2], edges) for c in cyc]).reshape(*da.shape[1:], bins)
        dels = np.array([_equivalent_amplitude(c[0], c[2], m, neq) for c in cyc]).reshape(da.shape[1:])
        finite = flat[np.isfinite(flat)]
        lo, hi = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 0.0)
        levels = np.linspace(lo, hi, bins + 1)
        cross = np.array([level_crossings(flat[:, k], levels) for k in range(flat.shape[1])]).reshape(
            *da.shape[1:], bins + 1
        )
        rdim, ldim = f"{name}_range", f"{name}_level"
        out = out.assign_coords(
            {
                rdim: (
                    rdim,
                    edges[1:],
                    {"units": units, "long_name": f"upper edge of the rainflow range bin of {what}"},
                ),
                ldim: (ldim, levels, {"units": units, "long_name": f"load level of {what}"}),
            }
        )
        out[f"{name}_rainflow"] = (
            (*chan, rdim),
            counts,
            _attrs(
                "1",
                f"rainflow cycle counts of {what} by range {within} (half cycles count 0.5)",
                _RAINFLOW_STANDARD,
                bin_width=float(edges[1] - edges[0]),
            ),
        )
        out[f"{name}_del"] = (
            tuple(chan),
            dels,
            _attrs(
                units,
                f"damage-equivalent load amplitude of {what} {within}",
                f"Palmgren–Miner with Wöhler exponent m = {m:g}: DEL = (Σ n_i S_a,i^m / N_eq)^(1/m); "
                + _RAINFLOW_STANDARD,
                wohler_exponent=m,
                n_eq=neq,
                convention="amplitude S_a = range/2; equivalent range = 2 DEL; no mean-stress correction",
                equivalent=neq_note,
            ),
        )
        out[f"{name}_crossings"] = (
            (*chan, ldim),
            cross,
            _attrs(
                "1",
                f"level crossings of {what} {within}: upward above the mean, downward below it",
                "ASTM E1049-85 §5.1.1 level-crossing counting",
            ),
        )

    return out


def _add_ride(out: Any, ds: Any, part: Any, t: np.ndarray, within: str, acceleration: str, skipped: list[str]) -> Any:
    """Ride: Sperling Wz and the ISO 2631 weighted RMS acceleration (:func:`add_indicators`)."""
    has_acc = acceleration in ds and {"time", "car", "component"} <= set(ds[acceleration].dims)
    if has_acc and (t.size < 8 or not np.isfinite(part[acceleration].values).all()):
        skipped.append(f"ride: fewer than 8 samples, or non-finite values, of {acceleration}")
    elif has_acc:
        acc = part[acceleration].transpose("time", "car", "component")
        comps = [str(c) for c in acc["component"].values]
        if not set(comps) <= set(_ISO_AXES):
            raise invalid(f"{acceleration}.component", comps, "components among 'x', 'y', 'z'")
        wz = np.full((acc.sizes["car"], 2), np.nan)
        aw = np.full((acc.sizes["car"], len(comps)), np.nan)
        for k in range(acc.sizes["car"]):
            for j, c in enumerate(comps):
                series = np.asarray(acc.values[:, k, j], dtype=float)
                aw[k, j] = iso2631_weighted_rms(t, series, c)
                if c in ("z", "y"):
                    wz[k, 0 if c == "z" else 1] = sperling_wz(t, series, "vertical" if c == "z" else "lateral")
        out = out.assign_coords(direction=("direction", ["vertical", "lateral"]))
        out["sperling_wz"] = (
            ("car", "direction"),
            wz,
            _attrs("1", f"Sperling ride index Wz {within}", _SPERLING_STANDARD, source=acceleration),
        )
        out["iso2631_weighted_rms"] = (
            ("car", "iso_axis"),
            aw,
            _attrs(
                "m/s2", f"ISO 2631-1 frequency-weighted RMS acceleration {within}", _ISO_STANDARD, source=acceleration
            ),
        )
        out = out.assign_coords(iso_axis=("iso_axis", comps))
    elif "tank_speed" in ds and "car" in ds["tank_speed"].dims:
        v = np.asarray(part["tank_speed"].transpose("time", "car").values, dtype=float)
        if t.size >= 8 and np.isfinite(v).all():
            a = np.gradient(v, t, axis=0)
            aw = np.array([[iso2631_weighted_rms(t, a[:, k], "x")] for k in range(v.shape[1])])
            out = out.assign_coords(iso_axis=("iso_axis", ["x"]))
            out["iso2631_weighted_rms"] = (
                ("car", "iso_axis"),
                aw,
                _attrs(
                    "m/s2",
                    f"ISO 2631-1 frequency-weighted RMS acceleration (W_d) {within}",
                    _ISO_STANDARD,
                    derived="longitudinal acceleration d(tank_speed)/dt by numpy.gradient (2nd-order central "
                    "differences); no car-body acceleration recorded",
                ),
            )
        else:
            skipped.append("ride (ISO 2631 x): fewer than 8 finite tank_speed samples")
        skipped.append("Sperling ride index and ISO 2631 y/z: no car-body acceleration recorded")
    else:
        skipped.append("ride: no car-body acceleration or tank speed recorded")
    return out


def add_indicators(
    ds: Any,
    *,
    wohler_exponent: float = 3.0,
    n_eq: float | None = None,
    equivalent_frequency: float = 1.0,
    bins: int = 20,
    friction: float = NADAL_FRICTION,
    min_duration: float = MIN_DURATION,
    static_load: Any = None,
    include_settling: bool = False,
    acceleration: str = ACCELERATION_VARIABLE,
) -> Any:
    """A copy of a results Dataset (:func:`railslosh.results.to_dataset`) with every indicator
    its variables support, each with ``units``, ``long_name`` and ``standard`` attributes. Maxima,
    durations, spectra and ride values cover the run after the settling phase
    (:func:`railslosh.results.settling`; the whole run with ``include_settling``); the global
    attribute ``indicators_after`` holds its start (s) and ``indicators_skipped`` says what the
    run does not record.

    * Derailment (wheel loads): ``l_over_v_max`` and ``l_over_v_time_over_limit`` per wheel against
      Nadal's limit (:func:`nadal_limit`, the profile's flange angle, μ = ``friction``);
      ``weinstock`` (time series), ``weinstock_max`` and ``weinstock_time_over_limit`` per axle
      against :data:`WEINSTOCK_LIMIT`; ``unloading_max`` and ``unloading_time_over_limit`` per wheel
      against the ``unloading_limit`` attribute or :data:`UNLOADING_LIMIT`, with Q₀ =
      ``wheel_load_reference``: ``static_load`` (N) when given, else each wheel's load at the end
      of the settling phase when the run has one, else the ``static_wheel_load`` attribute. Times
      over a limit count exceedances of ``min_duration`` (50 ms) or longer (:func:`exceedances`).
    * Roll-over: ``load_transfer_bogie`` and ``load_transfer_car`` (time series,
      :func:`load_transfer_ratio`) and their largest ``|LTR|``, ``*_max``.
    * Load spectra of ``coupler_force``, ``wheel_vertical``, ``fluid_force_tank`` and ``force_tank``
      (those present): ``<name>_rainflow`` (cycle counts in ``bins`` range bins, coordinate
      ``<name>_range`` = upper bin edge), ``<name>_del`` (:func:`damage_equivalent_load` for
      ``wohler_exponent`` and N_eq = ``n_eq``, default ``equivalent_frequency`` × the evaluated
      duration: the 1 Hz equivalent load), ``<name>_crossings`` (:func:`level_crossings` at
      ``bins`` + 1 levels from the smallest to the largest value, coordinate ``<name>_level``).
    * Ride: with a car-body acceleration ``acceleration`` (dims time, car, component; m/s²)
      ``sperling_wz`` (car, direction) and ``iso2631_weighted_rms`` (car, component). Without it,
      the longitudinal ``iso2631_weighted_rms`` (component x) of the acceleration got by
      differentiating ``tank_speed`` (said in its ``derived`` attribute); no Sperling index (it has
      no longitudinal weighting).
    """

    from railslosh import results

    m = _positive("wohler_exponent", wohler_exponent, "a Wöhler exponent")
    feq = _positive("equivalent_frequency", equivalent_frequency, "a frequency in Hz")
    if n_eq is not None:
        _positive("n_eq", n_eq, "an equivalent cycle count")
    if isinstance(bins, bool) or not isinstance(bins, int | np.integer) or bins < 1:
        raise invalid("bins", bins, "a whole number ≥ 1")
    dur = _positive("min_duration", min_duration, "a duration in s", zero=True)
    if "time" not in ds.dims:
        raise invalid("ds", "Dataset without a time dimension", "a results Dataset (railslosh.results.to_dataset)")
    out = ds.copy()
    settle = results.settling(ds)
    after = 0.0 if include_settling else settle.time
    part = results.after_settling(ds, after)
    t = np.asarray(part["time"].values, dtype=float)
    skipped: list[str] = []
    out.attrs["indicators_after"] = float(after)
    if t.size < 2:
        out.attrs["indicators_skipped"] = f"all: fewer than 2 samples at t ≥ {after:g} s"
        return out
    span = float(t[-1] - t[0])
    within = f"over {t[0]:g} ≤ t ≤ {t[-1]:g} s" + (" (after settling)" if after > 0 else "")

    # derailment and roll-over
    if "wheel_vertical" in ds and "side" in ds["wheel_vertical"].dims and ds.sizes.get("wheelset", 0):
        out, q_all = _add_derailment(
            out, ds, part, t, within, friction=friction, dur=dur, static_load=static_load, settle=settle
        )
        out = _add_load_transfer(out, ds, q_all, after, within, skipped)
    else:
        skipped.append("derailment and roll-over: no wheel loads (wheel_vertical) recorded")

    # load spectra
    neq = float(n_eq) if n_eq is not None else feq * span
    neq_note = f"N_eq = {neq:g}" + ("" if n_eq is not None else f" ({feq:g} Hz × {span:g} s evaluated)")
    out = _add_load_spectra(out, ds, part, within, m=m, neq=neq, neq_note=neq_note, bins=bins)
    if not any(n in part for n in _SPECTRA):
        skipped.append("load spectra: no coupler, wheel or liquid loads recorded")

    # ride
    out = _add_ride(out, ds, part, t, within, acceleration, skipped)
    if skipped:
        out.attrs["indicators_skipped"] = "; ".join(skipped)
    return out
