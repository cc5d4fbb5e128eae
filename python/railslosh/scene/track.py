"""``[track]`` of vehicle scenes: a preset, or a segment table in SI or US units, as SI rows
``(s, curvature, superelevation, grade, cant_right, cant_left)``; its ``[track.friction]``
(:func:`friction_table`) and its ``[track.irregularities]`` (:func:`irregularity_table`,
:func:`irregularity_spec`; :mod:`railslosh.irregularity`)."""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from railslosh import irregularity, vehicle
from railslosh.constants import ARC_DEGREE_RADIUS_FT, FOOT, INCH
from railslosh.limits import Limit, invalid, missing
from railslosh.scene.schema import IRREGULARITY_KINDS, MAX_ROWS, Section, increasing, scoped

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
    sec = Section("vehicle", "track", doc, extra=("irregularities", "friction"))
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


# --- [track.friction] ----------------------------------------------------------------------------------

FRICTION = "track.friction"


def friction_table(doc: Mapping[str, Any]) -> dict[str, Any] | None:
    """The ``[track.friction]`` table of a vehicle scene, checked: the ``friction_map`` of
    :func:`railslosh.vehicle.run` (a ``preset`` with its keys, or a ``profile`` table, and an optional
    ``along_track`` table); ``None`` without one (``car.friction`` everywhere)."""
    tr = doc.get("track")
    if not isinstance(tr, Mapping) or "friction" not in tr:
        return None
    sec = Section("vehicle", FRICTION, doc)
    if ("preset" in sec) == ("profile" in sec):
        raise invalid(FRICTION, sorted(sec.values), "exactly one of `track.friction.preset`, `track.friction.profile`")
    out: dict[str, Any] = {}
    if "preset" in sec:
        out["preset"] = sec.get("preset")
        for k in ("mu_top", "mu_gauge", "depth", "width"):
            out[k] = sec.get(k)
    else:
        sec.only_with(["mu_top", "mu_gauge", "depth", "width"], 'with preset = "lubricated_gauge_face"')
    for k, hi in (("profile", 1.0), ("along_track", 10.0)):
        if k in sec:
            out[k] = _pairs(sec.values[k], f"{FRICTION}.{k}", hi)
    return out


def _pairs(v: Any, field: str, hi: float) -> list[list[float]]:
    """A ``[[position, value], ...]`` table: finite, strictly increasing positions, values in [0, hi]."""
    if not isinstance(v, list | tuple) or not v:
        raise invalid(field, v, "a non-empty list of [position, value] pairs")
    value = Limit(0.0, hi, noun="a value")
    out: list[list[float]] = []
    for i, p in enumerate(v):
        if not isinstance(p, list | tuple) or len(p) != 2:
            raise invalid(f"{field}[{i}]", p, "a [position, value] pair of numbers")
        x = Limit(-1e9, 1e9, "m", "a position").check(p[0], f"{field}[{i}][0]")
        out.append([x, value.check(p[1], f"{field}[{i}][1]")])
    increasing([r[0] for r in out], lambda i: f"{field}[{i}][0]")
    return out


# --- [track.irregularities] ----------------------------------------------------------------------------

IRREGULARITY = "track.irregularities"
AHEAD = 10.0
"""m: the default ``start`` of an irregular section, ahead of the leading wheelset at t = 0."""
LENGTH_MARGIN = 50.0
"""m: the default ``length`` covers the run's travel and the train's length plus this, rounded up
to :data:`LENGTH_BLOCK`."""
LENGTH_BLOCK = 1000.0
"""m: the default ``length`` is a whole number of these, so that a shorter run (``--t-end``) of the
same scene runs on the same track (the generated track depends on its length: its wavelengths are
``length / k``)."""
_WAVELENGTH = Limit(1e-3, 1e4, "m", "a wavelength")
_KEYS = {
    "spectrum": ("kind", "class", "seed", "wavelengths", "taper", "start", "length", "step", "channels", "defects"),
    "file": ("kind", "file", "units", "sha256", "start", "channels", "defects"),
    "perfect": ("kind", "start", "length", "step", "defects"),
}


def _group(kind: str) -> str:
    return "spectrum" if kind in irregularity.SPECTRA else kind


def _scoped(exc: Exception) -> ValueError:
    """An error of :mod:`railslosh.irregularity` said of ``[track.irregularities]``."""
    msg = str(exc)
    for api, key in (("track_class", "class"), ("end", "length")):  # the API's names of the scene's keys
        if msg.startswith(f"invalid `{api}`"):
            msg = f"invalid `{key}`" + msg[len(f"invalid `{api}`") :]
    return scoped(ValueError(msg), IRREGULARITY)


def irregularity_table(doc: Mapping[str, Any]) -> dict[str, Any] | None:
    """The ``[track.irregularities]`` table of a vehicle scene, each key given checked and converted
    (SI units); ``None`` without one. Keys that do not go with the ``kind`` are refused."""
    tr = doc.get("track")
    if not isinstance(tr, Mapping) or "irregularities" not in tr:
        return None
    sec = Section("vehicle", IRREGULARITY, doc)
    kind = sec.get("kind")
    if kind is None:
        raise missing(f"{IRREGULARITY}.kind", "one of " + ", ".join(repr(k) for k in IRREGULARITY_KINDS))
    allowed = _KEYS[_group(kind)]
    for k, v in sec.values.items():
        if k not in allowed:
            raise invalid(f"{IRREGULARITY}.{k}", v, f"no `{k}` with kind = {kind!r} (it takes {', '.join(allowed)})")
    out: dict[str, Any] = {"kind": kind}
    if kind == "fra" and "class" not in sec:
        raise missing(f"{IRREGULARITY}.class", 'an FRA track class 1 (worst) to 6 with kind = "fra"')
    if kind in ("erri_low", "erri_high"):
        sec.only_with(["class"], 'with kind = "fra"')
    for k in ("class", "seed", "taper", "start", "length", "step", "units"):
        if k in sec:
            out[k] = sec.get(k)
    if "wavelengths" in sec:
        v = sec.values["wavelengths"]
        if not isinstance(v, list | tuple) or len(v) != 2:
            raise invalid(f"{IRREGULARITY}.wavelengths", v, "[shortest, longest] wavelength (m)")
        wl = [_WAVELENGTH.check(x, f"{IRREGULARITY}.wavelengths[{i}]") for i, x in enumerate(v)]
        if not wl[0] < wl[1]:
            raise invalid(f"{IRREGULARITY}.wavelengths", v, "[shortest, longest] with shortest < longest (m)")
        out["wavelengths"] = wl
    if "channels" in sec:
        v = sec.values["channels"]
        try:
            names = irregularity._channel_names(v)
        except ValueError as exc:
            raise _scoped(exc) from exc
        if not names:
            raise invalid(f"{IRREGULARITY}.channels", v, "at least one of " + ", ".join(irregularity.CHANNELS))
        out["channels"] = names
    for k in ("file", "sha256"):
        if k in sec:
            out[k] = sec.get(k)
    if kind == "file" and "file" not in out:
        raise missing(f"{IRREGULARITY}.file", 'the path of a track irregularity file with kind = "file"')
    if "sha256" in out and not re.fullmatch(r"[0-9a-fA-F]{64}", out["sha256"]):
        raise invalid(f"{IRREGULARITY}.sha256", out["sha256"], "64 hexadecimal digits (a SHA-256 digest)")
    if "defects" in sec:
        v = sec.values["defects"]
        if not isinstance(v, list | tuple):
            raise invalid(f"{IRREGULARITY}.defects", v, "an array of tables, each with a `type`")
        try:
            out["defects"] = [irregularity._defect(d, i) for i, d in enumerate(v)]
        except ValueError as exc:
            raise _scoped(exc) from exc
    if kind == "perfect" and not out.get("defects"):
        raise missing(f"{IRREGULARITY}.defects", 'at least one defect with kind = "perfect" (a perfect track)')
    return out


def irregularity_spec(
    table: Mapping[str, Any],
    *,
    cars: int,
    station: float,
    car: Mapping[str, float | str] | None,
    speed: float,
    t_end: float,
) -> dict[str, Any]:
    """The irregularity a checked ``[track.irregularities]`` table (:func:`irregularity_table`) gives
    for a train of ``cars`` whose front tank centre is at ``station`` at t = 0 and that runs at
    ``speed`` for ``t_end``: the spec of :func:`railslosh.irregularity.from_spec`, with the
    defaults filled in (``start`` 10 m ahead of the leading wheelset, ``length`` the travel plus
    the train plus 50 m rounded up to a whole kilometre, ...; ``file`` absolute with its ``units``
    and ``sha256``), checked to build (cheaply: the random phases are not summed) and to leave the
    track under the train perfect at t = 0."""
    p = vehicle.tank_car_parameters(dict(car) if car else None)
    lead = float(vehicle.wheelset_stations(cars, station, dict(car) if car else None)[0])
    train_length = (cars - 1) * (2.0 * p["coupler_reach"] + 1.0) + 2.0 * p["coupler_reach"]
    kind = table["kind"]
    spec: dict[str, Any] = {"kind": kind, **{k: v for k, v in table.items() if k != "kind"}}
    spec.setdefault("start", lead + AHEAD)
    need = lead + irregularity.CLEARANCE
    if kind != "file" and spec["start"] < need:
        raise invalid(
            f"{IRREGULARITY}.start",
            spec["start"],
            f"a track position ≥ {need:.6g} m: the irregular section (and its taper) must start at least "
            f"{irregularity.CLEARANCE:g} m ahead of the leading wheelset at {lead:.6g} m (at t = 0 the train stands "
            "on perfect track)",
        )
    try:
        if kind == "file":
            path = Path(spec["file"]).expanduser()
            if not path.is_file():
                what = "a directory" if path.is_dir() else "no such file"
                raise invalid(f"{IRREGULARITY}.file", spec["file"], f"a track irregularity file ({what})")
            spec["file"] = str(path.resolve())
            irr = irregularity.read(path, units=spec.get("units"))
            spec["units"] = irr.spec["units"]
            if spec.get("sha256") not in (None, irr.spec["sha256"]):
                raise invalid(
                    f"{IRREGULARITY}.sha256", spec["sha256"], f"the file's digest, which is {irr.spec['sha256']}"
                )
            spec["sha256"] = irr.spec["sha256"]
            irr = irr.placed(spec["start"])
            if spec.get("defects"):
                irr = irregularity.with_defects(spec["defects"], irr)
            if "channels" in spec:
                irr = irr.with_channels(spec["channels"])
            clear = irr.clear_until()
            if clear < need:
                shift = "" if clear == -float("inf") else f"; move `start` {need - clear:.6g} m further ahead"
                raise invalid(
                    f"{IRREGULARITY}.file",
                    spec["file"],
                    f"samples that are zero up to {need:.6g} m, {irregularity.CLEARANCE:g} m ahead of the leading "
                    f"wheelset at t = 0 (the train starts on perfect track); placed at start = {spec['start']:.6g} m "
                    + ("its first row is not zero (ramp the measured data in from zero)" if not shift else
                       f"it is irregular from {clear:.6g} m{shift}"),
                )  # fmt: skip
            return spec
        spec.setdefault("step", 0.05 if kind == "perfect" else 0.25)
        length = math.ceil((speed * t_end + train_length + LENGTH_MARGIN) / LENGTH_BLOCK) * LENGTH_BLOCK
        if kind != "perfect":
            spec.setdefault("seed", 1)
            spec.setdefault("wavelengths", [1.0, 70.0])
            spec.setdefault("taper", 20.0)
            spec.setdefault("channels", list(irregularity.CHANNELS))
            length = max(length, spec["wavelengths"][1])
        spec.setdefault("length", length)
        if kind == "perfect":
            irregularity.from_spec(spec)
        else:
            keys = ("length", "start", "step", "wavelengths", "seed", "taper")
            shape = irregularity.generate(kind, spec.get("class"), channels=[], **{k: spec[k] for k in keys})
            if spec.get("defects"):
                irregularity.with_defects(spec["defects"], shape)
    except ValueError as exc:
        if str(exc).startswith(f"invalid `{IRREGULARITY}"):
            raise
        raise _scoped(exc) from exc
    return spec
