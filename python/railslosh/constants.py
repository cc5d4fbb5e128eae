"""Physical constants and unit conversions, one definition each.

They are the Rust crate's values (``ancf_core::constants``, ``rail_mbs::track``), read from
``railslosh._core``, so Python, Rust, the scenes and the FMU use the same numbers.
"""

from __future__ import annotations

from railslosh import _core

GRAVITY: float = _core.GRAVITY
"""Standard gravity g0, m/s^2 (9.80665, 3rd CGPM 1901): every default and validation case."""
FOOT: float = _core.FOOT
"""One international foot, m."""
INCH: float = _core.INCH
"""One inch, m."""
MPH: float = _core.MPH
"""One mile per hour, m/s."""
ARC_DEGREE_RADIUS_FT: float = _core.ARC_DEGREE_RADIUS_FT
"""Radius, in feet, of a 1-degree curve by the arc definition (100 ft of arc per degree)."""

__all__ = ["ARC_DEGREE_RADIUS_FT", "FOOT", "GRAVITY", "INCH", "MPH"]
