"""PNG plots of a results Dataset (:func:`railslosh.results.to_dataset`), for an engineer's eye:
engineering units (kN, mm, km/h) chosen by magnitude, axis labels in words, one panel per car or
per component where lines would overlap, a legend entry per line (wheel loads: car, wheelset and
side), the limits a standard gives drawn in (L/V, wheel unloading), and the settling phase
(:func:`railslosh.results.settling`) shaded grey. Every figure is drawn inside the matplotlib style
:data:`STYLE` (``railslosh.mplstyle``), with the Agg canvas (no display needed).

    >>> from railslosh import plots, results
    >>> paths = plots.plot_dataset(results.load("out/results.nc"), "out/plots")
    >>> fig = plots.figure(ds, "wheel_loads")          # the matplotlib Figure, not saved
"""

from __future__ import annotations

import os
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np

# The limits of the standards and Nadal's limit live in railslosh.indicators (one definition);
# they stay importable from here.
from railslosh.indicators import (
    FLANGE_ANGLE,
    L_OVER_V_LIMIT,
    LOAD_CUTOFF,
    UNLOADING_LIMIT,
    low_pass,
    nadal_limit,
)
from railslosh.indicators import L_OVER_V_STANDARD as _L_OVER_V_SOURCE
from railslosh.indicators import UNLOADING_STANDARD as _UNLOADING_SOURCE
from railslosh.indicators import flange_angle as _flange_angle
from railslosh.indicators import wheel_profile as _profile

__all__ = [
    "FLANGE_ANGLE",
    "LABELS",
    "L_OVER_V_LIMIT",
    "PLOTS",
    "UNLOADING_LIMIT",
    "display_unit",
    "figure",
    "label",
    "limits",
    "nadal_limit",
    "peak_table",
    "plot_dataset",
]

STYLE = Path(__file__).with_name("railslosh.mplstyle")
"""The matplotlib style file of every railslosh figure (``matplotlib.style.context(STYLE)``)."""

# The one place where a variable becomes words: name -> (label, short label, quantity). The
# quantity picks the display unit (:func:`display_unit`); one name per concept, so the liquid's
# force is "Liquid force on the tank" whether a slosh or a vehicle run recorded it.
LABELS: dict[str, tuple[str, str, str]] = {
    "wheel_vertical": ("Vertical wheel load Q", "Wheel load Q", "force"),
    "wheel_lateral": ("Lateral wheel force Y", "Lateral wheel force Y", "force"),
    "l_over_v": ("Derailment quotient L/V = |Y|/Q", "L/V", "ratio"),
    "unloading": ("Wheel unloading ΔQ/Q₀", "ΔQ/Q₀", "ratio"),
    "wheelset_lateral": ("Wheelset lateral displacement", "Lateral displacement", "length"),
    "coupler_force": ("Coupler force", "Coupler force", "force"),
    "tank_station": ("Tank position along the track", "Position", "distance"),
    "tank_speed": ("Speed", "Speed", "speed"),
    "oil_com_tank": ("Liquid centre of mass", "position", "length"),
    "oil_com_global": ("Liquid centre of mass", "position", "distance"),
    "fluid_force_tank": ("Liquid force on the tank", "force", "force"),
    "volume_error": ("Liquid volume change", "Volume change", "percent"),
    "slosh_displacement": ("Slosh mass displacement", "Displacement", "length"),
    "force_tank": ("Liquid force on the tank", "force", "force"),
    "moment_tank": ("Liquid moment on the tank", "moment", "moment"),
    "force_global": ("Liquid force on the tank", "force", "force"),
    "moment_global": ("Liquid moment on the tank", "moment", "moment"),
    "com_tank": ("Liquid centre of mass", "position", "length"),
    "volume": ("Liquid volume", "Volume", "volume"),
    "kinetic_energy": ("Kinetic energy of the liquid", "Kinetic energy", "energy"),
    "potential_energy": ("Potential energy of the liquid", "Potential energy", "energy"),
    "newton_iterations": ("Newton iterations per step", "Iterations", "count"),
    "max_penetration": ("Largest wall penetration", "Penetration", "length"),
    "stored_energy": ("Stored elastic energy of the liquid", "Stored energy", "energy"),
    "input_work": ("Work put into the liquid", "Input work", "energy"),
    "energy_error": ("Energy growth ε (≤ 0 physical)", "ε", "ratio"),
    "min_volume_ratio": ("Smallest volume ratio J", "J", "ratio"),
    "containment_gap": ("Largest gap beyond a wall", "Gap", "length"),
    "irregularity_vertical": ("Vertical profile (mean rail height, up +)", "Vertical profile", "length"),
    "irregularity_alignment": ("Alignment (mean rail position, left +)", "Alignment", "length"),
    "irregularity_cross_level": ("Cross-level (right minus left rail)", "Cross-level", "length"),
    "irregularity_gauge": ("Gauge widening", "Gauge widening", "length"),
}

# quantity -> ((unit, factor from SI, used from this |SI value| up), ...), smallest first
_UNITS: dict[str, tuple[tuple[str, float, float], ...]] = {
    "force": (("N", 1.0, 0.0), ("kN", 1e-3, 1e3)),
    "moment": (("N m", 1.0, 0.0), ("kN m", 1e-3, 1e3)),
    "energy": (("J", 1.0, 0.0), ("kJ", 1e-3, 1e4), ("MJ", 1e-6, 1e7)),
    "length": (("mm", 1e3, 0.0), ("m", 1.0, 1.0)),
    "distance": (("m", 1.0, 0.0), ("km", 1e-3, 1e4)),
    "speed": (("km/h", 3.6, 0.0),),
    "ratio": (("", 1.0, 0.0),),
    "percent": (("%", 100.0, 0.0),),
    "volume": (("L", 1e3, 0.0), ("m³", 1.0, 1.0)),
    "count": (("", 1.0, 0.0),),
}

# quantity -> smallest y range drawn (SI): below it a series is round-off about a constant and is
# drawn flat (a wheelset on straight track moves by nanometres, not by "1e-6 mm" of full scale)
_RESOLUTION = {
    "force": 1.0,
    "moment": 0.1,
    "energy": 1e-3,
    "length": 1e-4,
    "distance": 1e-2,
    "speed": 1e-3,
    "ratio": 1e-3,
    "percent": 1e-5,
    "volume": 1e-6,
    "count": 1.0,
}

# liquid loads drawn also through EN 14363's 20 Hz low-pass (indicators.low_pass) when recorded
# finely enough to carry content above it: the raw line faint, the filtered line over it
_LOW_PASSED = frozenset(("force_tank", "moment_tank", "fluid_force_tank"))

_AXES = {"x": "Longitudinal", "y": "Lateral", "z": "Vertical"}
_ROTATIONS = {"x": "Roll", "y": "Pitch", "z": "Yaw"}


def label(name: str) -> str:
    """The variable in words (:data:`LABELS`), or its ``long_name``-free name when unknown."""
    return LABELS.get(name, (name.replace("_", " ").capitalize(), "", ""))[0]


def display_unit(name: str, values: Any = None, units: str = "") -> tuple[str, float]:
    """``(unit, factor)`` to show variable ``name`` in (SI value × factor): kN for forces from
    1 kN, mm for lengths below 1 m, km/h for speeds, ... (:data:`LABELS` quantity), by the
    largest finite ``|values|``. Unknown variables keep their SI ``units``."""
    quantity = LABELS.get(name, ("", "", ""))[2]
    if quantity not in _UNITS:
        return units, 1.0
    v = np.abs(np.asarray(values if values is not None else [0.0], dtype=float))
    big = float(np.nanmax(v)) if np.isfinite(v).any() else 0.0
    chosen = _UNITS[quantity][0]
    for entry in _UNITS[quantity]:
        if big >= entry[2]:
            chosen = entry
    return chosen[0], chosen[1]


def _with_unit(text: str, unit: str) -> str:
    return f"{text} ({unit})" if unit else text


def limits(ds: Any, name: str) -> list[tuple[float, str, str]]:
    """``(value in SI units, legend label, line style)`` of the standard limits of variable
    ``name``: L/V (UIC 518 / EN 14363 and Nadal for the run's wheel profile), wheel unloading
    (UIC 530-2 / EN 14363) and, for wheel loads, the load at that unloading and the static load.
    Dataset attributes ``l_over_v_limit`` and ``unloading_limit`` replace the defaults."""
    unloading = float(ds.attrs.get("unloading_limit", UNLOADING_LIMIT))
    if name == "l_over_v":
        lv = float(ds.attrs.get("l_over_v_limit", L_OVER_V_LIMIT))
        prof = _profile(ds)
        angle = _flange_angle(ds)
        return [
            (lv, f"limit {lv:g} ({_L_OVER_V_SOURCE})", "--"),
            (nadal_limit(angle), f"Nadal {nadal_limit(angle):.2f} ({prof}, δ = {angle:g}°, μ = 0.5)", ":"),
        ]
    if name == "unloading":
        return [(unloading, f"limit {unloading:g} ({_UNLOADING_SOURCE})", "--")]
    q0 = ds.attrs.get("static_wheel_load")
    if name == "wheel_vertical" and q0 is not None:
        q0 = float(q0)
        return [
            (q0, "static load Q₀", ":"),
            ((1 - unloading) * q0, f"ΔQ/Q₀ = {unloading:g} ({_UNLOADING_SOURCE})", "--"),
        ]
    return []


_IRREGULARITY = tuple(f"irregularity_{c}" for c in ("vertical", "alignment", "cross_level", "gauge"))

# (file stem, title, variables, panels): "one" panel, one per "component", per "car" or per "variable"
# against time; the track irregularity's channels against "distance", and their "psd" (log-log)
PLOTS: tuple[tuple[str, str, tuple[str, ...], str], ...] = (
    ("coupler_force", "Coupler forces (tension positive)", ("coupler_force",), "one"),
    ("fluid_force", "Force of the liquid on each tank (tank frame)", ("fluid_force_tank",), "component"),
    ("oil_com", "Liquid centre of mass (tank frame)", ("oil_com_tank",), "component"),
    ("wheel_loads", "Vertical wheel loads Q", ("wheel_vertical",), "car"),
    ("wheel_unloading", "Wheel unloading ΔQ/Q₀ = (Q₀ − Q)/Q₀", ("unloading",), "car"),
    ("l_over_v", "Derailment quotient L/V = |Y|/Q", ("l_over_v",), "car"),
    ("wheelset_lateral", "Wheelset lateral displacement from the track centreline", ("wheelset_lateral",), "car"),
    ("speed", "Speed", ("tank_speed",), "one"),
    ("slosh_force", "Force of the liquid on the tank (tank frame)", ("force_tank",), "component"),
    ("slosh_moment", "Moment of the liquid on the tank about its centre (tank frame)", ("moment_tank",), "component"),
    ("slosh_com", "Liquid centre of mass (tank frame)", ("com_tank",), "component"),
    ("energy", "Energies of the liquid", ("kinetic_energy", "potential_energy"), "variable"),
    ("irregularity", "Track irregularity along the track", _IRREGULARITY, "distance"),
    ("irregularity_psd", "Track irregularity spectra (one-sided PSD) against the target", _IRREGULARITY, "psd"),
)


def _cars(ds: Any) -> int:
    if "car" in ds.sizes:
        return int(ds.sizes["car"])
    n = int(ds.sizes.get("wheelset", 0))
    return n // 4 if n >= 4 and n % 4 == 0 else 1


def _series(da: Any, per_car: int) -> Iterator[tuple[str, Any, dict[str, Any]]]:
    """``(legend label, 1-D series, line style)`` of every line of ``da`` (dims time + others)."""
    from matplotlib.colors import to_hex

    other = [d for d in da.dims if d != "time"]
    if not other:
        yield label(str(da.name)), da, {}
        return
    stacked = da.stack(series=other)
    for k in range(stacked.sizes["series"]):
        s = stacked.isel(series=k)
        c = {d: s[d].values.item() for d in other}
        style: dict[str, Any] = {}
        if "wheelset" in c:
            ws = int(c["wheelset"])
            car = (ws - 1) // per_car + 1 if per_car else 1
            text = f"car {car}, wheelset {ws}"
            # resolved now, inside the style context: "CN" would be looked up again when saved
            style["color"] = to_hex(f"C{(ws - 1) % per_car if per_car else 0}")
            if "side" in c:
                text += f", {c['side']}"
                style["ls"] = "-" if c["side"] == "left" else "--"
        elif "car" in c and len(c) == 1:
            text = f"car {c['car']}"
            style["ls"] = ("-", "--", "-.", ":")[(int(c["car"]) - 1) % 4]  # identical cars stay visible
        elif "coupler" in c:
            text = f"coupler {c['coupler']} (cars {c['coupler']}–{int(c['coupler']) + 1})"
        else:
            text = ", ".join(f"{d} {v}" for d, v in c.items())
        yield text, s, style


def _panels(ds: Any, spec: tuple[str, str, tuple[str, ...], str]) -> list[tuple[str, Any]]:
    """``(y label, DataArray)`` of each panel; the DataArrays are in SI units."""
    _, _, names, kind = spec
    present = [n for n in names if n in ds.data_vars and ds[n].size]
    if kind == "variable":
        return [(LABELS.get(n, (n, n, ""))[1], ds[n]) for n in present]
    da = ds[present[0]]
    name = present[0]
    long, short, _ = LABELS.get(name, (name, name, ""))
    if kind == "component" and "component" in da.dims:
        words = _ROTATIONS if LABELS.get(name, ("", "", ""))[2] == "moment" else _AXES
        return [(f"{words.get(str(c), str(c))} {short}", da.sel(component=c)) for c in da["component"].values]
    if kind == "car" and "wheelset" in da.dims and da.sizes["wheelset"] % _cars(ds) == 0:
        per = da.sizes["wheelset"] // _cars(ds)
        return [(short, da.isel(wheelset=slice(k * per, (k + 1) * per))) for k in range(_cars(ds))]
    return [(long, da)]


def _shade_settling(ax: Any, ts: float, first: bool) -> None:
    if ts <= 0:
        return
    ax.axvspan(0.0, ts, color="0.88", zorder=0, lw=0)
    if first:
        ax.annotate(
            f"settling\n(t < {ts:.3g} s)",
            (ts, 1.0),
            xycoords=("data", "axes fraction"),
            xytext=(3, -3),
            textcoords="offset points",
            va="top",
            fontsize=7,
            color="0.35",
            bbox={"fc": "white", "ec": "none", "alpha": 0.75, "pad": 1.0},
        )


_MIRROR_ZERO = frozenset(("fluid_force_tank", "oil_com_tank", "force_tank", "com_tank"))
"""Variables whose lateral component a mirror-symmetric run (vehicle or slosh) keeps at zero
(:func:`railslosh.scene.run.mirror_symmetry`)."""


def _shade_mirror(ax: Any, since: Any, t_end: float) -> None:
    """Hatches a lateral panel from the time ``since`` (the results' ``mirror_lateral_valid_until``;
    ``None``: nothing) on which a mirror-symmetric run's lateral values, zero in an exact solution,
    exceed :data:`railslosh.scene.run.MIRROR_LOAD_LIMIT` of the liquid's weight."""
    if since is None or not np.isfinite(float(since)) or float(since) >= t_end:
        return
    since = float(since)
    ax.axvspan(since, t_end, facecolor="none", edgecolor="C3", hatch="///", lw=0, alpha=0.35, zorder=0)
    ax.annotate(
        f"mirror-symmetric run: lateral values after {since:.3g} s\nare discretization error (should be 0)",
        (since, 0.02),
        xycoords=("data", "axes fraction"),
        xytext=(3, 2),
        textcoords="offset points",
        fontsize=7,
        color="C3",
        bbox={"fc": "white", "ec": "none", "alpha": 0.75, "pad": 1.0},
    )


def _focus(ax: Any, t: np.ndarray, ys: Sequence[np.ndarray], ts: float, refs: Sequence[float], unit: str) -> None:
    """Y range from the data after settling and the reference lines; settling-phase values
    beyond it are clipped, and the clip is said in the panel."""
    after = t >= ts
    if ts <= 0 or after.sum() < 2:
        return
    post = np.concatenate([y[after] for y in ys])
    pre = np.concatenate([y[~after] for y in ys])
    post, pre = post[np.isfinite(post)], pre[np.isfinite(pre)]
    if post.size == 0 or pre.size == 0:
        return
    lo, hi = min([post.min(), *refs]), max([post.max(), *refs])
    pad = 0.08 * (hi - lo) if hi > lo else max(abs(hi), 1e-12) * 0.05
    if pre.min() >= lo - pad and pre.max() <= hi + pad:
        return
    ax.set_ylim(lo - pad, hi + pad)
    ax.annotate(
        f"settling phase clipped: {pre.min():.4g} to {pre.max():.4g}{f' {unit}' if unit else ''}",
        (0.0, 0.02),
        xycoords="axes fraction",
        xytext=(3, 0),
        textcoords="offset points",
        fontsize=7,
        color="0.35",
    )


def _min_span(ax: Any, span: float) -> None:
    """At least ``span`` of y range, so round-off noise of a series that stays near a constant
    (the lateral load in straight braking) is drawn flat, not as a signal."""
    lo, hi = ax.get_ylim()
    if span > 0 and hi - lo < span:
        mid = 0.5 * (lo + hi)
        ax.set_ylim(mid - 0.5 * span, mid + 0.5 * span)


def _draw(fig: Any, ds: Any, spec: tuple[str, str, tuple[str, ...], str]) -> None:
    from railslosh import results

    stem, title, names, kind = spec
    panels = _panels(ds, spec)
    ts = results.settling(ds).time
    t = np.asarray(ds["time"].values, dtype=float)
    values = np.concatenate([np.ravel(ds[n].values) for n in names if n in ds.data_vars])
    per_car = ds.sizes.get("wheelset", 0) // _cars(ds) if "wheelset" in ds.sizes else 0
    axes = fig.subplots(len(panels), 1, sharex=True, squeeze=False)[:, 0]
    for k, (ax, (ylabel, da)) in enumerate(zip(axes, panels, strict=True)):
        name = str(da.name)
        unit, f = display_unit(name, da.values if kind == "variable" else values, da.attrs.get("units", ""))
        ys = []
        finite = np.isfinite(t)
        filtered = name in _LOW_PASSED and t.size > 8 and np.median(np.diff(t)) <= 0.2 / LOAD_CUTOFF * (1 + 1e-9)
        for k_line, (text, s, style) in enumerate(_series(da.transpose("time", ...), per_car)):
            y = np.asarray(s.values, dtype=float) * f
            ok = finite & np.isfinite(y)
            if filtered and ok.sum() > 8:
                style = {"color": f"C{k_line}", **style}
                ax.plot(t, y, alpha=0.3, lw=0.8, **{**style, "label": f"{text}, raw"})
                grid, yf = low_pass(t[ok], y[ok])
                ax.plot(grid, yf, **{**style, "label": f"{text}, {LOAD_CUTOFF:g} Hz low-pass (EN 14363)"})
            else:
                ax.plot(t, y, label=text, **style)
            ys.append(y)
        refs = []
        for value, text, ls in limits(ds, name):
            ax.axhline(value * f, color="k", ls=ls, lw=1.0, label=text)
            refs.append(value * f)
        _shade_settling(ax, ts, k == 0)
        if name in _MIRROR_ZERO and "component" in da.coords and str(da["component"].values) == "y":
            _shade_mirror(ax, ds.attrs.get("mirror_lateral_valid_until"), float(np.nanmax(t, initial=0.0)))
        _focus(ax, t, ys, ts, refs, unit)
        floor = max(
            0.02 * float(np.nanmax(np.abs(values), initial=0.0)),
            _RESOLUTION.get(LABELS.get(name, ("", "", ""))[2], 0.0),
        )
        _min_span(ax, floor * f)
        ax.set_ylabel(_with_unit(ylabel, unit))
        if kind == "car" and len(panels) > 1:
            ax.set_title(f"car {k + 1}", loc="left")
        if len(ax.get_lines()) > 1:
            ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0))
    axes[-1].set_xlabel("Time (s)")
    frame = ds[names[0]].attrs.get("frame", "") if names[0] in ds.data_vars else ""
    _suptitle(fig, title, ds.attrs.get("title", ""))
    if frame:
        fig.text(0.995, 0.005, f"frame: {frame} (docs/frames.md)", ha="right", va="bottom", fontsize=7, color="0.4")


def _suptitle(fig: Any, title: str, run: str) -> None:
    """The figure's title: the plot's ``title``, then the run's title after a dash on the same
    line when that fits the figure's width, else on a line of its own (a long scene title would
    otherwise run off both sides of the saved PNG)."""
    import matplotlib as mpl
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import TextToPath

    if not run:
        fig.suptitle(title)
        return
    last = title.split("\n")[-1]
    one_line = f"{last} — {run}"
    prop = FontProperties(size=mpl.rcParams["figure.titlesize"], weight=mpl.rcParams["figure.titleweight"])
    width_pt, _, _ = TextToPath().get_text_width_height_descent(one_line, prop, ismath=False)
    fits = width_pt <= 0.92 * fig.get_figwidth() * 72.0
    fig.suptitle(f"{title} — {run}" if fits else f"{title}\n{run}")


def _irregularity(ds: Any) -> tuple[Any, dict[str, Any]] | None:
    """The run's track irregularity (:class:`railslosh.irregularity.Irregularity`) and its spec,
    rebuilt from the Dataset, or None."""
    from railslosh import results
    from railslosh.irregularity import CHANNELS, Irregularity

    spec = results.irregularity_spec(ds)
    if spec is None or "distance" not in ds.coords or not all(n in ds.data_vars for n in _IRREGULARITY):
        return None
    d = np.asarray(ds["distance"].values, dtype=float)
    arrays = [np.asarray(ds[f"irregularity_{c}"].values, dtype=float) for c in CHANNELS]
    if d.size < 2 or not all(np.isfinite(a).all() for a in arrays):
        return None
    step = float(spec.get("step", (d[-1] - d[0]) / (d.size - 1)))
    return Irregularity(float(d[0]), step, *arrays), spec


def _wavelength(x: Any) -> Any:
    """λ = 2π/Ω and back (the top axis of the spectra)."""
    with np.errstate(divide="ignore"):
        return 2 * np.pi / np.asarray(x, dtype=float)


def _irregularity_title(spec: dict[str, Any], *, seed: bool = True) -> str:
    kind = spec.get("kind", "")
    what = {
        "fra": f"FRA class {spec.get('class', '?')}",
        "erri_low": "ERRI B176 low level",
        "erri_high": "ERRI B176 high level",
        "file": f"file {Path(str(spec.get('file', ''))).name}",
        "perfect": "perfect track",
        "samples": "samples",
    }.get(kind, kind)
    if seed and "seed" in spec:
        what += f", seed {spec['seed']}"
    if seed and spec.get("defects"):
        what += f", {len(spec['defects'])} defect(s)"
    return what


def _irregularity_channels(irr: Any) -> list[str]:
    """The channels of an irregularity that are not zero throughout."""
    from railslosh.irregularity import CHANNELS

    return [c for c in CHANNELS if np.any(irr.channel(c) != 0.0)]


def _draw_irregularity(fig: Any, irr: Any, spec: dict[str, Any], ds: Any, plot: tuple[str, str, Any, str]) -> None:
    """The channels of the run's track irregularity ``irr`` against distance (panels
    ``"distance"``), or their Welch PSD with the target spectrum as a black line (``"psd"``)."""
    from railslosh import irregularity

    _, title, _, kind = plot
    channels = _irregularity_channels(irr)
    axes = fig.subplots(len(channels), 1, sharex=True, squeeze=False)[:, 0]
    if kind == "psd":
        # the samples past the taper (the ramp from zero is not part of the spectrum)
        start = irr.start + float(spec.get("taper", 0.0) or 0.0)
        n = int(np.count_nonzero(irr.distance >= start - 1e-9 * irr.step))
        nperseg = min(irregularity.WELCH_NPERSEG, n // 2)
        wl = spec.get("wavelengths")
        for ax, c in zip(axes, channels, strict=True):
            w, p = irregularity.welch_psd(irr, c, nperseg, start=start)
            lo, hi = (2 * np.pi / wl[1], 2 * np.pi / wl[0]) if wl else (float(w[0]), float(w[-1]))
            # the requested band and a little beyond (Hann leakage fills the rest with orders of
            # magnitude of nothing)
            shown = (w >= lo / 1.5) & (w <= hi * 1.5) & (p > 0)
            ax.loglog(w[shown], p[shown], label=f"Welch estimate ({nperseg} samples a segment, after the taper)")
            ys = [p[shown & (w >= lo) & (w <= hi)]]
            if spec.get("kind") in irregularity.SPECTRA:
                band = np.geomspace(lo, hi, 200)
                target = irregularity.psd(spec["kind"], c, band, spec.get("class"))
                ax.loglog(band, target, color="k", lw=1.0, label=f"target: {_irregularity_title(spec, seed=False)}")
                ys.append(target[target > 0])
            for x, text in ((lo, "wavelength range of the track" if wl else None), (hi, None)):
                ax.axvline(x, color="0.5", ls=":", lw=0.8, label=text)
            y = np.concatenate(ys)
            if y.size:
                ax.set_ylim(float(y.min()) / 10, float(y.max()) * 10)
            ax.set_xlim(lo / 1.5, hi * 1.5)
            ax.set_ylabel(f"{LABELS[f'irregularity_{c}'][1]}\n(m²/(rad/m))")
            if len(ax.get_lines()) > 1:
                ax.legend(loc="lower left", fontsize=7)
        axes[-1].set_xlabel("Spatial angular frequency Ω = 2π/λ (rad/m)")
        top = axes[0].secondary_xaxis("top", functions=(_wavelength, _wavelength))
        top.set_xlabel("Wavelength λ (m)")
    else:
        unit, f = display_unit(_IRREGULARITY[0], np.concatenate([irr.channel(c) for c in channels]))
        d = irr.distance
        span = None
        if "tank_station" in ds.data_vars and ds["tank_station"].size:
            st = np.asarray(ds["tank_station"].values, dtype=float)
            if np.isfinite(st).any():
                span = (float(np.nanmin(st)), float(np.nanmax(st)))
        for k, (ax, c) in enumerate(zip(axes, channels, strict=True)):
            ax.plot(d, irr.channel(c) * f)
            if span is not None:
                ax.axvspan(*span, color="0.88", zorder=0, lw=0, label="tank centres during the run" if k == 0 else None)
            ax.set_ylabel(_with_unit(LABELS[f"irregularity_{c}"][1], unit))
            _min_span(ax, _RESOLUTION["length"] * f)
        xlabel = "Distance along the track s (m)"
        if span is not None:
            axes[0].legend(loc="upper left", bbox_to_anchor=(1.01, 1.0))
            # the part the train ran over (its front wheelset is ahead of the front tank centre)
            right = span[1] + 30.0
            if right < irr.end:
                axes[-1].set_xlim(min(irr.start, span[0]) - 5.0, right)
                xlabel += f"; the part run over (the irregularity goes on to {irr.end:.6g} m)"
        axes[-1].set_xlabel(xlabel)
    _suptitle(fig, f"{title}\n{_irregularity_title(spec)}", ds.attrs.get("title", ""))
    fig.text(0.995, 0.005, "frame: track (docs/frames.md)", ha="right", va="bottom", fontsize=7, color="0.4")


def figure(ds: Any, stem: str) -> Any:
    """The :class:`matplotlib.figure.Figure` of plot ``stem`` (:data:`PLOTS`), drawn in
    :data:`STYLE`, or ``None`` when the Dataset lacks its variables or has fewer than 2 samples."""
    import matplotlib.style
    from matplotlib.figure import Figure

    spec = next((p for p in PLOTS if p[0] == stem), None)
    if spec is None:
        raise ValueError(f"invalid `stem` = {stem!r}: expected one of {', '.join(p[0] for p in PLOTS)}")
    if spec[3] in ("distance", "psd"):
        got = _irregularity(ds)
        if got is None or not _irregularity_channels(got[0]):
            return None
        if spec[3] == "psd" and np.count_nonzero(got[0].distance >= got[0].start + got[1].get("taper", 0.0)) < 16:
            return None  # too short a track past the taper for a spectrum
        with matplotlib.style.context(STYLE):
            n = len(_irregularity_channels(got[0]))
            fig = Figure(figsize=(9.0, 1.2 + 1.9 * n if n > 1 else 4.2))
            _draw_irregularity(fig, got[0], got[1], ds, spec)
        return fig
    if not any(n in ds.data_vars and ds[n].size for n in spec[2]) or ds.sizes.get("time", 0) < 2:
        return None
    with matplotlib.style.context(STYLE):
        n = len(_panels(ds, spec))
        fig = Figure(figsize=(9.0, 1.2 + 1.9 * n if n > 1 else 4.2))
        _draw(fig, ds, spec)
    return fig


def plot_dataset(ds: Any, out_dir: str | os.PathLike[str], *, dpi: int = 100) -> list[Path]:
    """Writes one PNG per plot of :data:`PLOTS` whose variables are in ``ds``; returns the paths."""
    import matplotlib.style

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    with matplotlib.style.context(STYLE):
        for spec in PLOTS:
            fig = figure(ds, spec[0])
            if fig is None:
                continue
            p = out / f"{spec[0]}.png"
            fig.savefig(p, dpi=dpi)
            paths.append(p)
    return paths


def peak_table(ds: Any, *, include_settling: bool = False) -> list[tuple[str, str, float, float]]:
    """``(variable, units, max |value|, time of the max)`` of every variable, after the settling
    phase unless ``include_settling`` (:func:`railslosh.results.peaks`, largest over components)."""
    from railslosh import results

    best: dict[str, tuple[str, str, float, float]] = {}
    for p in results.peaks(ds, include_settling=include_settling):
        if p.name not in best or abs(p.value) > best[p.name][2]:
            best[p.name] = (p.name, p.units, abs(p.value), p.time)
    return list(best.values())
