"""Parameter sweeps on Dask (issue 9): grid parsing, the scene field each grid name sets, and a
tiny sweep of cheap rigid-cargo runs on a LocalCluster whose every point equals the direct run."""

import numpy as np
import pytest

from railslosh import scene, sweep

ROOT = __import__("pathlib").Path(__file__).resolve().parents[1]
RIGID = ROOT / "examples/scenes/two_car_ecp_braking_rigid.toml"
SWRI = ROOT / "examples/scenes/swri_lane_change_20mph.toml"


def test_parse_grid_reads_toml_values():
    g = sweep.parse_grid(["oil=light,heavy", "fill=0.5,0.7", "bulkheads=0,2", "train.drive=true,false"])
    assert g == {"oil": ["light", "heavy"], "fill": [0.5, 0.7], "bulkheads": [0, 2], "train.drive": [True, False]}


@pytest.mark.parametrize("bad", ["oil", "=1,2", "oil=", "fill=0.5,0.5"])
def test_bad_grid_specs_are_value_errors(bad):
    with pytest.raises(ValueError, match="invalid `--grid"):
        sweep.parse_grid([bad])


def test_grid_names_set_the_documented_scene_fields():
    base = {"train": {}, "fluid": {}}
    over = sweep.grid_overrides(
        base, {"oil": "heavy", "fill": 0.7, "braking": "conventional", "speed": 60, "bulkheads": 2}
    )
    assert over["fluid"] == {"oil": "heavy", "fill": 0.7}
    assert over["brake"] == {"scope": "front"}
    assert over["train"] == {"speed": None, "speed_kmh": 60}
    # two bulkheads split the 11 m shell into thirds
    assert over["tank"]["bulkheads"] == [[pytest.approx(-11 / 6), 0.02], [pytest.approx(11 / 6), 0.02]]
    slosh = sweep.grid_overrides({"maneuver": {"speed_mph": 20}}, {"speed": 30})
    assert slosh["maneuver"] == {"speed": None, "speed_mph": None, "speed_kmh": 30}
    with pytest.raises(ValueError, match="invalid `braking`"):
        sweep.grid_overrides(base, {"braking": "hard"})
    with pytest.raises(ValueError, match="invalid `bulkheads`"):
        sweep.grid_overrides(base, {"bulkheads": 1.5})
    # issue 20: the track class of the irregularity and the liquid model are grid axes too
    track = sweep.grid_overrides(base, {"track_class": 3, "model": "pendulum"})
    assert track["track"] == {"irregularities": {"class": 3}}
    assert track["fluid"] == {"slosh_model": "pendulum"}


def test_a_bad_point_is_reported_before_anything_runs():
    with pytest.raises(ValueError, match=r"sweep point \{'speed': 500\}.*train.speed_kmh"):
        sweep.run_sweep(RIGID, {"speed": [20, 500]}, client=object())  # the client is never used


def test_tiny_sweep_on_a_local_cluster_equals_the_direct_runs():
    from dask.distributed import Client, LocalCluster

    over = {"train": {"t_end": 0.05}}
    grid = {"speed": [20, 40], "braking": ["ecp", "conventional"]}
    with (
        LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None) as cl,
        Client(cl) as c,
    ):
        done = []
        ds = sweep.run_sweep(RIGID, grid, overrides=over, client=c, on_done=lambda k, n: done.append((k, n)))
    assert done[-1] == (4, 4)
    assert ds.sizes["speed"] == 2 and ds.sizes["braking"] == 2 and ds.sizes["time"] == 6
    assert ds.attrs["sweep_dims"] == "speed,braking" and ds["speed"].attrs["units"] == "km/h"
    assert (ds["error"].values == "").all() and (ds["steps"].values > 0).all()
    for v in (20, 40):
        for b, scope in (("ecp", "all"), ("conventional", "front")):
            sc = scene.load_scene(RIGID, {"train": {"t_end": 0.05, "speed_kmh": v}, "brake": {"scope": scope}})
            res = scene.run_scene(sc)
            np.testing.assert_allclose(
                ds["coupler_force"].sel(speed=v, braking=b).values, res["coupler_force"], rtol=1e-9, atol=1e-9
            )
            np.testing.assert_allclose(ds["tank_speed"].sel(speed=v, braking=b).values, res["tank_speed"], rtol=1e-12)


def test_a_slosh_point_is_resampled_with_the_vehicle_load_filter():
    """Issue 19: a slosh run records every adaptive step; the sweep puts it on multiples of
    solver.step with its loads as hat-weighted means (the filter vehicle runs record loads with),
    says so, and keeps the other channels interpolated."""
    from railslosh import _core, results

    base = scene.read_scene(SWRI)
    over = {"solver": {"t_end": 0.3}}
    ds = sweep.run_point(base, over)
    assert "hat-weighted mean" in ds.attrs["resampling"] and "force_tank" in ds.attrs["resampling"]
    t = ds["time"].values
    np.testing.assert_allclose(np.diff(t), 0.01, atol=1e-12)
    sc = scene.load_scene(base, over)
    raw = results.to_dataset(scene.run_scene(sc), sc)
    expected = _core.hat_mean_resample(list(raw["time"].values), raw["force_tank"].values.tolist(), 0.01)
    np.testing.assert_allclose(ds["force_tank"].values, expected[: len(t)], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(ds["com_tank"].values, raw["com_tank"].interp(time=t).values, rtol=1e-12)
