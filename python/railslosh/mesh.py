"""Structured ANCF fluid meshes, in the tank frame (x forward along the axis, y left, z up,
origin at the tank centre).

Each function returns a :class:`railslosh.FluidMesh`; invalid arguments raise ``ValueError``
naming the field and its allowed range.
"""

from __future__ import annotations

import math

from railslosh import _core, limits
from railslosh._core import FluidMesh

#: Head depth of the tank car. The paper gives none; 0.5 m is a typical 2:1-type
#: semi-ellipsoidal head depth for a 3 m diameter DOT-111/117 car (R/3). The vehicle runs' value,
#: ``ancf_core::mesh::TANK_CAR_HEAD_DEPTH``.
TANK_CAR_HEAD_DEPTH: float = _core.TANK_HEAD_DEPTH
#: Tank of the crude-oil study (seed 000 §8.1, "a length of approximately 12 m", radius 1.5 m): the
#: vehicle runs' tank, 12 m overall, so its shell between the heads is 11 m long
#: (``ancf_core::mesh::TANK_CAR_LENGTH`` and ``TANK_CAR_RADIUS``, the one home of these numbers).
TANK_CAR_SHELL_LENGTH: float = _core.TANK_CAR_LENGTH - 2.0 * TANK_CAR_HEAD_DEPTH
TANK_CAR_RADIUS: float = _core.TANK_CAR_RADIUS
#: Deprecated alias (one release) of :data:`TANK_CAR_SHELL_LENGTH`, the shell length; until
#: 2026-11-26 it was 12 m, a 13 m tank overall, 1 m longer than the vehicle runs' tank.
TANK_CAR_LENGTH: float = TANK_CAR_SHELL_LENGTH

#: SwRI elliptical tank of seed 003 appendix C: 22.9845 y^2 + 57.2785 z^2 = 1, L = 0.324 m.
SWRI_SEMI_AXIS_Y = 1.0 / math.sqrt(22.9845)
SWRI_SEMI_AXIS_Z = 1.0 / math.sqrt(57.2785)
SWRI_LENGTH = 0.324


def box(
    size: tuple[float, float, float],
    counts: tuple[int, int, int],
    origin: tuple[float, float, float] | None = None,
) -> FluidMesh:
    """A rectangular block of fluid of ``size`` (m) with ``counts`` elements.

    By default the block is centred in x and y with its bottom at z = 0.
    """
    if origin is None:
        origin = (-0.5 * size[0], -0.5 * size[1], 0.0)
    return _core.box_mesh(tuple(origin), tuple(size), tuple(int(c) for c in counts))


def cylinder_tank(
    *,
    length: float = TANK_CAR_SHELL_LENGTH,
    radius: float = TANK_CAR_RADIUS,
    head_depth: float = TANK_CAR_HEAD_DEPTH,
    fill: float = 0.5,
    n_length: int = 6,
    n_width: int = 4,
    n_height: int = 2,
    grading: float = 1.0,
) -> FluidMesh:
    """Liquid in a horizontal cylinder with half-ellipsoidal heads.

    Parameters
    ----------
    length:
        Length of the cylindrical shell between the head tangent lines (m).
    radius:
        Shell radius (m).
    head_depth:
        Depth of each half-ellipsoidal head (m); 0 gives flat ends.
    fill:
        Liquid volume as a fraction of the tank volume, :data:`railslosh.limits.FILL` (0.03 to 0.97,
        the range scenes accept).
    n_length, n_width, n_height:
        Element counts. The crude-oil paper's meshes are 4x4x2, 6x4x2 and 8x4x2
        (900, 1260 and 1620 coordinates).
    grading:
        Ratio of the front (+x) to the rear (-x) element length (1 = uniform).
    """
    fill = limits.check("fill", fill)
    return _core.cylinder_tank(length, radius, head_depth, fill, n_length, n_width, n_height, grading)


def elliptic_cylinder(
    *,
    length: float = SWRI_LENGTH,
    semi_axis_y: float = SWRI_SEMI_AXIS_Y,
    semi_axis_z: float = SWRI_SEMI_AXIS_Z,
    fill: float = 0.5,
    n_length: int = 4,
    n_width: int = 6,
    n_height: int = 3,
) -> FluidMesh:
    """Liquid in a flat-ended cylinder of elliptical section (defaults: the SwRI tank of seed 003);
    ``fill`` as in :func:`cylinder_tank`."""
    fill = limits.check("fill", fill)
    return _core.elliptic_cylinder(length, semi_axis_y, semi_axis_z, fill, n_length, n_width, n_height)
