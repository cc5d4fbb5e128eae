"""Interpolation and extrapolation over the last three samples (seed 003 §2.3.1, ``interp.f``).

The Glue Code of seed 003 hands each code the other's data "interpolated and extrapolated ...
based upon the last three successful iterations". :class:`ThreeSampleHistory` keeps the last
three (t, value) samples and evaluates the Lagrange polynomial through them: quadratic with
three samples (exact for quadratics, error O(h³) for smooth data), linear with two, constant
with one.
"""

from __future__ import annotations

from collections import deque

import numpy as np

from railslosh.cosim.protocol import invalid


def lagrange_weights(times: np.ndarray, t: float) -> np.ndarray:
    """Weights w_i with p(t) = Σ w_i y_i for the polynomial through (times_i, y_i)."""
    times = np.asarray(times, dtype=float)
    w = np.ones(len(times))
    for i, ti in enumerate(times):
        for j, tj in enumerate(times):
            if i != j:
                w[i] *= (t - tj) / (ti - tj)
    return w


class ThreeSampleHistory:
    """Last ``order + 1`` samples (order 2 = seed 003's three-sample scheme) of a vector signal."""

    def __init__(self, order: int = 2):
        if order not in (0, 1, 2):
            raise invalid("order", order, "0, 1 or 2 (constant, linear, quadratic)")
        self.order = order
        self._t: deque[float] = deque(maxlen=order + 1)
        self._y: deque[np.ndarray] = deque(maxlen=order + 1)

    def __len__(self) -> int:
        return len(self._t)

    def push(self, t: float, y: np.ndarray) -> None:
        """Add a sample; times must increase strictly."""
        if self._t and not t > self._t[-1]:
            raise invalid("t", t, f"> last sample time {self._t[-1]}")
        self._t.append(float(t))
        self._y.append(np.array(y, dtype=float))

    def replace_last(self, y: np.ndarray) -> None:
        """Overwrite the value of the latest sample (same time)."""
        self._y[-1] = np.array(y, dtype=float)

    @property
    def times(self) -> list[float]:
        return list(self._t)

    def values(self) -> list[np.ndarray]:
        return list(self._y)

    def __call__(self, t: float) -> np.ndarray:
        """Polynomial through the stored samples, evaluated at ``t`` (inter- or extrapolation)."""
        if not self._t:
            raise ValueError("ThreeSampleHistory is empty: push a sample first")
        if len(self._t) == 1:
            return self._y[0].copy()
        w = lagrange_weights(np.array(self._t), t)
        return np.tensordot(w, np.array(self._y), axes=1)
