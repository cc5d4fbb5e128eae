"""Results in standard formats: the time series of a run as an :class:`xarray.Dataset` (units and
frames in the attributes, CF-style), saved to netCDF, and the fluid mesh snapshots as a VTU time
series with a ParaView ``.pvd`` collection.

    >>> from railslosh import scene, results
    >>> res = scene.run_scene("examples/scenes/two_car_ecp_braking_rigid.toml")
    >>> ds = results.to_dataset(res)
    >>> ds["coupler_force"].attrs["units"], ds["coupler_force"].attrs["sign"]
    ('N', 'positive in tension')
    >>> results.save(ds, "out/results.nc"); ds2 = results.load("out/results.nc")

Frames and signs follow ``docs/frames.md``: ``tank`` (K: x forward along the tank axis, y left,
z up, origin at the tank centre), ``track`` (T(s): tangent, left, up), ``global`` (G: z up).
Wheel arrays are ordered front to rear over all cars, sides ``[left, right]`` looking forward.
"""

from __future__ import annotations

import datetime as _dt
import json
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["NETCDF_ENGINE", "VARIABLES", "load", "save", "to_dataset", "write_vtu"]

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

_SCALARS = ("static_wheel_load", "dof", "fluid_mass", "elements", "wall_damping_ratio")
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
    try:
        attrs["scene_json"] = json.dumps(sc.to_dict(), default=str)
    except (AttributeError, TypeError):
        pass
    return attrs


def to_dataset(res: Mapping[str, Any], scene: Any = None) -> Any:
    """The time series of a run (the dict of :func:`railslosh.vehicle.run`, ``run_fluid``,
    :func:`railslosh.slosh.run` or :func:`railslosh.scene.run_scene`) as an ``xarray.Dataset``
    with dimension ``time`` (s) and, as needed, ``wheelset``, ``side``, ``coupler``, ``car`` and
    ``component`` (x, y, z). Every variable has ``units``, ``long_name`` and ``frame`` attributes;
    solver statistics and scalars (``static_wheel_load``, ``fluid_mass``, ...) are global attributes."""
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
    for k in _CHOICE:
        if res.get(k):
            attrs[k] = str(res[k])
    for k, v in (res.get("stats") or {}).items():
        attrs[f"stats_{k}"] = v
    for k, v in (res.get("margins") or {}).items():
        if v is not None:  # None: not measured (vehicle runs keep no energy account)
            attrs[f"margin_{k}"] = v
    if res.get("error"):
        attrs["error"] = str(res["error"])
    attrs |= _scene_attrs(scene if scene is not None else res.get("scene"))
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)


def save(ds: Any, path: str | os.PathLike[str]) -> Path:
    """Writes the Dataset to a netCDF-4 file (engine :data:`NETCDF_ENGINE`); returns the path."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    ds.to_netcdf(p, engine=NETCDF_ENGINE)
    return p


def load(path: str | os.PathLike[str]) -> Any:
    """Reads a results file written by :func:`save` into memory."""
    import xarray as xr

    with xr.open_dataset(path, engine=NETCDF_ENGINE) as ds:
        return ds.load()


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
        raise ValueError(f"invalid parameter `connectivity` of shape {conn.shape}: allowed (elements, 8)")
    out = Path(out_dir)
    (out / name).mkdir(parents=True, exist_ok=True)
    entries = []
    first = [np.asarray(e)[:, 0, :] for e in snaps[0][1]]
    for i, (t, cars) in enumerate(snaps):
        for k, e in enumerate(cars):
            e = np.asarray(e, dtype=float)  # (nodes, 4, 3): r, r_x, r_y, r_z
            if conn.max() >= len(e):
                raise ValueError(f"invalid parameter `connectivity`: node {conn.max()} of a mesh with {len(e)} nodes")
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
