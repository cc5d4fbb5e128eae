"""``[track]`` of vehicle scenes: a preset, or a segment table in SI or US units, as SI rows
``(s, curvature, superelevation, grade, cant_right, cant_left)``."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from railslosh.constants import ARC_DEGREE_RADIUS_FT, FOOT, INCH
from railslosh.limits import Limit, invalid
from railslosh.scene.schema import MAX_ROWS, Section, increasing

# Seed 000, Table 1: distance (ft), degree of curvature, super-elevation (in), grade (%), rail cant
# right / left (rad).
TABLE1_US = [
    [0.0, 0.0, 0.0, 0.0, 0.025, -0.025],
    [100.0, 0.0, 0.0, 0.0, 0.025, -0.025],
    [300.0, 3.0, 3.0, 0.0, 0.025, -0.025],
    [600.0, 3.0, 3.0, 0.0, 0.025, -0.025],
    [800.0, 0.0, 0.0, 0.0, 0.025, -0.025],
    [1000.0, 0.0, 0.0, 0.0, 0.025, -0.025],
    [1200.0, -3.0, -3.0, 0.0, 0.025, -0.025],
    [1500.0, -3.0, -3.0, 0.0, 0.025, -0.025],
    [1700.0, 0.0, 0.0, 0.0, 0.025, -0.025],
    [2800.0, 0.0, 0.0, 0.0, 0.025, -0.025],
]

_CANT = Limit(-0.1, 0.1, "rad", "a cant angle")
SI_COLUMNS: tuple[tuple[str, Limit], ...] = (
    ("s", Limit(-1e6, 1e6, "m", "a distance")),
    ("curvature", Limit(-0.02, 0.02, "1/m", "a curvature (radius ≥ 50 m)")),
    ("superelevation", Limit(-0.2, 0.2, "m", "a superelevation")),
    ("grade", Limit(-0.05, 0.05, "", "a grade (rise over run)")),
    ("cant_right", _CANT),
    ("cant_left", _CANT),
)
"""The columns of ``[track] rows`` and their limits."""
US_COLUMNS: tuple[tuple[str, Limit], ...] = (
    ("distance_ft", Limit(-3e6, 3e6, "ft", "a distance")),
    ("degree_of_curvature", Limit(-30.0, 30.0, "degrees", "a degree of curvature")),
    ("superelevation_in", Limit(-8.0, 8.0, "in", "a superelevation")),
    ("grade_percent", Limit(-5.0, 5.0, "%", "a grade")),
    ("cant_right", _CANT),
    ("cant_left", _CANT),
)
"""The columns of ``[track] us_rows`` and their limits."""


def rows(value: Any, field: str, columns: tuple[tuple[str, Limit], ...]) -> list[list[float]]:
    """A table of 2 to :data:`MAX_ROWS` rows of 3 to 6 numbers, increasing in the first column;
    missing trailing columns are 0."""
    names = ", ".join(c[0] for c in columns)
    if not isinstance(value, list | tuple) or not 2 <= len(value) <= MAX_ROWS:
        raise invalid(field, value, f"a list of 2 to {MAX_ROWS} rows [{names}]")
    out = []
    for i, row in enumerate(value):
        if not isinstance(row, list | tuple) or not 3 <= len(row) <= 6:
            raise invalid(f"{field}[{i}]", row, f"a row of 3 to 6 numbers [{names}]")
        r = [columns[j][1].check(x, f"{field}[{i}][{j}] ({columns[j][0]})") for j, x in enumerate(row)]
        out.append(r + [0.0] * (6 - len(r)))
    increasing([r[0] for r in out], lambda i: f"{field}[{i}][0] ({columns[0][0]})")
    return out


def us_to_si(us_rows: list[list[float]]) -> list[list[float]]:
    """US-unit rows (ft, degrees of curvature, in, %) in SI units (the units of
    :mod:`railslosh.constants`, as ``railslosh.rail.Track(..., units="us")``)."""
    return [
        [d * FOOT, deg / (ARC_DEGREE_RADIUS_FT * FOOT), e * INCH, g / 100.0, cr, cl] for d, deg, e, g, cr, cl in us_rows
    ]


def track(doc: Mapping[str, Any]) -> tuple[list[list[float]], str]:
    """The SI rows of ``[track]`` and where they came from (``"preset:table1"``, ``"preset:tangent"``,
    ``"rows"`` or ``"us_rows"``)."""
    sec = Section("vehicle", "track", doc)
    given = [k for k in ("preset", "rows", "us_rows") if k in sec]
    if len(given) != 1:
        raise invalid("track", sorted(sec.values), "exactly one of `track.preset`, `track.rows`, `track.us_rows`")
    kind = given[0]
    preset = sec.get("preset") if kind == "preset" else None
    if preset != "tangent":
        sec.only_with(["length"], 'with preset = "tangent"')
    if preset == "table1":
        return us_to_si(TABLE1_US), "preset:table1"
    if preset == "tangent":
        length = sec.get("length")
        return [[0.0] * 6, [length, 0.0, 0.0, 0.0, 0.0, 0.0]], "preset:tangent"
    if kind == "rows":
        return rows(sec.values["rows"], "track.rows", SI_COLUMNS), "rows"
    return us_to_si(rows(sec.values["us_rows"], "track.us_rows", US_COLUMNS)), "us_rows"
