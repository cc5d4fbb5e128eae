"""Results in standard formats: the time series of a run as an :class:`xarray.Dataset` (units and
frames in the attributes, CF-style), saved to netCDF, and the fluid mesh snapshots as a VTU time
series with a ParaView ``.pvd`` collection.

    >>> from railslosh import scene, results
    >>> res = scene.run_scene("examples/scenes/two_car_ecp_braking_rigid.toml")
    >>> ds = results.to_dataset(res)
    >>> ds["coupler_force"].attrs["units"], ds["coupler_force"].attrs["sign"]
    ('N', 'positive in tension')
    >>> results.save(ds, "out/results.nc"); ds2 = results.load("out/results.nc")

Every run has a settling phase (:func:`settling`): declared by the ``settle_time`` attribute,
absent when the run starts from a settled state (``settled_start``), otherwise detected from the
liquid's vertical load. :func:`peaks` and :func:`statistics` leave it out unless asked::

    >>> results.settling(ds)     # 20 mph lane change: Settling(time=0.0528, source='detected', rule=...)
    >>> results.peaks(ds)[1]     # Peak(name='force_tank', component='y', value=33.4, time=5.94, ...)

Frames and signs follow ``docs/frames.md``: ``tank`` (K: x forward along the tank axis, y left,
z up, origin at the tank centre), ``track`` (T(s): tangent, left, up), ``global`` (G: z up).
Wheel arrays are ordered front to rear over all cars, sides ``[left, right]`` looking forward.
"""

from __future__ import annotations

import datetime as _dt
import json
import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "NETCDF_ENGINE",
    "SETTLING_HOLD",
    "SETTLING_TOLERANCE",
    "VARIABLES",
    "Peak",
    "Settling",
    "Statistic",
    "after_settling",
    "extreme",
    "irregularity_spec",
    "load",
    "peaks",
    "save",
    "settling",
    "settling_time",
    "statistics",
    "to_dataset",
    "write_vtu",
]

NETCDF_ENGINE = "netcdf4"
"""Engine of :func:`save` / :func:`load`: the netCDF4 package (its wheels bundle the netCDF-C library);
the files are netCDF-4 (HDF5), readable by any netCDF tool."""

# name: (dims after "time", units, frame, long name, extra attributes)
VARIABLES: dict[str, tuple[tuple[str, ...], str, str, str, dict[str, str]]] = {
    # vehicle runs
    "wheel_vertical": (("wheelset", "side"), "N", "track", "vertical wheel load Q (along track up)", {}),
    "wheel_lateral": (("wheelset", "side"), "N", "track", "lateral wheel force Y", {"sign": "positive to the left"}),
    "l_over_v": (("wheelset", "side"), "1", "track", "derailment quotient L/V = |Y|/Q", {}),
    "unloading": (("wheelset", "side"), "1", "track", "wheel unloading ratio (Q0 - Q)/Q0", {}),
    "wheelset_lateral": (("wheelset",), "m", "track", "wheelset lateral displacement from the centreline", {}),
    "coupler_force": (("coupler",), "N", "car", "coupler force", {"sign": "positive in tension"}),
    "tank_station": (("car",), "m", "track", "arc length of the tank centre along the track", {}),
    "tank_speed": (("car",), "m/s", "global", "tank speed", {}),
    "car_acceleration": (
        ("car", "component"),
        "m/s2",
        "car",
        "acceleration of the car body (tank centre), gravity not included",
        {"recorded_as": "load channel (load_filter)"},
    ),
    # fluid vehicle runs
    "oil_com_tank": (("car", "component"), "m", "tank", "liquid centre of mass", {}),
    "oil_com_global": (("car", "component"), "m", "global", "liquid centre of mass", {}),
    "fluid_force_tank": (("car", "component"), "N", "tank", "force of the liquid on the tank", {}),
    "volume_error": (("car",), "1", "", "relative liquid volume change", {}),
    # equivalent (pendulum) slosh model runs
    "slosh_displacement": (
        ("car", "mode"),
        "m",
        "tank",
        "displacement of each slosh mass from rest along the slosh axis",
        {},
    ),
    # slosh runs
    "force_tank": (("component",), "N", "tank", "force of the liquid on the tank", {}),
    "moment_tank": (("component",), "N m", "tank", "moment of the liquid on the tank about its origin", {}),
    "force_global": (("component",), "N", "global", "force of the liquid on the tank", {}),
    "moment_global": (("component",), "N m", "global", "moment of the liquid on the tank about its origin", {}),
    "com_tank": (("component",), "m", "tank", "liquid centre of mass", {}),
    "volume": ((), "m3", "", "liquid volume", {}),
    "kinetic_energy": ((), "J", "global", "kinetic energy of the liquid", {}),
    "potential_energy": ((), "J", "global", "gravitational potential energy of the liquid", {}),
    "newton_iterations": ((), "1", "", "Newton iterations of the step", {}),
    "max_penetration": ((), "m", "tank", "largest wall penetration of the liquid", {}),
    # run-time invariants (rail_mbs::invariants)
    "stored_energy": ((), "J", "", "stored elastic energy of the liquid (penalty + contact springs)", {}),
    "input_work": (
        (),
        "J",
        "",
        "work put into the liquid (walls; in the tank frame gravity and pseudo-forces)",
        {},
    ),
    "energy_error": ((), "1", "", "energy growth (E - E0 - input work) / energy scale; <= 0 when physical", {}),
    "min_volume_ratio": ((), "1", "", "smallest volume ratio J = det F at any quadrature point", {}),
    "containment_gap": (
        (),
        "m",
        "tank",
        "largest gap beyond a wall of any fluid node, contact point or the centre of mass",
        {},
    ),
}

_SCALARS = ("static_wheel_load", "dof", "fluid_mass", "elements", "wall_damping_ratio", "wall_adhesion")
_FLAGS = ("shear_stabilization",)
_CHOICE = ("fluid_model", "fluid_model_reason", "load_filter", "stepper", "stepper_reason")
"""The fluid model of a vehicle scene and why (:mod:`railslosh.fluid_model`), and how its loads were
recorded (``load_filter``), and the stepper of a slosh run and why (``stepper``, ``stepper_reason``),
as global attributes."""


def _scene_attrs(sc: Any) -> dict[str, Any]:
    if sc is None:
        return {}
    attrs: dict[str, Any] = {"scene_kind": getattr(sc, "kind", ""), "title": getattr(sc, "name", "") or ""}
    if getattr(sc, "description", ""):
        attrs["scene_description"] = sc.description
    # the declared settling phase (:func:`settling`): a scene's `settle_time` (s), or a start from
    # a saved rest state (`settled_start`)
    if getattr(sc, "settle_time", None) is not None:
        attrs["settle_time"] = float(sc.settle_time)
    if getattr(sc, "settled_start", False):
        attrs["settled_start"] = 1
    try:
        attrs["scene_json"] = json.dumps(sc.to_dict(), default=str)
    except (AttributeError, TypeError):
        pass
    return attrs


def _irregularity(irr: Any) -> tuple[dict[str, Any], dict[str, Any], dict[str, Any]]:
    """The variables, coordinate and global attributes of a run's track irregularity
    (:class:`railslosh.irregularity.Irregularity`): ``irregularity_<channel>`` on the ``distance``
    dimension (m), and its :meth:`~railslosh.irregularity.Irregularity.summary` as
    ``irregularity_<key>`` attributes (``rms`` as ``irregularity_rms_<channel>``, ``defects`` and
    ``class_limits`` as JSON text)."""
    from railslosh.irregularity import CHANNELS, MEANINGS, Irregularity

    if not isinstance(irr, Irregularity):
        return {}, {}, {}
    data_vars = {
        f"irregularity_{c}": (
            ("distance",),
            np.asarray(getattr(irr, c)),
            {"units": "m", "long_name": f"track irregularity, {MEANINGS[c][0]}", "sign": MEANINGS[c][1],
             "frame": "track"},
        )
        for c in CHANNELS
    }  # fmt: skip
    coords = {
        "distance": ("distance", irr.distance, {"units": "m", "long_name": "distance along the track (arc length s)"})
    }
    attrs: dict[str, Any] = {}
    for k, v in irr.summary().items():
        key = f"irregularity_{k}"
        if k == "rms":
            attrs |= {f"{key}_{c}": float(x) for c, x in v.items()}
        elif k == "defects":
            attrs[key] = json.dumps(v)
        elif k == "channels":
            attrs[key] = ",".join(v)
        elif isinstance(v, bool):
            attrs[key] = int(v)
        elif isinstance(v, str | int | float):
            attrs[key] = v
        elif isinstance(v, list | tuple) and all(isinstance(x, int | float) for x in v):
            attrs[key] = np.asarray(v, dtype=float)
        elif v is not None:
            attrs[key] = json.dumps(v, default=str)
    return data_vars, coords, attrs


def irregularity_spec(ds: Any) -> dict[str, Any] | None:
    """The track irregularity a results Dataset records (:func:`to_dataset`), back as a dict:
    ``kind``, ``class``, ``seed``, ``wavelengths``, ``taper``, ``start``, ``length``, ``step``,
    ``channels``, ``file``, ``units``, ``sha256``, ``defects``, ``first``/``last`` distance,
    ``samples``, ``rms`` (per channel) and ``class_limits`` as far as the run had them; ``None``
    without one."""
    a = ds.attrs
    if "irregularity_kind" not in a:
        return None
    out: dict[str, Any] = {}
    rms: dict[str, float] = {}
    for k, v in a.items():
        if not k.startswith("irregularity_"):
            continue
        key = k[len("irregularity_") :]
        if key.startswith("rms_"):
            rms[key[4:]] = float(v)
        elif key in ("defects", "class_limits"):
            out[key] = json.loads(v)
        elif key == "channels":
            out[key] = [c for c in str(v).split(",") if c]
        elif isinstance(v, np.ndarray):
            out[key] = [float(x) for x in v]
        elif isinstance(v, np.generic):
            out[key] = v.item()
        else:
            out[key] = v
    if rms:
        out["rms"] = rms
    return out


def to_dataset(res: Mapping[str, Any], scene: Any = None) -> Any:
    """The time series of a run (the dict of :func:`railslosh.vehicle.run`, ``run_fluid``,
    :func:`railslosh.slosh.run` or :func:`railslosh.scene.run_scene`) as an ``xarray.Dataset``
    with dimension ``time`` (s) and, as needed, ``wheelset``, ``side``, ``coupler``, ``car`` and
    ``component`` (x, y, z). Every variable has ``units``, ``long_name`` and ``frame`` attributes;
    solver statistics and scalars (``static_wheel_load``, ``fluid_mass``, ...) are global attributes.
    A run on an irregular track (``res["irregularity"]``) adds its samples as ``irregularity_vertical``,
    ``irregularity_alignment``, ``irregularity_cross_level``, ``irregularity_gauge`` (m) on the
    ``distance`` dimension and its spec as ``irregularity_*`` attributes (:func:`irregularity_spec`)."""
    import xarray as xr

    from railslosh import __version__

    t = np.asarray(res["t"], dtype=float)
    nt = len(t)
    data_vars: dict[str, Any] = {}
    for name, (dims, units, frame, long_name, extra) in VARIABLES.items():
        if name not in res:
            continue
        arr = np.asarray(res[name])
        if arr.ndim == len(dims) + 2 and "car" not in dims:
            dims = ("car", *dims)  # the per-car series of a fluid vehicle run (e.g. containment_gap)
        if arr.shape[:1] != (nt,) or arr.ndim != len(dims) + 1:
            continue  # not a time series of the expected layout
        attrs = {"units": units, "long_name": long_name, **extra}
        if frame:
            attrs["frame"] = frame
        data_vars[name] = (("time", *dims), arr, attrs)
    coords: dict[str, Any] = {"time": ("time", t, {"units": "s", "long_name": "simulated time"})}
    sizes = {d: v[1].shape[i + 1] for v in data_vars.values() for i, d in enumerate(v[0][1:])}
    if "side" in sizes:
        coords["side"] = ("side", ["left", "right"], {"long_name": "wheel side looking forward"})
    if "component" in sizes:
        coords["component"] = ("component", ["x", "y", "z"])
    for d, long_name in (("wheelset", "wheelset, front to rear over all cars"), ("car", "car, front to rear")):
        if d in sizes:
            coords[d] = (d, np.arange(1, sizes[d] + 1), {"long_name": long_name})
    if "coupler" in sizes:
        coords["coupler"] = (
            "coupler",
            np.arange(1, sizes["coupler"] + 1),
            {"long_name": "coupler k joins cars k, k+1"},
        )
    attrs: dict[str, Any] = {
        "Conventions": "CF-1.8",
        "source": f"railslosh {__version__}",
        "history": f"created {_dt.datetime.now(_dt.UTC).isoformat(timespec='seconds')}",
        "frames": "see docs/frames.md: global G (z up), track T(s) (tangent, left, up), tank K (x along the axis)",
    }
    for k in _SCALARS:
        if k in res and res[k] is not None:
            attrs[k] = res[k]
    for k in _FLAGS:  # netCDF has no boolean attribute
        if k in res:
            attrs[k] = int(bool(res[k]))
    for k in _CHOICE:
        if res.get(k):
            attrs[k] = str(res[k])
    for k, v in (res.get("stats") or {}).items():
        attrs[f"stats_{k}"] = v
    for k, v in (res.get("margins") or {}).items():
        if v is not None:  # None: not measured (vehicle runs keep no energy account)
            attrs[f"margin_{k}"] = v
    for k, v in (res.get("mirror_symmetry") or {}).items():
        if isinstance(v, int | float):  # None: the lateral channels never strayed (no attribute)
            attrs[f"mirror_{k}"] = float(v)
    if res.get("error"):
        attrs["error"] = str(res["error"])
    if res.get("settle_time") is not None:
        attrs["settle_time"] = float(res["settle_time"])
    if res.get("settled_start"):
        attrs["settled_start"] = 1
    attrs |= _scene_attrs(scene if scene is not None else res.get("scene"))
    irr_vars, irr_coords, irr_attrs = _irregularity(res.get("irregularity"))
    data_vars |= irr_vars
    coords |= irr_coords
    attrs |= irr_attrs
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)


def save(ds: Any, path: str | os.PathLike[str]) -> Path:
    """Writes the Dataset to a netCDF-4 file (engine :data:`NETCDF_ENGINE`); returns the path."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    ds.to_netcdf(p, engine=NETCDF_ENGINE)
    return p


def load(path: str | os.PathLike[str]) -> Any:
    """Reads a results file written by :func:`save` into memory. A missing file raises
    :class:`FileNotFoundError`, a file that is not netCDF :class:`ValueError`, both naming the path."""
    import xarray as xr

    p = Path(path)
    if not p.is_file():
        what = "a directory" if p.is_dir() else "no such file"
        raise FileNotFoundError(f"invalid results file `{p}`: {what}; expected a results.nc written by `railslosh run`")
    try:
        with xr.open_dataset(p, engine=NETCDF_ENGINE) as ds:
            return ds.load()
    except (OSError, ValueError) as exc:  # netCDF4: "[Errno -51] NetCDF: Unknown file format"
        reason = getattr(exc, "strerror", None) or str(exc).splitlines()[0]
        raise ValueError(
            f"invalid results file `{p}`: not a netCDF file ({reason}); "
            "expected a results.nc written by `railslosh run`"
        ) from exc


# --- the settling phase, peaks and statistics ----------------------------------------------------

SETTLING_TOLERANCE = 0.05
"""Detected settling ends once the liquid's vertical load stays within this fraction of its settled
value (the weight) for :data:`SETTLING_HOLD`; the deviation squared measures the energy of the
start-up oscillation about the rest state, so 5 % leaves 0.25 % of the energy of a release from an
unloaded start."""

SETTLING_HOLD = 0.1
"""s: how long the vertical load must stay within :data:`SETTLING_TOLERANCE` (at most a quarter of
the run)."""

_RULE = "detected: the liquid's vertical load stays within {tol:.0%} of its time average (the weight) for {hold:.3g} s"
_RULE_DECAY = (
    "detected: the liquid's vertical load never stays within {tol:.0%} of the weight for {hold:.3g} s before an "
    "excitation starts; settling ends where its start-up deviation is smallest ({dev:.0%}) before rising again"
)


@dataclass(frozen=True)
class Settling:
    """The settling phase ``0 <= t < time`` of a run, and where it came from: ``source`` is
    ``"declared"`` (the ``settle_time`` attribute: the scene), ``"settled start"`` (the run starts
    from a saved rest state: ``settled_start`` attribute), ``"detected"`` (:func:`settling`) or
    ``"none"`` (nothing to detect it from); ``rule`` says it in words."""

    time: float
    source: str
    rule: str


def _truthy(v: Any) -> bool:
    if isinstance(v, str):
        return v.strip().lower() in ("1", "true", "yes")
    try:
        return bool(np.asarray(v).item())
    except (TypeError, ValueError):
        return False


def _vertical_liquid_load(ds: Any) -> np.ndarray | None:
    """(time, channels) vertical load of the liquid on each tank (tank frame z), or None."""
    for name in ("fluid_force_tank", "force_tank"):
        if name in ds.data_vars and "component" in ds[name].dims:
            da = ds[name].sel(component="z").transpose("time", ...)
            return np.asarray(da.values, dtype=float).reshape(da.shape[0], -1)
    return None


def _detect(t: np.ndarray, load: np.ndarray) -> tuple[float, str] | None:
    """End of the start-up transient of the vertical load and the rule that found it (see
    :func:`settling`), or None."""
    ok = np.isfinite(load).all(axis=1) & np.isfinite(t)
    t, load = t[ok], load[ok]
    if len(t) < 3 or t[-1] <= t[0]:
        return None
    span = t[-1] - t[0]
    weight = np.trapezoid(load, t, axis=0) / span
    if np.any(np.abs(weight) <= 1e-9 * (np.abs(load).max() + 1e-300)):
        return None
    dev = np.max(np.abs(load - weight) / np.abs(weight), axis=1)
    hold = min(SETTLING_HOLD, span / 4)
    end = np.searchsorted(t, t + hold * (1 - 1e-9), side="right")
    n = int(np.searchsorted(t, t[-1] - hold * (1 - 1e-9), side="right"))  # windows that fit the run
    env = np.array([dev[i : max(end[i], i + 1)].max() for i in range(max(n, 1))])
    quiet = np.flatnonzero(env <= SETTLING_TOLERANCE)
    if quiet.size:
        return float(t[quiet[0]]), _RULE.format(tol=SETTLING_TOLERANCE, hold=hold)
    # no quiet window (an excitation starts before the liquid has settled that far): the end of
    # the initial decay, the quietest window before the deviation rises to twice its running minimum
    low = np.minimum.accumulate(env)
    rise = np.flatnonzero((env > 2 * low) & (low < env[0]))
    i = int(np.argmin(env[: rise[0] if rise.size else len(env)]))
    return float(t[i]), _RULE_DECAY.format(tol=SETTLING_TOLERANCE, hold=hold, dev=env[i])


def settling(ds: Any) -> Settling:
    """The settling phase of a results Dataset, in this order:

    1. the ``settle_time`` attribute (s; the scene's declared settling time), clipped to the run;
    2. ``settled_start`` true (1, ``"true"``): the run starts from a settled rest state, no settling;
    3. detected from the liquid's vertical load on each tank (``fluid_force_tank`` / ``force_tank``,
       tank-frame z): its settled value is its time average over the run (the weight: the liquid
       starts and ends at rest vertically); settling ends at the first time after which the
       deviation from it stays within :data:`SETTLING_TOLERANCE` of the weight for
       :data:`SETTLING_HOLD` s (every tank). Where that never happens because an excitation
       starts first, it ends where the start-up deviation is quietest before it rises again
       (to twice its running minimum). A run without a start-up transient gets 0;
    4. otherwise 0 (``"none"``): runs without liquid start from their static equilibrium (the
       springs are preloaded); declare ``settle_time`` for other start-up transients (a car set
       centred into a curve settles onto its flanges in about 0.5 s).

    Deterministic: the same Dataset gives the same time."""
    t = np.asarray(ds["time"].values, dtype=float)
    t_end = float(t[-1]) if t.size else 0.0
    if "settle_time" in ds.attrs:
        v = float(np.asarray(ds.attrs["settle_time"]).item())
        if not np.isfinite(v) or v < 0:
            raise ValueError(f"invalid attribute `settle_time` = {v!r}: expected a time >= 0 s")
        return Settling(min(v, t_end), "declared", f"declared: the scene's settling time {v:g} s")
    if _truthy(ds.attrs.get("settled_start", False)):
        return Settling(0.0, "settled start", "none: the run starts from a settled rest state")
    load = _vertical_liquid_load(ds)
    if load is None or not t.size:
        return Settling(
            0.0, "none", "none: no liquid load to detect it from; the run starts from its static equilibrium"
        )
    found = _detect(t, load)
    if found is None:
        return Settling(0.0, "none", "none: too few finite samples of the liquid's vertical load to detect it")
    return Settling(found[0], "detected", found[1])


def settling_time(ds: Any) -> float:
    """End of the settling phase in s (:func:`settling`)."""
    return settling(ds).time


def after_settling(ds: Any, settle: float | Settling | None = None) -> Any:
    """The samples at ``t >= settling time`` (:func:`settling`, or the time given)."""
    if settle is None:
        settle = settling(ds)
    ts = settle.time if isinstance(settle, Settling) else float(settle)
    return ds.isel(time=np.flatnonzero(np.asarray(ds["time"].values) >= ts - 1e-12))


@dataclass(frozen=True)
class Peak:
    """The largest ``|value|`` of a variable (of one component where it has them): ``value`` is
    signed, in the variable's ``units``; ``where`` holds the coordinates of the peak (car,
    wheelset, side, ...); ``after`` is the start of the searched interval (the settling time)."""

    name: str
    component: str | None
    value: float
    time: float
    where: dict[str, Any]
    units: str
    after: float


def _split(da: Any) -> list[tuple[str | None, Any]]:
    if "component" in da.dims:
        return [(str(c), da.sel(component=c)) for c in da["component"].values]
    return [(None, da)]


def extreme(da: Any, *, mode: str = "abs", after: float = 0.0, cutoff: float | None = None) -> Peak | None:
    """The largest ``|value|`` (``mode="abs"``), largest (``"max"``) or smallest (``"min"``) value
    of a DataArray with a ``time`` dimension over ``t >= after``, as a :class:`Peak`; None when
    nothing finite is there. A ``component`` coordinate of one component is kept in ``component``.
    With ``cutoff`` (Hz) the values at ``t >= after`` first pass through
    :func:`railslosh.indicators.low_pass` at that cut-off (e.g.
    :data:`railslosh.indicators.LOAD_CUTOFF`, EN 14363's 20 Hz for forces); the time is then that of
    the filter's grid."""
    if mode not in ("abs", "max", "min"):
        raise ValueError(f"invalid `mode` = {mode!r}: expected 'abs', 'max' or 'min'")
    da = da.transpose("time", ...)
    t = np.asarray(da["time"].values, dtype=float)
    keep = t >= after - 1e-12
    t, v = t[keep], np.asarray(da.values, dtype=float)[keep]
    if cutoff is not None:
        # only the samples after `after` are filtered: the settling phase's spike stays out
        from railslosh import indicators

        finite = np.isfinite(v.reshape(t.size, -1)).all(axis=1)
        if finite.sum() < 2:
            return None
        t, filtered = indicators.low_pass(t[finite], v.reshape(t.size, -1)[finite], cutoff)
        v = filtered.reshape((t.size, *v.shape[1:]))
    if v.size == 0 or not np.isfinite(v).any():
        return None
    key = {"abs": np.abs(v), "max": v, "min": -v}[mode]
    flat = int(np.nanargmax(key))
    idx = np.unravel_index(flat, v.shape)
    where = {}
    for d, i in zip(da.dims[1:], idx[1:], strict=True):
        where[d] = da[d].values[i].item() if d in da.coords else int(i)
    comp = str(da["component"].values.item()) if "component" in da.coords and da["component"].ndim == 0 else None
    time = float(t[idx[0]])
    return Peak(str(da.name), comp, float(v.flat[flat]), time, where, da.attrs.get("units", ""), float(after))


def peaks(ds: Any, *, include_settling: bool = False) -> list[Peak]:
    """:class:`Peak` (largest ``|value|``) of every variable with a ``time`` dimension, one per
    component, after the settling phase (:func:`settling`) unless ``include_settling``."""
    ts = 0.0 if include_settling else settling(ds).time
    rows = []
    for da in ds.data_vars.values():
        if "time" not in da.dims:
            continue
        for _, sub in _split(da):
            p = extreme(sub, after=ts)
            if p is not None:
                rows.append(p)
    return rows


@dataclass(frozen=True)
class Statistic:
    """Smallest, largest and time-averaged value of a variable (one component where it has them)
    over ``t >= after``, in its ``units``."""

    name: str
    component: str | None
    min: float
    max: float
    mean: float
    units: str
    after: float


def statistics(ds: Any, *, include_settling: bool = False) -> list[Statistic]:
    """:class:`Statistic` of every variable with a ``time`` dimension (one per component), after
    the settling phase (:func:`settling`) unless ``include_settling``."""
    ts = 0.0 if include_settling else settling(ds).time
    part = after_settling(ds, ts)
    t = np.asarray(part["time"].values, dtype=float)
    rows = []
    for name, da in part.data_vars.items():
        if "time" not in da.dims:
            continue
        for comp, sub in _split(da.transpose("time", ...)):
            v = np.asarray(sub.values, dtype=float).reshape(len(t), -1)
            keep = np.isfinite(v).all(axis=1)
            if v.size == 0 or not keep.any():
                continue
            vk, tk = v[keep], t[keep]
            span = tk[-1] - tk[0]
            mean = float(np.trapezoid(vk, tk, axis=0).mean() / span) if span > 0 else float(vk.mean())
            units = da.attrs.get("units", "")
            rows.append(Statistic(str(name), comp, float(vk.min()), float(vk.max()), mean, units, ts))
    return rows


# --- fluid snapshots for ParaView ----------------------------------------------------------------

# VTK hexahedron node order: bottom face counter-clockwise, then the top face (the ANCF element
# node order A..H of docs/frames.md is the same).


def write_vtu(
    res: Mapping[str, Any], out_dir: str | os.PathLike[str], connectivity: Any, name: str = "fluid"
) -> Path | None:
    """Writes the fluid snapshots of a ``run_fluid`` result as ``out_dir/name/<name>_car<k>_<i>.vtu``
    (hexahedra from the ANCF nodes; point data: displacement from the first snapshot, m, and the
    position gradients ``r_x``, ``r_y``, ``r_z``) and a ParaView collection ``out_dir/<name>.pvd``
    (one block per car, timestep = simulated time). ``connectivity`` is the element-node table of
    the fluid mesh, shape (elements, 8). Returns the ``.pvd`` path, or ``None`` without snapshots."""
    import meshio

    snaps = res.get("snapshots") or []
    if not snaps:
        return None
    conn = np.asarray(connectivity, dtype=np.int64)
    if conn.ndim != 2 or conn.shape[1] != 8:
        raise ValueError(f"invalid `connectivity` of shape {conn.shape}: expected (elements, 8)")
    out = Path(out_dir)
    (out / name).mkdir(parents=True, exist_ok=True)
    entries = []
    first = [np.asarray(e)[:, 0, :] for e in snaps[0][1]]
    for i, (t, cars) in enumerate(snaps):
        for k, e in enumerate(cars):
            e = np.asarray(e, dtype=float)  # (nodes, 4, 3): r, r_x, r_y, r_z
            if conn.max() >= len(e):
                raise ValueError(f"invalid `connectivity`: node {conn.max()} of a mesh with {len(e)} nodes")
            mesh = meshio.Mesh(
                points=e[:, 0, :],
                cells=[("hexahedron", conn)],
                point_data={
                    "displacement": e[:, 0, :] - first[k],
                    "r_x": e[:, 1, :],
                    "r_y": e[:, 2, :],
                    "r_z": e[:, 3, :],
                },
            )
            fname = f"{name}/{name}_car{k + 1}_{i:04d}.vtu"
            meshio.write(out / fname, mesh, binary=True)
            entries.append(f'    <DataSet timestep="{float(t):.9g}" part="{k}" file="{fname}"/>')
    pvd = out / f"{name}.pvd"
    pvd.write_text(
        '<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n'
        "  <Collection>\n" + "\n".join(entries) + "\n  </Collection>\n</VTKFile>\n",
        encoding="utf-8",
    )
    return pvd
