"""Track geometry, wheel and rail profiles, and the contact of one wheel on its rail.

    >>> from railslosh import rail
    >>> track = rail.Track.from_us([0, 300, 1300, 1600], [0, 3, 3, 0], [0, 3, 3, 0])  # ft, degrees, inches
    >>> v = track.balance_speed(800 * 0.3048)  # m/s, sqrt(g R h / B) on the 3-degree curve
    >>> wheel, head = rail.Profile.s1002(), rail.Profile.uic60()
    >>> res = rail.contact(wheel, head, rail_cant=1 / 40, lateral_shift=0.003, load=50e3, speed=20.0)
    >>> res["normal_force"], res["y_track"]  # one entry per contact point

Units are SI (m, rad, N, s) unless a name says otherwise (``distance_ft``, ``superelevation_in``).
Conventions (``docs/frames.md`` and the Rust docs of ``rail_mbs::track`` / ``rail_mbs::profile``):

* track frame: x along increasing ``s``, y to the **left**, z up; curvature is positive for a curve
  to the left, super-elevation positive when the right rail is raised, grade is rise over run;
  rail cant follows Table 1 of the tank-car paper (right rail +0.025 rad, left rail -0.025 rad =
  both inclined inward);
* profiles are curves ``z(y)`` in m, ``y`` towards the field side for wheels and rails alike, ``z``
  up; a wheel profile gives the height above the nominal rolling circle (local radius
  ``r0 - z(y)``), flange at negative ``y``.

Bad input raises ``ValueError`` naming the field and its allowed range; failed computations raise
``railslosh.RailsloshError``.
"""

from __future__ import annotations

from collections.abc import Sequence
from os import PathLike
from typing import Any

import numpy as np
import numpy.typing as npt

from railslosh import _core
from railslosh.constants import GRAVITY

STANDARD_GAUGE = 1.435
"""Standard gauge, m."""
DEFAULT_CANT_BASE = 1.5
"""Default base over which super-elevation is measured, m."""

FloatArray = npt.NDArray[np.float64]
ArrayLike = float | Sequence[float] | npt.NDArray[Any]

_SI_FIELDS = ("s", "curvature", "superelevation", "grade", "cant_right", "cant_left")
_US_FIELDS = ("distance_ft", "degree_of_curvature", "superelevation_in", "grade_percent", "cant_right", "cant_left")


def _floats(x: ArrayLike, field: str) -> FloatArray:
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"invalid `{field}` = {x!r}: expected numbers") from exc
    return a


def _column(x: ArrayLike, n: int | None, field: str) -> FloatArray:
    a = _floats(x, field)
    if a.ndim == 0 and n is not None:
        a = np.full(n, float(a))
    if a.ndim != 1:
        raise ValueError(f"invalid `{field}`: expected a number or a 1-D sequence, got shape {a.shape}")
    return np.ascontiguousarray(a)


def _query(s: ArrayLike, field: str = "s") -> tuple[FloatArray, bool]:
    a = _floats(s, field)
    if a.ndim > 1:
        raise ValueError(f"invalid `{field}`: expected a number or a 1-D sequence, got shape {a.shape}")
    return np.ascontiguousarray(np.atleast_1d(a)), a.ndim == 0


def _scalar_or(a: FloatArray, scalar: bool) -> Any:
    return a[0] if scalar else a


class Track:
    """Track geometry from a segment table (curvature, super-elevation, grade and rail cant vary
    linearly in distance between rows, so a change of curvature is a clothoid).

    Columns in SI units: ``s`` (m, strictly increasing), ``curvature`` (1/m, positive left),
    ``superelevation`` (m, positive = right rail raised, ``|e| < cant_base``), ``grade`` (fraction),
    ``cant_right`` / ``cant_left`` (rad, Table 1 convention). A number instead of a column is used for
    every row. ``units="us"`` reads the columns as feet, degrees of curvature (arc definition,
    R = 5729.58 ft / D), inches, percent and rad (see :meth:`from_us`).
    """

    def __init__(
        self,
        s: ArrayLike,
        curvature: ArrayLike,
        superelevation: ArrayLike,
        grade: ArrayLike = 0.0,
        cant_right: ArrayLike = 0.0,
        cant_left: ArrayLike = 0.0,
        *,
        units: str = "si",
        gauge: float = STANDARD_GAUGE,
        cant_base: float = DEFAULT_CANT_BASE,
        origin: tuple[float, float, float] = (0.0, 0.0, 0.0),
        heading: float = 0.0,
    ) -> None:
        names = _US_FIELDS if units == "us" else _SI_FIELDS
        first = _column(s, None, names[0])
        cols = [first] + [
            _column(c, len(first), name)
            for c, name in zip((curvature, superelevation, grade, cant_right, cant_left), names[1:], strict=True)
        ]
        self._inner = _core.Track(
            *cols,
            units=units,
            gauge=gauge,
            cant_base=cant_base,
            origin=origin,
            heading=heading,
        )

    @classmethod
    def from_us(
        cls,
        distance_ft: ArrayLike,
        degree_of_curvature: ArrayLike,
        superelevation_in: ArrayLike,
        grade_percent: ArrayLike = 0.0,
        cant_right: ArrayLike = 0.0,
        cant_left: ArrayLike = 0.0,
        **options: Any,
    ) -> Track:
        """Track from a table in US units: distance (ft), degree of curvature (arc definition, sign =
        direction, positive left), super-elevation (in), grade (%) and rail cant (rad)."""
        return cls(
            distance_ft,
            degree_of_curvature,
            superelevation_in,
            grade_percent,
            cant_right,
            cant_left,
            units="us",
            **options,
        )

    @classmethod
    def from_table(
        cls, rows: Sequence[Sequence[float]] | npt.NDArray[Any], *, units: str = "si", **options: Any
    ) -> Track:
        """Track from rows of 3 to 6 numbers: (s, curvature, superelevation[, grade[, cant_right[,
        cant_left]]]) in the units of ``units`` ("si" or "us")."""
        a = _floats(rows, "rows")
        if a.ndim != 2 or not 3 <= a.shape[1] <= 6:
            raise ValueError(
                f"invalid `rows`: expected a table of 3 to 6 columns (s, curvature, superelevation, grade, "
                f"cant_right, cant_left), got shape {a.shape}"
            )
        return cls(*(a[:, k] for k in range(a.shape[1])), units=units, **options)

    @property
    def gauge(self) -> float:
        """Track gauge, m."""
        return self._inner.gauge

    @property
    def cant_base(self) -> float:
        """Base over which super-elevation is measured, m."""
        return self._inner.cant_base

    @property
    def range(self) -> tuple[float, float]:
        """First and last distance of the table, m."""
        return self._inner.range

    @property
    def table(self) -> FloatArray:
        """The table in SI units, shape (n, 6): s, curvature, superelevation, grade, cant_right, cant_left."""
        return self._inner.table

    @property
    def units(self) -> str:
        """Units the table was given in ("si" or "us")."""
        return self._inner.units

    def _map(self, name: str, s: ArrayLike, *args: Any) -> Any:
        q, scalar = _query(s)
        return _scalar_or(getattr(self._inner, name)(q, *args), scalar)

    def position(self, s: ArrayLike) -> FloatArray:
        """Centreline position (global, m): shape (3,) for a number, (n, 3) for n distances."""
        return self._map("position", s)

    def tangent(self, s: ArrayLike) -> FloatArray:
        """Unit tangent (direction of increasing s): (3,) or (n, 3)."""
        return self._map("tangent", s)

    def frame(self, s: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """Track frame(s): origin (3,) or (n, 3) and rotation (3, 3) or (n, 3, 3), whose columns are the
        axes x (tangent), y (left), z (up) in global coordinates (grade and super-elevation included)."""
        q, scalar = _query(s)
        origin, rotation = self._inner.frame(q)
        return (origin[0], rotation[0]) if scalar else (origin, rotation)

    def curvature(self, s: ArrayLike) -> Any:
        """Signed curvature, 1/m (positive = curve to the left)."""
        return self._map("curvature", s)

    def superelevation(self, s: ArrayLike) -> Any:
        """Signed super-elevation, m (positive = right rail raised)."""
        return self._map("superelevation", s)

    def grade(self, s: ArrayLike) -> Any:
        """Grade (fraction, positive climbing)."""
        return self._map("grade", s)

    def heading(self, s: ArrayLike) -> Any:
        """Heading of the centreline, rad (from +X towards +Y)."""
        return self._map("heading", s)

    def bank_angle(self, s: ArrayLike) -> Any:
        """Roll angle of the track frame, rad (``-asin(e / cant_base)``)."""
        return self._map("bank_angle", s)

    def balance_speed(self, s: ArrayLike) -> Any:
        """Balance (equilibrium) speed ``sqrt(g R h / cant_base)``, m/s; NaN on tangent track or where
        the super-elevation is adverse, 0 on a curve without super-elevation."""
        return self._map("balance_speed", s)

    def rail_point(self, s: ArrayLike, side: str) -> FloatArray:
        """Point(s) of the gauge line of the "left" or "right" rail (centreline +- gauge/2 along y)."""
        return self._map("rail_point", s, side)

    def rail_inward_cant(self, s: ArrayLike, side: str) -> Any:
        """Inward cant of the "left" or "right" rail, rad (positive = head tilted towards the centre)."""
        return self._map("rail_inward_cant", s, side)

    def project(self, points: ArrayLike) -> tuple[Any, Any, Any]:
        """Projects global point(s) (shape (3,) or (n, 3)) onto the centreline: (s, lateral, vertical)."""
        p = _floats(points, "points")
        scalar = p.ndim == 1
        if p.shape[-1:] != (3,) or p.ndim > 2:
            raise ValueError(f"invalid `points`: expected shape (3,) or (n, 3), got {p.shape}")
        s, lat, vert = self._inner.project(np.ascontiguousarray(p.reshape(-1)))
        return (s[0], lat[0], vert[0]) if scalar else (s, lat, vert)

    def __repr__(self) -> str:
        return repr(self._inner)


class Profile:
    """A wheel or rail profile ``z(y)`` in m (C2 cubic spline through the data); build it with one of
    the class methods."""

    def __init__(self, inner: _core.Profile) -> None:
        if not isinstance(inner, _core.Profile):
            raise TypeError(
                "use Profile.s1002(), .uic60(), .aar1b_approx(), .from_simpack(), .from_points() or .from_file()"
            )
        self._inner = inner

    @classmethod
    def s1002(cls, spacing: float = 2e-4) -> Profile:
        """S1002 wheel (EN 13715), sampled every ``spacing`` m over y in [-69.5, 60] mm."""
        return cls(_core.Profile.s1002(float(spacing)))

    @classmethod
    def uic60(cls, spacing: float = 2e-4) -> Profile:
        """UIC 60 rail head, uncanted (pass ``rail_cant=1/40`` to :func:`contact` for a canted rail)."""
        return cls(_core.Profile.uic60(float(spacing)))

    @classmethod
    def aar1b_approx(cls) -> Profile:
        """Approximate AAR-1B wide-flange wheel (NOT the licensed AAR contour; see the Rust docs)."""
        return cls(_core.Profile.aar1b_approx())

    @classmethod
    def from_simpack(cls, path: str | PathLike[str]) -> Profile:
        """SIMPACK ``.prr`` (rail) / ``.prw`` (wheel) file; converted to m and z up, with the file's
        shift and mirror flags applied."""
        return cls(_core.Profile.from_simpack(path))

    @classmethod
    def from_points(cls, y: ArrayLike, z: ArrayLike, *, name: str = "points", kind: str | None = None) -> Profile:
        """Profile through points (y, z) in m (y towards the field side, z up); sorted by y."""
        return cls(_core.Profile.from_points(_column(y, None, "y"), _column(z, None, "z"), name, kind))

    @classmethod
    def from_file(
        cls,
        path: str | PathLike[str],
        *,
        scale: float = 1.0,
        z_down: bool = False,
        mirror_y: bool = False,
        kind: str | None = None,
    ) -> Profile:
        """Two-column text file of ``y z`` pairs (whitespace, comma or semicolon separated; ``#``
        comments). ``scale`` converts the file unit to m (1e-3 for mm); ``z_down`` flips z for files
        with z downwards; ``mirror_y`` flips y."""
        return cls(_core.Profile.from_two_column(path, scale=float(scale), z_down=z_down, mirror_y=mirror_y, kind=kind))

    @property
    def name(self) -> str:
        """Profile name (standard designation or file name)."""
        return self._inner.name

    @property
    def kind(self) -> str | None:
        """ "rail", "wheel" or None when unknown."""
        return self._inner.kind

    @property
    def y_range(self) -> tuple[float, float]:
        """Lateral range of the data, m."""
        return self._inner.y_range

    @property
    def knots(self) -> FloatArray:
        """Spline knots, shape (k, 2): y, z in m."""
        return self._inner.knots

    def highest_point(self) -> tuple[float, float]:
        """Highest point (y, z) of the profile, m."""
        return self._inner.highest_point()

    def sample(self, n: int = 200) -> FloatArray:
        """``n`` evenly spaced points over the profile range, shape (n, 2): y, z in m."""
        return self._inner.sample(int(n))

    def z(self, y: ArrayLike) -> Any:
        """Height z(y), m (the spline continues linearly outside the data)."""
        q, scalar = _query(y, "y")
        return _scalar_or(self._inner.eval(q)[0], scalar)

    def slope(self, y: ArrayLike) -> Any:
        """dz/dy at y."""
        q, scalar = _query(y, "y")
        return _scalar_or(self._inner.eval(q)[1], scalar)

    def trim_steep_ends(self, max_slope: float) -> Profile:
        """Copy restricted to the longest run where the chord slope stays below ``max_slope`` (drops
        near-vertical faces that a z(y) spline cannot follow)."""
        return Profile(self._inner.trim_steep_ends(float(max_slope)))

    def __repr__(self) -> str:
        return repr(self._inner)


def _core_profile(p: Profile | _core.Profile, field: str) -> _core.Profile:
    if isinstance(p, Profile):
        return p._inner
    if isinstance(p, _core.Profile):
        return p
    raise ValueError(f"invalid `{field}` = {p!r}: expected a railslosh.rail.Profile")


def contact(
    wheel: Profile,
    rail: Profile,
    *,
    side: str = "left",
    nominal_radius: float = 0.46,
    wheel_offset: float = 0.75,
    rail_offset: float | None = None,
    gauge: float = STANDARD_GAUGE,
    gauge_depth: float = 0.014,
    rail_cant: float = 0.0,
    trim_slope: float | None = None,
    lateral_shift: float = 0.0,
    yaw: float = 0.0,
    roll: float = 0.0,
    load: float | None = None,
    penetration: float | None = None,
    speed: float = 0.0,
    lateral_velocity: float = 0.0,
    yaw_rate: float = 0.0,
    axle_rate: float | None = None,
    creepages: tuple[float, float, float] | None = None,
    creep_model: str = "shen-hedrick-elkins",
    creep_parameters: dict[str, float] | None = None,
    friction: float = 0.3,
    friction_profile: Sequence[tuple[float, float]] | None = None,
    young: float = 2.1e11,
    poisson: float = 0.3,
    scan_points: int = 400,
    patch_model: str = "hertz",
    kp_epsilon: float | None = None,
    kp_strips: int | None = None,
    patch_combination: str = "separate",
    a_sep: float | None = None,
    d_sep: float | None = None,
    d_comb: float | None = None,
) -> dict[str, Any]:
    """Contact of one wheel of a wheelset on its straight rail, at the height that carries ``load``
    (total vertical force on the wheel, N) or reaches ``penetration`` (largest contact penetration,
    m); exactly one of the two.

    Geometry: the wheel profile origin lies ``wheel_offset`` from the wheelset centre (0.75 m for S1002
    with a 1360 mm back-to-back); the rail profile origin lies ``rail_offset`` from the track
    centreline, by default such that the gauge point ``gauge_depth`` below the rail crown (found on
    the profile as given, before ``rail_cant`` and trimming) is at ``gauge / 2``. ``rail_cant`` is the
    inward inclination (1/40 for a standard UIC 60 on a 1:40 seat; 0 for pre-canted profile files).
    ``trim_slope`` drops rail profile ends steeper than that slope (e.g. 10 for the near-vertical side
    faces of a measured rail) after the gauge point is found.

    Motion: the wheelset centre is at lateral ``lateral_shift`` (m, positive left) with ``yaw`` and
    ``roll`` (rad), moving forward at ``speed`` (m/s) and spinning about the axle at ``axle_rate``
    (rad/s, default ``speed / nominal_radius`` = pure rolling). Creepages follow from these velocities,
    or are prescribed as ``creepages = (longitudinal, lateral, spin [1/m])`` (wheel relative to rail,
    contact frame) at every point. Creep law: "shen-hedrick-elkins", "polach", "linear" or "fastsim";
    ``creep_parameters``: Polach's reduction factors ``{"k_a": ..., "k_s": ...}`` (each in (0, 1],
    default 1) or FASTSIM's grid ``{"nx": ..., "ny": ...}`` (2–400 cells, default 40 × 40).
    Friction: ``friction`` everywhere, or ``friction_profile`` = ``[(v, mu), ...]``, μ over the rail
    profile's lateral coordinate ``v`` (m, the ``y_rail`` of the result; linear between, held
    outside), each contact point taking the μ of its own location (e.g.
    :func:`lubricated_gauge_face`); the result's ``friction`` gives the μ of each point.

    Patch model: ``patch_model="hertz"`` (Hertz's ellipse from the curvatures at the contact point,
    the default) or ``"kik_piotrowski"``: the non-elliptic patch of Kik & Piotrowski (2008) from the
    profiles' separation across the contact, for the gauge corner and flange where the curvature
    varies across the patch; ``kp_epsilon`` is its virtual-penetration factor (default 0.55, in
    [0.05, 1]) and ``kp_strips`` its number of strips (default 60, 4–5000). FASTSIM then runs on the
    patch's strips; the other creep laws use its equivalent ellipse (same area and length-to-width
    ratio), which ``semi_axis_a`` / ``semi_axis_b`` report.

    Patches of several points: ``patch_combination="separate"`` (the default: one patch per local
    minimum of the gap) or ``"contact"``: CONTACT's rule, under which two neighbouring points whose
    rigid interpenetration regions lie within ``d_sep`` (m, default 8 mm; facing ends) and whose
    normals differ by at most ``a_sep`` (rad, default π) form one Kik–Piotrowski patch over both
    regions, fully within ``d_comb`` (default 4 mm), blended with the separate patches between
    ``d_comb`` and ``d_sep`` (the Manchester benchmark's input is ``a_sep = π/2``). It reproduces
    CONTACT's one patch at the benchmark's centred wheelset in force, width and position but not
    its creep forces (docs/validation.md, "One patch or two").

    The wheel is lowered onto the rail from 50 mm above its nominal height, so for a shift beyond
    flange contact (about 8 mm for S1002 on UIC 60) the flange may land on the rail head (a derailed
    position) instead of pressing against the gauge face.

    Returns a dict: ``height`` (m), ``vertical_force`` and ``lateral_force`` (N, sums on the wheel),
    ``rail_offset`` (m), and one entry per loaded contact point in 1-D arrays ``y_track`` (lateral
    position of the contact point in the track frame, m, left positive), ``y_rail`` / ``y_wheel``
    (rail / wheel profile coordinates, m), ``rolling_radius``, ``contact_angle`` (rad from vertical),
    ``penetration``, ``normal_force``, ``creep_longitudinal``, ``creep_lateral`` (N, on the wheel
    along the contact axes e1 forward and e2 to the left), ``spin_moment`` (N m), ``semi_axis_a``
    (along the rolling direction), ``semi_axis_b`` (m), ``max_pressure`` (Pa), ``patch_area`` (m²),
    ``patch_width`` (lateral extent of the patch, m), arrays of shape (n, 3) ``creepages``, ``point``,
    ``reference_point`` (the pressure centroid of a Kik–Piotrowski patch; ``point`` for Hertz),
    ``normal``, ``e1``, ``e2``, ``force_on_wheel``, and ``method``.
    """
    if creepages is not None:
        c = _floats(creepages, "creepages")
        if c.shape != (3,):
            raise ValueError(f"invalid `creepages`: expected (longitudinal, lateral, spin), got shape {c.shape}")
        creepages = (float(c[0]), float(c[1]), float(c[2]))
    numbers = dict(
        nominal_radius=nominal_radius,
        wheel_offset=wheel_offset,
        gauge=gauge,
        gauge_depth=gauge_depth,
        rail_cant=rail_cant,
        lateral_shift=lateral_shift,
        yaw=yaw,
        roll=roll,
        speed=speed,
        lateral_velocity=lateral_velocity,
        yaw_rate=yaw_rate,
        friction=friction,
        young=young,
        poisson=poisson,
    )
    optional = dict(
        rail_offset=rail_offset, trim_slope=trim_slope, load=load, penetration=penetration, axle_rate=axle_rate
    )
    kwargs: dict[str, Any] = {k: _number(v, k) for k, v in numbers.items()}
    kwargs.update({k: None if v is None else _number(v, k) for k, v in optional.items()})
    table = None
    if friction_profile is not None:
        table = [(_number(v, "friction_profile"), _number(mu, "friction_profile")) for v, mu in friction_profile]
    return _core.wheel_rail_contact(
        _core_profile(wheel, "wheel"),
        _core_profile(rail, "rail"),
        side=side,
        creepages=creepages,
        creep_model=creep_model,
        creep_parameters=None if creep_parameters is None else dict(creep_parameters),
        friction_profile=table,
        scan_points=int(scan_points),
        patch_model=patch_model,
        kp_epsilon=None if kp_epsilon is None else _number(kp_epsilon, "kp_epsilon"),
        kp_strips=None if kp_strips is None else _count(kp_strips, "kp_strips"),
        patch_combination=patch_combination,
        a_sep=None if a_sep is None else _number(a_sep, "a_sep"),
        d_sep=None if d_sep is None else _number(d_sep, "d_sep"),
        d_comb=None if d_comb is None else _number(d_comb, "d_comb"),
        **kwargs,
    )


def lubricated_gauge_face(
    rail: Profile,
    *,
    mu_top: float = _core.LUBRICATED_GAUGE_FACE["mu_top"],
    mu_gauge: float = _core.LUBRICATED_GAUGE_FACE["mu_gauge"],
    depth: float = _core.LUBRICATED_GAUGE_FACE["depth"],
    width: float = _core.LUBRICATED_GAUGE_FACE["width"],
) -> list[tuple[float, float]]:
    """The ``friction_profile`` of a lubricated gauge face on ``rail`` (for :func:`contact`): ``mu_gauge``
    on the gauge side up to the point ``depth`` (m) below the rail top (2 mm: on UIC 60 about 25 mm to
    the gauge side of the top), ``mu_top`` on the rest of the head, changing linearly over ``width`` (m).
    Defaults: ``railslosh._core.LUBRICATED_GAUGE_FACE`` (``rail_mbs::wheel_rail::GaugeFaceLubrication``)."""
    return _core.lubricated_gauge_face(
        _core_profile(rail, "rail"),
        mu_top=_number(mu_top, "mu_top"),
        mu_gauge=_number(mu_gauge, "mu_gauge"),
        depth=_number(depth, "depth"),
        width=_number(width, "width"),
    )


def _number(x: Any, field: str) -> float:
    try:
        return float(x)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"invalid `{field}` = {x!r}: expected a number") from exc


def _count(x: Any, field: str) -> int:
    if isinstance(x, bool) or not isinstance(x, (int, np.integer)):
        raise ValueError(f"invalid `{field}` = {x!r}: expected a whole number")
    return int(x)


__all__ = [
    "DEFAULT_CANT_BASE",
    "GRAVITY",
    "STANDARD_GAUGE",
    "Profile",
    "Track",
    "contact",
    "lubricated_gauge_face",
]
