"""Participant protocols and the exchanged data of the co-simulation (issue 6, seed 003).

Two kinds of participant meet at one rigid tank:

* a **slosh participant** (:class:`SloshParticipant`) takes the tank motion in seed 003's
  interface and returns the load of the fluid on the tank;
* a **vehicle participant** (:class:`VehicleParticipant`) takes that load and returns the
  tank motion.

Tank motion (seed 003 §3.1, Jacman report: linear acceleration, angular velocity and angular
acceleration of the tank, plus the gravity direction) is a dict with four 3-vectors, all in
**tank axes** (docs/frames.md, frame K):

``acceleration``
    inertial acceleration of the tank origin, m/s², *without* gravity;
``angular_velocity``
    angular velocity of the tank, rad/s;
``angular_acceleration``
    angular acceleration of the tank, rad/s²;
``gravity``
    the gravity vector, m/s² (``(0, 0, -9.80665)`` for a level tank).

A load is ``(force, moment)``: the force the fluid exerts **on the tank** and its moment about
the tank origin, tank axes (docs/frames.md, "Signs of forces and loads").

Both protocols share ``time``, ``save_state()`` and ``restore_state(state)`` (checkpointing for
the implicit masters). ``advance(t_end, input_start, input_end)`` integrates from ``time`` to
``t_end`` with the input varying linearly in time between the two values and returns the output
at ``t_end``; ``t_end == time`` is allowed for the emulators and only evaluates the output for ``input_end``; a
slosh participant that rejects zero-length windows (``railslosh._core.SloshParticipant``) provides
``set_initial_input(motion) -> (force, moment)`` instead, which the masters use at the start.
The Rust participant (issue 6, ``crates/railslosh-py/src/cosim.rs``) has this interface;
its ``added_mass()`` is the whole liquid as a rigid body, an over-estimate of the added mass
(see :func:`railslosh.cosim.centrifuge.critical_ratio` for what that means for splitting).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any, Protocol, runtime_checkable

import numpy as np

MOTION_KEYS = ("acceleration", "angular_velocity", "angular_acceleration", "gravity")
"""Keys of a tank-motion dict, in the order of :func:`motion_to_vector`."""

Load = tuple[np.ndarray, np.ndarray]


@runtime_checkable
class SloshParticipant(Protocol):
    """The slosh side: tank motion in, fluid load on the tank out."""

    @property
    def time(self) -> float:
        """Current time of the participant, s."""
        ...

    def advance(
        self, t_end: float, input_start: Mapping[str, Any], input_end: Mapping[str, Any]
    ) -> tuple[Sequence[float], Sequence[float]]:
        """Advance to ``t_end`` under motion varying linearly from ``input_start`` to ``input_end``;
        return (force[3], moment[3]) on the tank at ``t_end``."""
        ...

    def save_state(self) -> Any:
        """Return an opaque checkpoint of the state (including ``time``)."""
        ...

    def restore_state(self, state: Any) -> None:
        """Return to a checkpoint taken by :meth:`save_state`."""
        ...

    def added_mass(self) -> Any:
        """6x6 estimate of the rigidly carried mass M_a about the tank origin, tank axes:
        the load depends on the tank acceleration as ``-M_a @ [acceleration, angular_acceleration]``."""
        ...


@runtime_checkable
class VehicleParticipant(Protocol):
    """The vehicle side: fluid load in (6-vector force, moment), tank motion out."""

    @property
    def time(self) -> float: ...

    def advance(self, t_end: float, load_start: Sequence[float], load_end: Sequence[float]) -> dict[str, np.ndarray]:
        """Advance to ``t_end`` under the load varying linearly between the two 6-vectors; return
        the tank-motion dict at ``t_end`` (accelerations consistent with ``load_end``)."""
        ...

    def save_state(self) -> Any: ...

    def restore_state(self, state: Any) -> None: ...

    def set_added_mass(self, added_mass: np.ndarray | None) -> None:
        """Added-mass splitting: from now on the vehicle carries ``added_mass`` (6x6, tank axes)
        in its own inertia, and the load it receives is the *exchanged* load ``L + M_a @ acc``."""
        ...


def invalid(name: str, value: object, allowed: str) -> ValueError:
    """The project's error for a bad parameter: names the field and the allowed range."""
    return ValueError(f"invalid `{name}` = {value!r}: expected {allowed}")


def check_positive(name: str, value: float, *, allow_zero: bool = False) -> float:
    """Return ``value`` as float if it is finite and > 0 (>= 0 with ``allow_zero``)."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise invalid(name, value, "a finite number " + (">= 0" if allow_zero else "> 0")) from None
    if not math.isfinite(v) or v < 0 or (v == 0 and not allow_zero):
        raise invalid(name, value, "a finite number " + (">= 0" if allow_zero else "> 0"))
    return v


def check_vector(name: str, value: object, n: int = 3) -> np.ndarray:
    """Return ``value`` as a finite float array of shape (n,)."""
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise invalid(name, value, f"a finite {n}-vector") from None
    if v.shape != (n,) or not np.all(np.isfinite(v)):
        raise invalid(name, value, f"a finite {n}-vector")
    return v


def check_motion(motion: Mapping[str, Any], name: str = "motion") -> dict[str, np.ndarray]:
    """Validate a tank-motion dict and return it with float arrays.

    Raises ``ValueError`` naming the missing or bad field (e.g. ``motion.gravity``)."""
    if not isinstance(motion, Mapping):
        raise invalid(name, motion, f"a dict with keys {list(MOTION_KEYS)}")
    missing = [k for k in MOTION_KEYS if k not in motion]
    extra = [k for k in motion if k not in MOTION_KEYS]
    if missing or extra:
        raise invalid(name, sorted(motion), f"exactly the keys {list(MOTION_KEYS)} (missing {missing}, extra {extra})")
    return {k: check_vector(f"{name}.{k}", motion[k]) for k in MOTION_KEYS}


def check_load(load: object, name: str = "load") -> np.ndarray:
    """A load given as a 6-vector or as (force[3], moment[3]); returned as a 6-vector."""
    if isinstance(load, tuple | list) and len(load) == 2:
        return np.concatenate([check_vector(f"{name}.force", load[0]), check_vector(f"{name}.moment", load[1])])
    return check_vector(name, load, 6)


def motion_to_vector(motion: Mapping[str, Any]) -> np.ndarray:
    """Tank-motion dict -> 12-vector in the order of :data:`MOTION_KEYS`."""
    return np.concatenate([np.asarray(motion[k], dtype=float) for k in MOTION_KEYS])


def vector_to_motion(v: np.ndarray) -> dict[str, np.ndarray]:
    """12-vector -> tank-motion dict (inverse of :func:`motion_to_vector`)."""
    v = np.asarray(v, dtype=float)
    return {k: v[3 * i : 3 * i + 3].copy() for i, k in enumerate(MOTION_KEYS)}


def motion_acceleration6(motion: Mapping[str, Any]) -> np.ndarray:
    """[acceleration, angular_acceleration]: the 6-vector that multiplies the added mass."""
    return np.concatenate(
        [np.asarray(motion["acceleration"], float), np.asarray(motion["angular_acceleration"], float)]
    )
