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
    res = rs.slosh.run(mesh, rs.fluids.water(depth=0.1), tank, rs.slosh.Motion(), t_end=0.05, h=0.01)
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
    with pytest.raises(ValueError, match="invalid parameter `connectivity`"):
        results.write_vtu(fluid_run, tmp_path, np.zeros((2, 4), dtype=int))
