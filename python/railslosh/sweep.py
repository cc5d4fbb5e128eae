"""Parameter sweeps of a scene on Dask: every point of a grid (oil type x fill x braking x
bulkheads x speed, or any scene field) is one run; the results are gathered into one
``xarray.Dataset`` with the sweep parameters as dimensions.

    >>> from railslosh import _core, sweep
    >>> grid = sweep.parse_grid(["oil=light,heavy", "fill=0.5,0.7"])
    >>> ds = sweep.run_sweep("examples/scenes/crude_ecp_braking_light.toml", grid)   # LocalCluster
    >>> ds["coupler_force"].sel(oil="heavy", fill=0.7)

Grid names: ``oil`` (``fluid.oil``), ``fill`` (``fluid.fill``), ``braking`` (``ecp`` / ``all`` or
``conventional`` / ``front``: ``brake.scope``), ``bulkheads`` (number of equally spaced 20 mm
bulkheads: ``tank.bulkheads``), ``speed`` (km/h: ``train.speed_kmh``, or the maneuver speed of a
slosh scene), ``track_class`` (the FRA class of ``[track.irregularities]``), ``model``
(``fluid.slosh_model``: ``auto``, ``ancf``, ``pendulum``, ``rigid``), or any dotted scene field
``section.key`` (or ``track.irregularities.key``). Runs are distributed with
``dask.distributed``: a ``LocalCluster`` by default (threads: the Rust solver releases the GIL),
or the scheduler at ``address`` (its workers need railslosh installed).
"""

from __future__ import annotations

import itertools
import os
import time
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from railslosh import _core, mesh, results, scene
from railslosh.limits import invalid, suggest
from railslosh.scene.load import parse_value, set_dotted
from railslosh.slosh import SimulationError

__all__ = ["ALIASES", "grid_overrides", "parse_grid", "parse_value", "run_point", "run_sweep", "sweep_points"]

ALIASES = {
    "oil": "fluid.oil",
    "fill": "fluid.fill",
    "braking": "brake.scope",
    "bulkheads": "tank.bulkheads",
    "speed": "train.speed_kmh",
    "track_class": "track.irregularities.class",
    "model": "fluid.slosh_model",
}
"""Short grid names and the scene field each sets."""

_BRAKING = {"ecp": "all", "conventional": "front", "all": "all", "front": "front"}


def parse_grid(specs: Sequence[str]) -> dict[str, list[Any]]:
    """``["oil=light,heavy", "fill=0.5,0.7"]`` -> ``{"oil": ["light", "heavy"], "fill": [0.5, 0.7]}``."""
    grid: dict[str, list[Any]] = {}
    for spec in specs:
        name, sep, values = spec.partition("=")
        name = name.strip()
        if not sep or not name or not values.strip():
            raise invalid("--grid", spec, "NAME=V1,V2,... (e.g. --grid oil=light,heavy)")
        if name in grid:
            raise invalid(f"--grid {name}", values, f"one --grid {name}=... (it is given twice)")
        vals = [parse_value(v) for v in values.split(",") if v.strip()]
        if len(set(map(repr, vals))) != len(vals):
            raise invalid(f"--grid {name}", values, "distinct values")
        grid[name] = vals
    return grid


def _set(over: dict[str, Any], dotted: str, value: Any) -> None:
    if "." not in dotted:
        close = suggest(dotted, ALIASES)
        hint = f" (did you mean `{close}`?)" if close else ""
        raise ValueError(
            f"invalid `--grid {dotted}`: unknown grid name{hint}; expected one of {', '.join(ALIASES)} "
            "or a scene field section.key"
        )
    set_dotted(over, dotted, value, option=f"--grid {dotted}")


def _bulkheads(n: Any, tank_length: float = _core.TANK_CAR_LENGTH) -> list[list[float]]:
    if isinstance(n, bool) or not isinstance(n, int) or not 0 <= n <= 5:
        raise invalid("bulkheads", n, "a number of equally spaced bulkheads from 0 to 5")
    shell = tank_length - 2.0 * mesh.TANK_CAR_HEAD_DEPTH
    return [[round(-shell / 2 + shell * (k + 1) / (n + 1), 6), 0.02] for k in range(n)]


def grid_overrides(base: Mapping[str, Any], point: Mapping[str, Any]) -> dict[str, Any]:
    """Scene overrides (for :func:`railslosh.scene.load_scene`) of one grid point."""
    over: dict[str, Any] = {}
    slosh = "maneuver" in base
    for name, value in point.items():
        if name == "braking":
            if value not in _BRAKING:
                raise invalid("braking", value, f"one of {', '.join(_BRAKING)}")
            _set(over, "brake.scope", _BRAKING[value])
        elif name == "bulkheads":
            # overall tank length: the car's (shell + two heads) or a slosh tank's shell + two heads
            if slosh:
                shell = float(base.get("tank", {}).get("length", mesh.TANK_CAR_SHELL_LENGTH))
                length = shell + 2.0 * mesh.TANK_CAR_HEAD_DEPTH
            else:
                car = base.get("car") if isinstance(base.get("car"), Mapping) else {}
                length = float(car.get("tank_length", _core.TANK_CAR_LENGTH))
            _set(over, "tank.bulkheads", _bulkheads(value, length))
        elif name == "speed" and slosh:
            over.setdefault("maneuver", {}).update({"speed": None, "speed_mph": None, "speed_kmh": value})
        elif name == "speed":
            over.setdefault("train", {}).update({"speed": None, "speed_kmh": value})
        else:
            _set(over, ALIASES.get(name, name), value)
    return over


def _time_grid(sc: Any) -> np.ndarray:
    dt = sc.record_every if sc.kind != "slosh" else sc.step
    n = int(round(sc.t_end / dt))
    return np.linspace(0.0, n * dt, n + 1)


#: Load channels of slosh runs, resampled by their hat-weighted mean (the vehicle runs' load filter).
LOADS = ("force_tank", "moment_tank", "force_global", "moment_global")


def _resample(ds: Any, grid: np.ndarray) -> Any:
    """A slosh run's Dataset (every adaptive step) on ``grid`` (multiples of ``solver.step``): the
    loads by their hat-weighted mean over the steps (:func:`railslosh._core.hat_mean_resample`, the
    zero-phase anti-aliasing filter vehicle runs record their loads with, so the sweep's loads
    carry no aliased wall ringing), every other channel by linear interpolation. The Dataset says
    so in its ``resampling`` attribute."""
    t = ds["time"].values
    out = ds.interp(time=grid)
    dt = float(grid[1] - grid[0]) if len(grid) > 1 else float(t[-1] - t[0]) or 1.0
    for name in LOADS:
        if name in ds:
            v = ds[name].values.reshape(len(t), -1)
            r = _core.hat_mean_resample(list(t), v.tolist(), dt)[: len(grid)]
            out[name] = (ds[name].dims, r.reshape((len(grid), *ds[name].shape[1:])), ds[name].attrs)
    out.attrs["resampling"] = (
        f"loads ({', '.join(n for n in LOADS if n in ds)}): hat-weighted mean over the steps onto multiples of "
        f"{dt:g} s; other channels: linear interpolation"
    )
    return out


def run_point(base: Mapping[str, Any], overrides: Mapping[str, Any]) -> Any:
    """Runs one grid point; returns its Dataset on the scene's uniform time grid (vehicle runs record
    on it already, their loads as hat-weighted means; slosh runs, which record every adaptive step,
    are put on multiples of ``solver.step``: loads by the same hat-weighted mean, other channels
    interpolated, see :func:`_resample`), with the run's ``wall_time``, ``steps`` and ``error``
    (empty when it finished) as scalar variables."""
    sc = scene.load_scene(base, overrides)
    t0 = time.perf_counter()
    error = ""
    try:
        res = scene.run_scene(sc)
    except SimulationError as exc:
        res, error = dict(exc.results), str(exc)
        res["scene"] = sc
    ds = results.to_dataset(res, sc)
    grid = _time_grid(sc)
    t = ds["time"].values
    if len(t) <= len(grid) and np.allclose(t, grid[: len(t)], rtol=0.0, atol=1e-9):
        ds = ds.assign_coords(time=("time", grid[: len(t)], ds["time"].attrs))  # exactly the common grid
    elif len(t) >= 2:
        ds = _resample(ds, grid[grid <= t[-1] + 1e-9])
    stats = res.get("stats") or {}
    ds["wall_time"] = ((), time.perf_counter() - t0, {"units": "s", "long_name": "wall time of the run"})
    ds["steps"] = ((), int(stats.get("steps", 0)), {"units": "1", "long_name": "accepted steps"})
    ds["error"] = ((), error, {"long_name": "why the run stopped early (empty: it finished)"})
    ds.attrs = {k: v for k, v in ds.attrs.items() if not k.startswith("stats_") and k != "scene_json"}
    return ds


def _client(scheduler: str | None, workers: int, processes: bool) -> Any:
    from dask.distributed import Client, LocalCluster

    if scheduler:
        return Client(scheduler)
    cluster = LocalCluster(
        n_workers=1 if not processes else workers,
        threads_per_worker=workers if not processes else 1,
        processes=processes,
        dashboard_address=None,
    )
    return Client(cluster)


def sweep_points(
    scene_source: str | os.PathLike[str] | Mapping[str, Any],
    grid: Mapping[str, Sequence[Any]],
    overrides: Mapping[str, Any] | None = None,
) -> tuple[dict[str, Any], list[str], list[dict[str, Any]], list[dict[str, Any]]]:
    """The parsed scene (``overrides`` merged), the grid names, every point of ``grid`` and its
    scene overrides, each point checked (its scene loads): a bad value raises ``ValueError`` naming
    the point and the field, before anything runs."""
    if not grid:
        raise invalid("grid", {}, "at least one NAME=V1,V2,...")
    base = scene.read_scene(scene_source)
    if overrides:
        base = scene.merge(base, overrides)
    names = list(grid)
    points = [dict(zip(names, combo, strict=True)) for combo in itertools.product(*(grid[n] for n in names))]
    overs = []
    for pt in points:
        over = grid_overrides(base, pt)
        try:
            scene.load_scene(base, over)
        except ValueError as exc:
            raise ValueError(f"sweep point {pt}: {exc}") from exc
        overs.append(over)
    return base, names, points, overs


def run_sweep(
    scene_source: str | os.PathLike[str] | Mapping[str, Any],
    grid: Mapping[str, Sequence[Any]],
    *,
    overrides: Mapping[str, Any] | None = None,
    scheduler: str | None = None,
    workers: int | None = None,
    processes: bool = False,
    client: Any = None,
    on_done: Any = None,
) -> Any:
    """Runs every point of ``grid`` (name -> values) on Dask and returns one Dataset with a
    dimension per grid name (coordinates = the grid values as given). Every point is validated
    before anything runs (a bad value raises ``ValueError`` naming the field). ``overrides`` apply to
    every point; ``client`` (a ``dask.distributed.Client``) or ``scheduler`` (an address) choose the
    cluster, else a ``LocalCluster`` with ``workers`` (default: CPU count) threads (``processes=True``:
    worker processes). ``on_done(done, total)`` is called as runs finish. Points whose run stopped
    early hold the results up to the failure (NaN after it) and their message in ``error``."""
    import xarray as xr

    base, names, points, overs = sweep_points(scene_source, grid, overrides)
    own = client is None
    if own:
        client = _client(scheduler, workers or os.cpu_count() or 1, processes)
    try:
        from dask.distributed import as_completed

        futures = [client.submit(run_point, base, o, pure=False) for o in overs]
        index = {f.key: i for i, f in enumerate(futures)}
        out: list[Any] = [None] * len(futures)
        for k, fut in enumerate(as_completed(futures), 1):
            out[index[fut.key]] = fut.result()
            if on_done is not None:
                on_done(k, len(futures))
    finally:
        if own:
            cluster = getattr(client, "cluster", None)
            client.close()
            if cluster is not None:
                cluster.close()
    # one hypercube: every point on the union of the time grids
    expanded = [ds.expand_dims({n: [pt[n]] for n in names}) for ds, pt in zip(out, points, strict=True)]
    combined = xr.combine_by_coords(
        expanded, data_vars="all", combine_attrs="drop_conflicts", join="outer", compat="no_conflicts"
    )
    combined.attrs["sweep_dims"] = ",".join(names)
    for n in names:
        combined[n].attrs["long_name"] = f"sweep parameter {ALIASES.get(n, n)}"
        if n == "speed":
            combined[n].attrs["units"] = "km/h"
    return combined
