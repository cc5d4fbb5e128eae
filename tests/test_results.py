"""Results in standard formats (issue 9): the xarray Dataset carries every time series with the
documented units and frames, survives a netCDF round trip, and the fluid snapshots become VTU
hexahedra (correctly oriented, volume of the liquid) in a ParaView collection."""

import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

import railslosh as rs
from railslosh import results, scene

TANGENT = [[0, 0, 0, 0, 0, 0], [4000, 0, 0, 0, 0, 0]]


@pytest.fixture(scope="module")
def fluid_run():
    sc = scene.load_scene(
        {
            "scene": {"name": "short fluid run"},
            "track": {"preset": "tangent", "length": 4000.0},
            "train": {"cars": 2, "station": 300.0, "speed_kmh": 40.0, "t_end": 0.1, "step": 4e-3, "record_every": 0.02},
            "brake": {"design": True},
            "fluid": {"oil": "light", "fill": 0.5},
            "mesh": {"counts": [2, 2, 2]},
            "outputs": {"snapshot_every": 0.04},
        }
    )
    return scene.run_scene(sc)


def test_dataset_holds_every_series_with_units_and_frames(fluid_run):
    ds = results.to_dataset(fluid_run)
    nt = len(fluid_run["t"])
    assert ds.sizes["time"] == nt and ds.sizes["wheelset"] == 8 and ds.sizes["car"] == 2 and ds.sizes["coupler"] == 1
    assert list(ds["side"].values) == ["left", "right"] and list(ds["component"].values) == ["x", "y", "z"]
    for name, (_dims, units, frame, long_name, extra) in results.VARIABLES.items():
        if name not in fluid_run or not hasattr(fluid_run[name], "shape"):
            continue
        da = ds[name]
        np.testing.assert_array_equal(da.values, fluid_run[name])
        assert da.attrs["units"] == units and da.attrs["long_name"] == long_name
        assert da.attrs.get("frame", "") == frame
        for k, v in extra.items():
            assert da.attrs[k] == v
    assert ds["coupler_force"].attrs["sign"] == "positive in tension"
    assert ds["fluid_force_tank"].attrs["frame"] == "tank"
    assert ds.attrs["stats_steps"] == fluid_run["stats"]["steps"] and ds.attrs["scene_kind"] == "fluid_vehicle"
    assert ds.attrs["title"] == "short fluid run" and ds.attrs["fluid_mass"] == fluid_run["fluid_mass"]


def test_netcdf_round_trip_keeps_values_and_attributes(fluid_run, tmp_path):
    ds = results.to_dataset(fluid_run)
    p = results.save(ds, tmp_path / "sub" / "results.nc")
    back = results.load(p)
    for name in ds.data_vars:
        np.testing.assert_array_equal(back[name].values, ds[name].values)
        assert back[name].attrs == ds[name].attrs
    assert back.attrs["scene_json"] == ds.attrs["scene_json"]
    # the stored scene reproduces the scene
    import json

    again = scene.load_scene(json.loads(back.attrs["scene_json"]))
    assert again.fluid == fluid_run["scene"].fluid and again.cars == 2


def test_slosh_results_become_a_dataset():
    mesh = rs.mesh.box((0.4, 0.3, 0.1), (1, 2, 1))
    tank = rs.slosh.TankGeometry.box((-0.2, -0.15, 0.0), (0.2, 0.15, 0.3))
    res = rs.slosh.run(mesh, rs.fluids.water(depth=0.1), tank, rs.slosh.Motion(), t_end=0.05, step=0.01)
    ds = results.to_dataset(res)
    assert ds["force_tank"].dims == ("time", "component") and ds["force_tank"].attrs["units"] == "N"
    assert ds["moment_global"].attrs["frame"] == "global" and ds["volume"].attrs["units"] == "m3"
    np.testing.assert_array_equal(ds["com_tank"].values, res["com_tank"])
    assert "wheel_vertical" not in ds


def _hex_volume(p):
    """Volume of a trilinear hexahedron in VTK node order (positive when correctly oriented),
    by 2x2x2 Gauss quadrature of det J."""
    g = np.array([-1, 1]) / np.sqrt(3.0)
    ref = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1], [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]])
    vol = 0.0
    for a in g:
        for b in g:
            for c in g:
                dn = (
                    np.array(
                        [
                            [
                                r[0] * (1 + r[1] * b) * (1 + r[2] * c),
                                r[1] * (1 + r[0] * a) * (1 + r[2] * c),
                                r[2] * (1 + r[0] * a) * (1 + r[1] * b),
                            ]
                            for r in ref
                        ]
                    )
                    / 8.0
                )
                vol += np.linalg.det(p.T @ dn)
    return vol


def test_vtu_snapshots_and_pvd_collection(fluid_run, tmp_path):
    snaps = fluid_run["snapshots"]
    assert len(snaps) == 3  # t = 0, 0.04, 0.08
    pvd = results.write_vtu(fluid_run, tmp_path, fluid_run["connectivity"])
    root = ET.parse(pvd).getroot()
    entries = root.find("Collection").findall("DataSet")
    assert len(entries) == 2 * len(snaps)
    times = sorted({float(e.get("timestep")) for e in entries})
    assert times == pytest.approx([s[0] for s in snaps])
    rho = 850.0
    for e in entries:
        m = meshio.read(tmp_path / e.get("file"))
        k, i = int(e.get("part")), times.index(float(e.get("timestep")))
        np.testing.assert_allclose(m.points, np.asarray(snaps[i][1][k])[:, 0, :])
        hexes = m.cells_dict["hexahedron"]
        assert hexes.shape == (fluid_run["elements"], 8)
        vols = np.array([_hex_volume(m.points[h]) for h in hexes])
        assert (vols > 0).all(), "VTK hexahedron node order (orientation)"
        # trilinear hexahedra through the ANCF nodes hold the liquid volume to a few per cent
        assert vols.sum() == pytest.approx(fluid_run["fluid_mass"] / rho, rel=0.08)
        assert set(m.point_data) == {"displacement", "r_x", "r_y", "r_z"}
    assert results.write_vtu({"snapshots": []}, tmp_path, fluid_run["connectivity"]) is None
    with pytest.raises(ValueError, match="invalid `connectivity`"):
        results.write_vtu(fluid_run, tmp_path, np.zeros((2, 4), dtype=int))


def test_a_slosh_scene_writes_tank_frame_vtu_snapshots_holding_the_liquid_volume(tmp_path):
    """Issue 19: ParaView output for slosh scenes too. `railslosh run` of a rectangular-tank slosh
    scene with outputs.snapshot_every writes fluid.pvd; every VTU opens with meshio, its hexahedra
    are in the tank frame (inside the box) and hold the liquid volume the run recorded."""
    from railslosh import cli

    text = """
[tank]
shape = "box"
lower = [-0.208, -0.162, 0.0]
upper = [0.208, 0.162, 0.3]
[fluid]
oil = "water"
fill = 0.44
[mesh]
counts = [2, 4, 2]
viscous_points = 4
penalty_points = 4
contact_points_per_edge = 4
[solver]
t_end = 0.6
step = 0.01
[maneuver]
type = "lane_change"
speed_mph = 20.0
t0 = 0.0
[outputs]
snapshot_every = 0.2
plots = false
"""
    path = tmp_path / "box.toml"
    path.write_text(text, encoding="utf-8")
    assert cli.main(["run", str(path), "-o", str(tmp_path / "out"), "-q"]) == 0
    pvd = tmp_path / "out" / "fluid.pvd"
    entries = ET.parse(pvd).getroot().find("Collection").findall("DataSet")
    times = [float(e.get("timestep")) for e in entries]
    assert times == pytest.approx([0.0, 0.2, 0.4, 0.6], abs=0.011)
    ds = results.load(tmp_path / "out" / "results.nc")
    for e, t in zip(entries, times, strict=True):
        m = meshio.read(tmp_path / "out" / e.get("file"))
        hexes = m.cells_dict["hexahedron"]
        assert hexes.shape == (16, 8)
        lo, hi = np.array([-0.208, -0.162, 0.0]), np.array([0.208, 0.162, 0.3])
        assert (m.points >= lo - 0.01).all() and (m.points <= hi + 0.01).all(), "tank frame"
        vols = np.array([_hex_volume(m.points[h]) for h in hexes])
        recorded = float(ds["volume"].sel(time=t, method="nearest"))
        # straight-edged hexahedra through the ANCF nodes of a box-shaped liquid: within 1 %
        assert vols.sum() == pytest.approx(recorded, rel=0.01), (t, vols.sum(), recorded)


# --- the settling phase (issue 19) ----------------------------------------------------------------


def _startup(w=340e3, cars=2, t_end=2.0, n=1001):
    """A fluid-vehicle-like run: each tank's vertical load released from zero overshoots to about
    1.7 x the weight (the start-up spike), then braking loads the tank longitudinally from 0.5 s."""
    t = np.linspace(0.0, t_end, n)
    f = np.zeros((n, cars, 3))
    f[:, :, 2] = (-w * (1 - np.exp(-t / 0.03) * np.cos(2 * np.pi * 50 * t)))[:, None]
    f[:, :, 0] = np.where(t > 0.5, 0.1 * w * np.sin(np.pi * (t - 0.5) / (t_end - 0.5)), 0.0)[:, None]
    return t, f


def test_settling_is_detected_from_the_liquid_vertical_load():
    t, f = _startup()
    ds = results.to_dataset({"t": t, "fluid_force_tank": f})
    s = results.settling(ds)
    # the envelope exp(-t/0.03) falls below 5 % at 0.09 s: the 0.1 s quiet window starts about there
    assert s.source == "detected" and 0.05 < s.time < 0.1
    assert "5%" in s.rule and results.settling_time(ds) == s.time == results.settling(ds).time  # deterministic
    part = results.after_settling(ds)
    assert float(part["time"][0]) >= s.time and float(part["time"][-1]) == 2.0
    # peaks and statistics leave the start-up spike out unless asked
    z_all = next(p for p in results.peaks(ds, include_settling=True) if p.component == "z")
    z = next(p for p in results.peaks(ds) if p.component == "z")
    assert z_all.value < -1.6 * 340e3 and z_all.time < 0.02
    assert abs(z.value) < 1.06 * 340e3 and z.time >= s.time and z.after == s.time
    x = next(p for p in results.peaks(ds) if p.component == "x")
    assert x.value == pytest.approx(0.1 * 340e3, rel=1e-3) and x.where == {"car": 1}
    st = {(r.name, r.component): r for r in results.statistics(ds)}
    assert st["fluid_force_tank", "z"].min > -1.06 * 340e3 and st["fluid_force_tank", "z"].after == s.time
    st_all = {(r.name, r.component): r for r in results.statistics(ds, include_settling=True)}
    assert st_all["fluid_force_tank", "z"].min < -1.6 * 340e3


def test_a_declared_or_settled_start_replaces_detection():
    t, f = _startup()
    ds = results.to_dataset({"t": t, "fluid_force_tank": f})
    ds.attrs["settle_time"] = 0.5
    assert results.settling(ds) == results.Settling(0.5, "declared", "declared: the scene's settling time 0.5 s")
    ds.attrs["settle_time"] = 99.0  # beyond the run: the whole run
    assert results.settling_time(ds) == 2.0
    ds.attrs["settle_time"] = -1.0
    with pytest.raises(ValueError, match="invalid attribute `settle_time`"):
        results.settling(ds)
    del ds.attrs["settle_time"]
    for flag in (1, "true", np.int8(1)):
        ds.attrs["settled_start"] = flag
        assert results.settling(ds).time == 0.0 and results.settling(ds).source == "settled start"
    ds.attrs["settled_start"] = 0
    assert results.settling(ds).source == "detected"


def test_runs_without_a_start_up_transient_have_no_settling():
    t = np.linspace(0.0, 1.0, 201)
    f = np.zeros((len(t), 3))
    f[:, 2] = -137.0 * (1 + 0.01 * np.sin(2 * np.pi * 3 * t))  # at rest from the start
    ds = results.to_dataset({"t": t, "force_tank": f})
    assert results.settling(ds).time == 0.0
    # no liquid (rigid lading): nothing to detect from, the run starts from its static equilibrium
    ds = results.to_dataset({"t": t, "coupler_force": np.ones((len(t), 1))})
    assert results.settling(ds) == results.Settling(0.0, "none", results.settling(ds).rule)


def test_an_excitation_before_the_liquid_has_settled_ends_settling_where_the_startup_is_quietest():
    t = np.linspace(0.0, 2.0, 2001)
    f = np.zeros((len(t), 3))
    f[:, 2] = -137.0 * (1 - np.exp(-t / 0.05) * np.cos(2 * np.pi * 40 * t))
    f[t >= 0.2, 2] -= 137.0 * 3 * np.sin(np.pi * (t[t >= 0.2] - 0.2) / 0.3) * (t[t >= 0.2] < 0.5)  # a bump at 0.2 s
    ds = results.to_dataset({"t": t, "force_tank": f})
    s = results.settling(ds)
    assert s.source == "detected" and "never stays within" in s.rule
    assert 0.05 < s.time < 0.2, "ends before the bump, after the start-up spike"


def test_extreme_finds_largest_smallest_and_largest_magnitude():
    t = np.linspace(0.0, 1.0, 11)
    c = np.stack([np.sin(2 * np.pi * t), -3 * t], axis=1)
    ds = results.to_dataset({"t": t, "coupler_force": c})
    da = ds["coupler_force"]
    lo, hi = results.extreme(da, mode="min"), results.extreme(da, mode="max")
    assert lo.value == pytest.approx(-3.0) and lo.where == {"coupler": 2} and lo.time == 1.0
    assert hi.value == pytest.approx(np.sin(2 * np.pi * 0.2)) and hi.time == pytest.approx(0.2)
    assert results.extreme(da, after=0.55).time == pytest.approx(1.0)
    with pytest.raises(ValueError, match="invalid `mode`"):
        results.extreme(da, mode="mean")


def test_loading_a_file_that_is_not_netcdf_is_a_clear_error(tmp_path):
    bad = tmp_path / "results.nc"
    bad.write_text("this is not netCDF\n")
    with pytest.raises(ValueError, match=r"invalid results file `.*results\.nc`: not a netCDF file"):
        results.load(bad)
    with pytest.raises(FileNotFoundError, match="no such file"):
        results.load(tmp_path / "missing.nc")
    with pytest.raises(FileNotFoundError, match="a directory"):
        results.load(tmp_path)


def test_a_run_or_scene_declares_its_settling_phase_through_to_dataset():
    t, f = _startup()
    ds = results.to_dataset({"t": t, "fluid_force_tank": f, "settle_time": 0.5})
    assert ds.attrs["settle_time"] == 0.5 and results.settling(ds).source == "declared"

    class Scene:
        kind, name, settle_time, settled_start = "fluid_vehicle", "declared", None, True

        def to_dict(self):
            return {}

    ds = results.to_dataset({"t": t, "fluid_force_tank": f}, Scene())
    assert ds.attrs["settled_start"] == 1 and results.settling(ds).time == 0.0


def test_a_declared_settle_time_comes_from_the_scene():
    """Issue 19: `[scene] settle_time` declares the settling phase; the Dataset carries it and the
    peaks leave it out (here on a short SwRI lane change)."""
    import tomllib
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "examples/scenes/swri_lane_change_20mph.toml"
    doc = tomllib.loads(path.read_text(encoding="utf-8"))
    doc["scene"]["settle_time"] = 0.2
    doc["solver"]["t_end"] = 0.4
    sc = scene.load_scene(doc)
    assert sc.settle_time == 0.2
    ds = results.to_dataset(scene.run_scene(sc), sc)
    s = results.settling(ds)
    assert ds.attrs["settle_time"] == 0.2 and s.time == 0.2 and s.source == "declared"
    doc["scene"]["settle_time"] = -1.0
    with pytest.raises(ValueError, match="invalid `scene.settle_time` = -1.0: expected a time from 0 to 600 s"):
        scene.load_scene(doc)
