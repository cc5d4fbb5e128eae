"""A self-contained HTML report of a results directory (``railslosh report DIR``), rendered from the
jinja2 template ``templates/report.html.j2``: the settling phase and how it was found, a summary
table of the headline results after settling (with the standard limits and the values the
settling phase would have given), the run's invariant margins, a figure gallery (PNGs embedded as
data URIs, so the page can be mailed or archived alone), the solver statistics and the scene, all
in engineering units rounded to meaningful digits.

    >>> from railslosh import report
    >>> report.write_report("out/ecp_light")        # -> out/ecp_light/report.html
"""

from __future__ import annotations

import base64
import json
import math
import os
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["FILTERED", "HEADLINE", "num", "write_report"]

TEMPLATE = Path(__file__).with_name("templates") / "report.html.j2"
"""The jinja2 template of the report."""

HEADLINE: tuple[tuple[str, str], ...] = (
    ("coupler_force", "max"),
    ("coupler_force", "min"),
    ("fluid_force_tank", "abs"),
    ("force_tank", "abs"),
    ("moment_tank", "abs"),
    ("wheel_vertical", "max"),
    ("wheel_vertical", "min"),
    ("unloading", "max"),
    ("l_over_v", "max"),
    ("wheel_lateral", "abs"),
    ("wheelset_lateral", "abs"),
    ("slosh_displacement", "abs"),
)
"""Rows of the summary table: ``(variable, extreme)`` with extreme ``"abs"`` (largest ``|value|``),
``"max"`` or ``"min"``; one row per component for vectors."""

FILTERED: tuple[str, ...] = (
    "coupler_force",
    "fluid_force_tank",
    "force_tank",
    "moment_tank",
    "wheel_vertical",
    "wheel_lateral",
)
"""Loads whose summary row also gives the extreme through EN 14363's 20 Hz low-pass
(:func:`railslosh.indicators.low_pass`): the value a track test reports, without the penalty
liquid's and the contact's ringing above it."""

_MODE = {"abs": "", "max": ", largest", "min": ", smallest"}
# (variable, extreme) -> (index in plots.limits, the value must stay "below" / "above" it)
_LIMITS = {
    ("l_over_v", "max"): (0, "below"),
    ("unloading", "max"): (0, "below"),
    ("wheel_vertical", "min"): (1, "above"),
}


def num(v: Any, sig: int = 4, *, strip: bool = False) -> str:
    """``v`` to ``sig`` significant digits (whole digits are kept), thin-space thousands; ``—``
    for missing or non-finite values; scientific notation below 1e-3 and from 1e7. ``strip``
    drops trailing zeros (inputs such as scene parameters, whose digits are exact)."""
    try:
        x = float(v)
    except (TypeError, ValueError):
        return "—"
    if not math.isfinite(x):
        return "—"
    if x == 0:
        return "0"
    mag = math.floor(math.log10(abs(x)))
    if mag < -3 or mag >= 7:
        text = f"{x:.{sig - 1}e}"
        if strip:
            mant, exp = text.split("e")
            text = f"{mant.rstrip('0').rstrip('.')}e{exp}"
        return text
    text = f"{x:,.{max(0, sig - 1 - mag)}f}"
    if strip and "." in text:
        text = text.rstrip("0").rstrip(".")
    return text.replace(",", "\u2009")


def _where(p: Any, per_car: int) -> str:
    w = p.where
    if "wheelset" in w:
        ws = int(w["wheelset"])
        car = f"car {(ws - 1) // per_car + 1}, " if per_car else ""
        return f"{car}wheelset {ws}" + (f", {w['side']}" if "side" in w else "")
    if "coupler" in w:
        k = int(w["coupler"])
        return f"coupler {k} (cars {k}–{k + 1})"
    return ", ".join(f"{d} {v}" for d, v in w.items())


def _quantity(name: str, comp: str | None, mode: str) -> str:
    from railslosh import plots

    text = plots.label(name) + (" (tension +)" if name == "coupler_force" else "")
    if comp is not None:
        words = plots._ROTATIONS if plots.LABELS.get(name, ("", "", ""))[2] == "moment" else plots._AXES
        text += f", {words.get(comp, comp).lower()} ({comp})"
    return text + _MODE[mode]


def _summary(ds: Any, ts: float) -> list[dict[str, Any]]:
    from railslosh import indicators, plots, results

    per_car = ds.sizes["wheelset"] // plots._cars(ds) if "wheelset" in ds.sizes else 0
    rows = []
    for name, mode in HEADLINE:
        if name not in ds.data_vars or "time" not in ds[name].dims or not ds[name].size:
            continue
        unit, f = plots.display_unit(name, ds[name].values, ds[name].attrs.get("units", ""))
        for comp, da in results._split(ds[name]):
            p = results.extreme(da, mode=mode, after=ts)
            if p is None:
                continue
            before = (
                results.extreme(da.isel(time=np.flatnonzero(da["time"].values < ts)), mode=mode) if ts > 0 else None
            )
            limit, limit_class = "", ""
            if (name, mode) in _LIMITS:
                idx, side = _LIMITS[name, mode]
                lims = plots.limits(ds, name)
                if idx < len(lims):
                    value, text, _ = lims[idx]
                    ok = p.value <= value if side == "below" else p.value >= value
                    # "limit 0.8 (UIC 518, EN 14363)" -> "UIC 518, EN 14363"; wheel loads: "ΔQ/Q₀ = 0.6; UIC ..."
                    if name == "wheel_vertical":
                        source = text.replace(" (", "; ", 1).removesuffix(")")
                    else:
                        source = text[text.find("(") + 1 : text.rfind(")")]
                    bound = (
                        f"{'≤' if side == 'below' else '≥'} {num(value * f, 3, strip=True)}{f' {unit}' if unit else ''}"
                    )
                    limit = f"{bound} ({source})"
                    limit_class = "ok" if ok else "bad"
            lp = results.extreme(da, mode=mode, after=ts, cutoff=indicators.LOAD_CUTOFF) if name in FILTERED else None
            rows.append(
                {
                    "name": name,
                    "component": comp or "",
                    "mode": mode,
                    "si": repr(p.value),
                    "quantity": _quantity(name, comp, mode),
                    "where": _where(p, per_car) or "tank",
                    "value": num(p.value * f),
                    "unit": unit,
                    "time": num(p.time, 4),
                    "limit": limit,
                    "limit_class": limit_class,
                    "settling": "—" if before is None else f"{num(before.value * f)} at {num(before.time, 3)} s",
                    "low_pass": "" if lp is None else f"{num(lp.value * f)} at {num(lp.time, 3)} s",
                }
            )
    return rows


def _statistics(ds: Any) -> list[dict[str, Any]]:
    from railslosh import plots, results

    rows = []
    for s in results.statistics(ds):
        unit, f = plots.display_unit(s.name, ds[s.name].values, s.units)
        quantity = _quantity(s.name, s.component, "abs")
        rows.append(
            {
                "quantity": quantity,
                "min": num(s.min * f),
                "max": num(s.max * f),
                "mean": num(s.mean * f),
                "unit": unit,
                "variable": s.name + (f"[{s.component}]" if s.component else ""),
            }
        )
    return rows


# Defaults of rail_mbs::invariants (MIN_VOLUME_RATIO, ENERGY_GROWTH_LIMIT); runs use these.
_MIN_VOLUME_RATIO = 0.1
_ENERGY_GROWTH_LIMIT = 0.05


def _margins(a: dict[str, Any]) -> list[dict[str, str]]:
    rows = []

    def row(what: str, value: str, time: Any, limit: str, ok: bool | None, share: str = "") -> None:
        status = "" if ok is None else ("ok" if ok else "exceeded") + share
        cls = "" if ok is None else ("ok" if ok else "bad")
        rows.append(
            {"what": what, "value": value, "time": num(time, 4), "limit": limit, "status": status, "status_class": cls}
        )

    if "margin_worst_gap" in a:
        gap, lim = float(a["margin_worst_gap"]), float(a.get("margin_gap_limit", math.nan))
        share = f" ({num(100 * gap / lim, 2, strip=True)} % of the limit)" if lim > 0 else ""
        row(
            "Containment: largest gap of the liquid beyond a wall",
            f"{num(gap * 1e3, 3)} mm",
            a.get("margin_worst_gap_time"),
            f"{num(lim * 1e3, 3)} mm (half the smallest element edge)",
            gap <= lim if math.isfinite(lim) else None,
            share,
        )
    if "margin_min_volume_ratio" in a:
        j = float(a["margin_min_volume_ratio"])
        lim_text = f"> {_MIN_VOLUME_RATIO:g} (distorted below, inverted at 0)"
        row(
            "Element validity: smallest volume ratio J = det F",
            num(j, 4),
            a.get("margin_min_volume_ratio_time"),
            lim_text,
            j > _MIN_VOLUME_RATIO,
        )
    if "margin_worst_energy_error" in a:
        eps = float(a["margin_worst_energy_error"])
        lim_text = f"≤ {_ENERGY_GROWTH_LIMIT:g} (≤ 0 when physical)"
        row(
            "Energy balance: largest energy growth ε",
            num(eps, 2),
            a.get("margin_worst_energy_time"),
            lim_text,
            eps <= _ENERGY_GROWTH_LIMIT,
        )
    if "mirror_limit" in a:  # liquid on mirror-symmetric inputs (railslosh.scene.run.mirror_symmetry)
        from railslosh.scene.run import MIRROR_LOAD_LIMIT

        since = a.get("mirror_lateral_valid_until")
        row(
            "Mirror symmetry: largest lateral liquid load (0 in an exact solution)",
            f"{num(float(a.get('mirror_worst_lateral_load', math.nan)), 3)} N",
            a.get("mirror_worst_time"),
            f"≤ {num(float(a['mirror_limit']), 3)} N ({MIRROR_LOAD_LIMIT:g} of the liquid's weight)",
            since is None,
            "" if since is None else f": lateral channels are discretization error after {num(float(since), 4)} s",
        )
    if "margin_dissipated" in a:
        e = float(a["margin_dissipated"])
        value = f"{num(e / 1e3, 4)} kJ" if abs(e) >= 1e4 else f"{num(e, 4)} J"
        row("Energy dissipated by the liquid (damping, viscosity)", value, None, "—", None)
    return rows


_STATS = {
    "steps": "time steps",
    "rejected_steps": "rejected steps",
    "newton_iterations": "Newton iterations",
    "factorizations": "LU factorizations",
    "jacobian_evaluations": "Jacobian evaluations",
    "wall_time": "solver wall time (s)",
    "time_total": "solver wall time (s)",
    "time_assembly": "  of which assembly (s)",
    "time_factorization": "  of which factorization (s)",
    "time_solve": "  of which linear solves (s)",
}


def _solver(ds: Any) -> list[tuple[str, str]]:
    a = ds.attrs
    t = np.asarray(ds["time"].values, dtype=float)
    rows = [("simulated time (s)", num(t[-1] if t.size else 0.0, 4)), ("recorded samples", str(t.size))]
    for k, v in a.items():
        if k.startswith("stats_"):
            key = k[6:]
            rows.append((_STATS.get(key, key.replace("_", " ")), num(v, 3) if "time" in key else str(v)))
    if "stats_newton_iterations" in a and a.get("stats_steps"):
        rows.append(
            ("Newton iterations per step", num(float(a["stats_newton_iterations"]) / float(a["stats_steps"]), 3))
        )
    if "dof" in a:
        rows.append(("degrees of freedom", str(a["dof"])))
    if "elements" in a:
        rows.append(("fluid elements per tank", str(a["elements"])))
    if "fluid_mass" in a:
        rows.append(("liquid mass per tank (t)", num(float(a["fluid_mass"]) / 1e3, 4)))
    if "static_wheel_load" in a:
        rows.append(("static wheel load Q₀ (kN)", num(float(a["static_wheel_load"]) / 1e3, 4)))
    if "wall_damping_ratio" in a:
        rows.append(("wall damping ratio", num(a["wall_damping_ratio"], 3, strip=True)))
    if "wall_adhesion" in a:
        rows.append(("wall adhesion (× ρ g H)", num(a["wall_adhesion"], 3, strip=True)))
    if "shear_stabilization" in a:
        rows.append(("shear stabilization", "on" if int(a["shear_stabilization"]) else "off"))
    for k, why, text in (
        ("fluid_model", "fluid_model_reason", "liquid model"),
        ("stepper", "stepper_reason", "stepper"),
        ("load_filter", "", "load recording"),
    ):
        if k in a:
            rows.append((text, f"{a[k]}" + (f" ({a[why]})" if why and a.get(why) else "")))
    return rows


# scene key -> (unit shown, factor from the scene's value); the scene dict is in SI units
_SCENE_UNITS: dict[str, tuple[str, float]] = {
    "speed": ("km/h", 3.6),
    "speed_kmh": ("km/h", 1.0),
    "design_v1_kmh": ("km/h", 1.0),
    "speed_mph": ("mph", 1.0),
    "station": ("m", 1.0),
    "length": ("m", 1.0),
    "offset": ("m", 1.0),
    "hold": ("m", 1.0),
    "height": ("m", 1.0),
    "height_in": ("in", 1.0),
    "wheelset_lateral_offset": ("mm", 1e3),
    "t_end": ("s", 1.0),
    "t0": ("s", 1.0),
    "settle_time": ("s", 1.0),
    "design_duration": ("s", 1.0),
    "snapshot_every": ("s", 1.0),
    "record_every": ("s", 1.0),
    "step": ("ms", 1e3),
    "times": ("s", 1.0),
    "mass": ("t", 1e-3),
    "torques": ("kN m", 1e-3),
    "fill": ("%", 100.0),
    "suspension_frequency": ("Hz", 1.0),
    "coupler_stiffness": ("MN/m", 1e-6),
    "coupler_damping": ("kN s/m", 1e-3),
}


_SCENE_NAMES = {"speed_kmh": "speed", "speed_mph": "speed", "design_v1_kmh": "design end speed", "t0": "start time"}


def _scene_value(key: str, v: Any) -> str:
    unit, f = _SCENE_UNITS.get(key, ("", 1.0))
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, int | float):
        return f"{num(v * f, strip=True)}{f' {unit}' if unit else ''}"
    if isinstance(v, list | tuple) and v and all(isinstance(x, int | float) and not isinstance(x, bool) for x in v):
        if key == "counts":
            return " × ".join(str(x) for x in v)
        return ", ".join(num(x * f, strip=True) for x in v) + (f" {unit}" if unit else "")
    if isinstance(v, dict):
        return "; ".join(f"{k} = {_scene_value(k, x)}" for k, x in v.items())
    return str(v)


def _track(rows: list[list[float]]) -> dict[str, Any]:
    """The track table in words: curve radius and side, superelevation in mm, grade in ‰, rail cant 1:n."""
    header = ["from s (m)", "curve", "superelevation (mm)", "grade (‰)", "rail cant right", "rail cant left"]
    out = []
    for r in rows:
        r = [float(x) for x in r] + [0.0] * (6 - len(r))
        k = r[1]
        curve = (
            "tangent" if abs(k) < 1e-12 else f"R = {num(1 / abs(k), 4, strip=True)} m {'left' if k > 0 else 'right'}"
        )
        cant = ["0" if abs(c) < 1e-12 else f"1:{num(1 / math.tan(abs(c)), 3, strip=True)}" for c in r[4:6]]
        out.append(
            [num(r[0], 6, strip=True), curve, num(r[2] * 1e3, 3, strip=True), num(r[3] * 1e3, 3, strip=True), *cant]
        )
    return {"header": header, "rows": out}


def _irregularity(ds: Any) -> list[tuple[str, str]]:
    """The run's track irregularity in words (:func:`railslosh.results.irregularity_spec`): where it
    came from, its grid and its RMS per channel in mm."""
    from railslosh import results

    spec = results.irregularity_spec(ds)
    if spec is None:
        return []
    kinds = {
        "fra": "US FRA track spectrum",
        "erri_low": "ERRI B176 low-level spectrum",
        "erri_high": "ERRI B176 high-level spectrum",
        "file": "measured file",
        "perfect": "perfect track with defects",
        "samples": "samples",
    }
    rows = [("kind", kinds.get(str(spec.get("kind")), str(spec.get("kind"))))]
    for key, text in (("class", "FRA class"), ("seed", "seed"), ("file", "file"), ("units", "file units")):
        if key in spec:
            rows.append((text, str(spec[key])))
    if "sha256" in spec:
        rows.append(("file SHA-256", str(spec["sha256"])[:16] + "…"))
    if "wavelengths" in spec:
        lo, hi = spec["wavelengths"]
        rows.append(("wavelengths", f"{num(lo, strip=True)}–{num(hi, strip=True)} m"))
    if "taper" in spec:
        rows.append(("taper", f"{num(spec['taper'], strip=True)} m"))
    if "first" in spec and "last" in spec:
        rows.append(("from s", f"{num(spec['first'], 6, strip=True)} to {num(spec['last'], 6, strip=True)} m"))
    if "step" in spec:
        rows.append(("sample spacing", f"{num(spec['step'], strip=True)} m"))
    if spec.get("channels"):
        rows.append(("channels", ", ".join(spec["channels"])))
    for d in spec.get("defects") or []:
        text = ", ".join(f"{k.replace('_', ' ')} {num(v, strip=True)} m" for k, v in d.items() if k != "type")
        rows.append((f"defect: {str(d.get('type', '')).replace('_', ' ')}", text))
    for c, v in (spec.get("rms") or {}).items():
        if float(v) > 0:  # channels not drawn are zero
            rows.append((f"RMS {c.replace('_', ' ')}", f"{num(float(v) * 1e3, 3)} mm"))
    for c, v in (spec.get("class_limits") or {}).items():
        if v["min"] != 0.0 or v["max"] != 0.0:
            lo, hi = v["limits"]
            rows.append(
                (
                    f"{c.replace('_', ' ')} against FRA limits",
                    f"{num(v['min'] * 1e3, 3)} to {num(v['max'] * 1e3, 3)} mm, limits {num(lo * 1e3, 3)} to "
                    f"{num(hi * 1e3, 3)} mm: {'within' if v['within'] else 'EXCEEDED'} (whole realization)",
                )
            )
    return rows


def _scene(ds: Any) -> tuple[list[tuple[str, list[tuple[str, str]]]], dict[str, Any] | None]:
    irregular = _irregularity(ds)
    try:
        d = json.loads(ds.attrs.get("scene_json", ""))
    except ValueError:
        return ([("track.irregularities", irregular)] if irregular else []), None
    if not isinstance(d, dict):
        return ([("track.irregularities", irregular)] if irregular else []), None
    sections, track = [], None
    for section, body in d.items():
        if section == "scene" or not isinstance(body, dict):
            continue
        rows = []
        for k, v in body.items():
            if section == "track" and k == "rows" and isinstance(v, list):
                track = _track(v)
                continue
            if section == "track" and k == "irregularities":
                continue  # said from the run's record below (defaults filled in, RMS)
            key = _SCENE_NAMES.get(k, k.replace("_", " "))
            rows.append((key, _scene_value(k, v)))
        if rows:
            sections.append((section, rows))
    if irregular:
        sections.append(("track.irregularities", irregular))
    return sections, track


def _figures(pngs: list[Path]) -> list[dict[str, str]]:
    from railslosh import plots

    order = {p[0]: (i, p[1]) for i, p in enumerate(plots.PLOTS)}
    pngs = sorted(pngs, key=lambda p: (order.get(p.stem, (len(order), ""))[0], p.stem))
    return [
        {
            "caption": order.get(p.stem, (0, p.stem.replace("_", " ")))[1],
            "data": base64.b64encode(p.read_bytes()).decode("ascii"),
        }
        for p in pngs
    ]


def write_report(results_dir: str | os.PathLike[str], out: str | os.PathLike[str] | None = None) -> Path:
    """Writes ``report.html`` for a directory made by ``railslosh run`` (``results.nc`` and
    ``plots/*.png``; plots are drawn first when missing). Returns the HTML path. A directory
    without ``results.nc``, or a ``results.nc`` that is not netCDF, raises :class:`ValueError`."""
    import jinja2

    from railslosh import plots, results

    d = Path(results_dir)
    nc = d / "results.nc"
    if not nc.is_file():
        raise ValueError(f"invalid `results_dir` = {str(d)!r}: expected a directory with results.nc")
    ds = results.load(nc)
    pngs = sorted((d / "plots").glob("*.png"))
    if not pngs:
        pngs = plots.plot_dataset(ds, d / "plots")
    settle = results.settling(ds)
    t = np.asarray(ds["time"].values, dtype=float)
    scene, track = _scene(ds)
    kinds = {"slosh": "slosh scene", "vehicle": "vehicle scene", "fluid_vehicle": "vehicle scene with liquid"}
    context = {
        "title": str(ds.attrs.get("title") or d.name),
        "description": str(ds.attrs.get("scene_description", "")),
        "kind": kinds.get(str(ds.attrs.get("scene_kind", "")), str(ds.attrs.get("scene_kind", "")) or "run"),
        "source": str(ds.attrs.get("source", "railslosh")),
        "history": str(ds.attrs.get("history", "")),
        "simulated": f"{num(t[-1], 4, strip=True)} s" if t.size else "nothing",
        "error": str(ds.attrs.get("error", "")),
        "settling": {
            "time": settle.time,
            "time_text": num(settle.time, 3, strip=True),
            "rule": settle.rule,
            "source": settle.source,
        },
        "after_text": f"after settling (t ≥ {num(settle.time, 3, strip=True)} s)"
        if settle.time > 0
        else "over the whole run",
        "summary": _summary(ds, settle.time),
        "statistics": _statistics(ds),
        "margins": _margins(dict(ds.attrs)),
        "figures": _figures(pngs),
        "pvd": next((p.name for p in sorted(d.glob("*.pvd"))), ""),
        "solver": _solver(ds),
        "scene": scene,
        "track": track,
    }
    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(TEMPLATE.parent),
        autoescape=True,
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
    )
    path = Path(out) if out is not None else d / "report.html"
    path.write_text(env.get_template(TEMPLATE.name).render(**context), encoding="utf-8")
    return path
