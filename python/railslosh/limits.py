"""Parameter limits shared by scene files and the Python API, and the one form of every input
error: ``invalid `dotted.field` = value: expected …``.

    >>> from railslosh import limits
    >>> limits.check("fill", 0.5)
    0.5
    >>> limits.check("fill", 0.99, "fluid.fill")
    Traceback (most recent call last):
    ValueError: invalid `fluid.fill` = 0.99: expected a volume fraction from 0.03 to 0.97

:data:`PARAMETERS` is the table of the limits that scenes (:mod:`railslosh.scene`) and the API
functions taking the same parameter (:func:`railslosh.mesh.cylinder_tank`,
:func:`railslosh.vehicle.run_fluid`, ...) both check. The compiled kernels raise their errors in the same form.
"""

from __future__ import annotations

import difflib
import functools
import math
import numbers
import re
import types
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

__all__ = [
    "FILL",
    "PARAMETERS",
    "Limit",
    "check",
    "invalid",
    "missing",
    "name_native_arguments",
    "suggest",
    "unknown",
]

_MAX_SHOWN = 100  # characters of a value quoted in a message


def _show(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= _MAX_SHOWN else text[: _MAX_SHOWN - 1] + "…"


def invalid(field: str, value: Any, expected: str) -> ValueError:
    """The error of a bad value: ``invalid `field` = value: expected <expected>``."""
    return ValueError(f"invalid `{field}` = {_show(value)}: expected {expected}")


def missing(field: str, expected: str) -> ValueError:
    """The error of a required field (or section) that is not given."""
    return ValueError(f"invalid `{field}`: missing; expected {expected}")


def suggest(name: str, allowed: Iterable[str]) -> str | None:
    """The allowed name closest to a misspelled ``name`` (``difflib``), or None."""
    names = [a for a in allowed if isinstance(a, str)]
    if not isinstance(name, str):
        return None
    lower = {a.lower(): a for a in names}
    if name.lower() in lower:
        return lower[name.lower()]
    close = difflib.get_close_matches(name, names, n=1, cutoff=0.6)
    return close[0] if close else None


def unknown(field: str, what: str, allowed: Iterable[str], prefix: str = "") -> ValueError:
    """The error of an unknown key or section ``field`` (dotted), with a "did you mean" suggestion
    among ``allowed`` (names without ``prefix``)."""
    names = sorted(allowed)
    name = field.rsplit(".", 1)[-1] if prefix else field
    close = suggest(name, names)
    hint = f" (did you mean `{prefix}{close}`?)" if close is not None else ""
    return ValueError(f"invalid `{field}`: unknown {what}{hint}; expected one of {', '.join(names)}")


@dataclass(frozen=True)
class Limit:
    """The range of a number: ``lo`` to ``hi`` (``lo`` excluded when ``lo_open``) in ``unit``;
    ``noun`` says what the number is in messages ("a time", "a volume fraction")."""

    lo: float
    hi: float
    unit: str = ""
    noun: str = "a number"
    lo_open: bool = False
    integer: bool = False

    def expected(self, lo: float | None = None, hi: float | None = None, note: str = "") -> str:
        """What is allowed, in words: ``a time > 0 s and ≤ 600 s``, ``a speed from 0 to 70 m/s``."""
        lo = self.lo if lo is None else lo
        hi = self.hi if hi is None else hi
        u = f" {self.unit}" if self.unit else ""
        rng = f"> {lo:g}{u} and ≤ {hi:g}{u}" if self.lo_open else f"from {lo:g} to {hi:g}{u}"
        return f"{self.noun} {rng}{note}"

    def check(self, value: Any, field: str, *, lo: float | None = None, hi: float | None = None, note: str = "") -> Any:
        """``value`` as a float (an int for integer limits) when it is a number (not a boolean) in
        the range; else the ``ValueError`` of :func:`invalid`. ``lo``/``hi`` narrow the range for
        limits that depend on other fields; ``note`` adds why."""
        lo_ = self.lo if lo is None else lo
        hi_ = self.hi if hi is None else hi
        if self.integer:
            n = int(value) if isinstance(value, numbers.Integral) and not isinstance(value, bool) else None
            if n is None or not lo_ <= n <= hi_:
                raise invalid(field, value, self.expected(lo_, hi_, note))
            return n
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            raise invalid(field, value, self.expected(lo_, hi_, note))
        try:
            x = float(value)
        except OverflowError:  # an integer beyond the float range
            x = math.inf
        if not math.isfinite(x) or x < lo_ or x > hi_ or (self.lo_open and x <= lo_):
            raise invalid(field, value, self.expected(lo_, hi_, note))
        return x


FILL = Limit(0.03, 0.97, noun="a volume fraction")
"""Liquid volume as a fraction of the tank volume. The tank meshes (``ancf_core::mesh``) map the
wetted cross-section, the segment of the circle below the free surface, onto a structured grid;
the element at each end of the free surface has a corner where the surface meets the wall, at the
half-angle of the wetted arc: 30° at fill 0.029, 90° at 0.5, 150° at 0.971 (for an ellipse, the
same in its parametric angle). Within 0.03 to 0.97 that corner stays between 30° and 150° (0.97 is
the mesh builder's own upper bound); beyond, those elements degenerate: a sliver at low fill
(where the elements of the paper's 6×4×2 tank-car mesh are also 20 times longer than high at
0.03), a flat corner at high fill."""

PARAMETERS: dict[str, Limit] = {
    "fill": FILL,
    "wall_damping_ratio": Limit(0.0, 10.0, noun="a damping ratio"),
    "wall_adhesion": Limit(0.0, 50.0, noun="a suction in units of the hydrostatic pressure rho g H"),
}
"""The limits checked alike by scenes and by the API functions that take these parameters."""


def check(name: str, value: Any, field: str | None = None) -> Any:
    """Checks ``value`` against ``PARAMETERS[name]``; ``field`` names it in the error (default
    ``name``). Returns the value as a float."""
    return PARAMETERS[name].check(value, field or name)


_NOTE = re.compile(r"while processing '([^']+)'")


def _native_argument(error: Exception) -> str | None:
    """The argument that a compiled function's extraction error is about: PyO3 names it only in a
    note (``while processing 't_end'``), which ``str(error)`` leaves out."""
    for note in getattr(error, "__notes__", ()):
        m = _NOTE.fullmatch(note)
        if m:
            return m.group(1)
    return None


def _named(fn: Callable[..., Any]) -> Callable[..., Any]:
    @functools.wraps(fn)
    def call(*args: Any, **kwargs: Any) -> Any:
        try:
            return fn(*args, **kwargs)
        except (TypeError, ValueError, OverflowError) as e:
            # PyO3 notes the argument on every extraction error: a wrong type (TypeError), a
            # negative count (OverflowError) or a point of the wrong length (ValueError)
            field = _native_argument(e)
            if field is None:
                raise
            shown = f" = {_show(kwargs[field])}" if field in kwargs else ""
            if isinstance(e, TypeError):
                raise TypeError(f"invalid `{field}`{shown}: {e}") from e
            why = f"expected a non-negative integer in range ({e})" if isinstance(e, OverflowError) else str(e)
            raise ValueError(f"invalid `{field}`{shown}: {why}") from e

    return call


def name_native_arguments(module: types.ModuleType) -> None:
    """Wraps every function of the compiled module ``module`` (``railslosh._core``) in place so
    that an argument of the wrong type raises ``TypeError: invalid `t_end` = 'abc': must be real
    number, not str`` instead of PyO3's message without the argument's name. Idempotent."""
    for name, obj in vars(module).items():
        if isinstance(obj, types.BuiltinFunctionType) and not name.startswith("_"):
            setattr(module, name, _named(obj))
