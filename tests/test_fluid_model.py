"""The fluid model of a vehicle scene (issue 7, "skip what a scene doesn't need"): the automatic
choice between rigid lading, the equivalent pendulum model and the ANCF continuum, its record in
the results, the equivalent model's runs, and its lambda table against the Python Steklov solve."""

from pathlib import Path

import numpy as np
import pytest

from railslosh import _core, fluid_model, results, scene, vehicle
from railslosh.cosim.emulators import cylinder_lambda

ROOT = Path(__file__).resolve().parents[1]

BRAKING = {
    "track": {"preset": "tangent", "length": 4000.0},
    "train": {"cars": 2, "station": 300.0, "speed_kmh": 40.0, "t_end": 3.0, "step": 4e-3, "record_every": 0.02},
    "brake": {"design": True, "scope": "front"},
    "fluid": {"oil": "light", "fill": 0.5},
    "mesh": {"counts": [3, 2, 2]},
}
BULKHEADS = {**BRAKING, "tank": {"bulkheads": [[-1.8, 0.02], [1.8, 0.02]]}}
CURVE = {
    "track": {"preset": "table1"},
    "train": {"cars": 1, "station": 110.0, "speed_kmh": 100.0, "drive": True, "t_end": 2.0, "step": 4e-3},
    "fluid": {"oil": "light", "fill": 0.5},
}


def _with(doc, **sections):
    out = {k: dict(v) if isinstance(v, dict) else v for k, v in doc.items()}
    for k, v in sections.items():
        if v is None:
            out.pop(k, None)
        else:
            out[k] = {**out.get(k, {}), **v}
    return out


def _decide(doc):
    return fluid_model.decide(scene.load_scene(doc))


def test_irregular_track_with_alignment_or_cross_level_is_ancf():
    """Rule 3 (docs/user-guide.md, "Bogie model": on FRA class 5 track with all four channels the
    liquid moves the wheel-unloading, L/V and load-transfer extremes by -47 % to +84 % against rigid
    lading): a lateral channel or a twist defect picks ANCF; the vertical profile alone does not."""
    tangent = {"preset": "tangent", "length": 1500.0}
    irr = {"kind": "fra", "class": 5, "seed": 1, "start": 58.0, "taper": 5.0}
    base = _with(BRAKING, brake=None, train={"cars": 1, "station": 50.0})
    for channels, model in ((["vertical"], "rigid"), (["vertical", "cross_level"], "ancf"), (["alignment"], "ancf")):
        doc = _with(base, track={**tangent, "irregularities": {**irr, "channels": channels}})
        c = _decide(doc)
        assert c.model == model, (channels, c.reason)
        if model == "ancf":
            assert c.reason.startswith("irregular track with") and "84 %" in c.reason
    twist = {"kind": "perfect", "defects": [{"type": "twist", "start": 70.0, "base": 3.0, "cross_level": 0.01}]}
    assert _decide(_with(base, track={**tangent, "irregularities": twist})).model == "ancf"
    # a requested model is kept
    doc = _with(base, track={**tangent, "irregularities": irr}, fluid={"slosh_model": "rigid"})
    assert _decide(doc).model == "rigid"


def test_no_excitation_is_rigid():
    c = _decide(_with(BRAKING, brake=None))
    assert (c.model, c.axis, c.accel_x, c.accel_y) == ("rigid", None, 0.0, 0.0)
    assert "no axis excited" in c.reason
    # Curving at the balance speed (about 60 km/h on the 3-degree, 3 in curve) is within 0.1 m/s^2.
    c = _decide(_with(CURVE, train={"speed_kmh": 60.0}))
    assert c.model == "rigid" and c.accel_y < fluid_model.EXCITATION_THRESHOLD


def test_braking_with_bulkheads_is_a_longitudinal_pendulum():
    c = _decide(BULKHEADS)
    assert (c.model, c.axis) == ("pendulum", "longitudinal"), c.reason
    # The designed brake slows the loaded train from 40 to 5 km/h in 10 s: about 1 m/s^2 on the
    # front car alone, shared by two cars.
    assert 0.3 < c.accel_x < 0.8 and c.accel_y == 0.0 and 0.0 < c.rise_ratio <= 1.0


def test_braking_a_tank_without_bulkheads_is_nonlinear_hence_ancf():
    # The free surface of a 12 m tank rises (L/2) a/g x 2 > half of the 1.5 m depth under ECP braking.
    c = _decide(_with(BRAKING, brake={"scope": "all"}))
    assert c.model == "ancf" and c.rise_ratio > 1.0 and "nonlinear" in c.reason


def test_curving_above_balance_speed_is_a_lateral_pendulum():
    c = _decide(CURVE)
    assert (c.model, c.axis) == ("pendulum", "lateral"), c.reason
    v, kappa, e = 100 / 3.6, 1 / (5729.577951308232 / 3 * 0.3048), 3 * 0.0254
    assert c.accel_y == pytest.approx(v**2 * kappa - 9.80665 * e / 1.5, rel=1e-3)


def test_both_axes_or_snapshots_need_ancf():
    both = _with(CURVE, brake={"design": True}, train={"drive": False})
    c = _decide(both)
    assert c.model == "ancf" and "both axes" in c.reason
    c = _decide(_with(BULKHEADS, outputs={"snapshot_every": 0.5}))
    assert c.model == "ancf" and "snapshot" in c.reason


def test_a_requested_model_is_used():
    for model in ("ancf", "pendulum", "rigid"):
        c = _decide(_with(BRAKING, fluid={"slosh_model": model}))
        assert c.model == model and "requested" in c.reason
    assert _decide(_with(BRAKING, fluid={"slosh_model": "pendulum"})).axis == "longitudinal"
    sc = scene.load_scene(_with(BRAKING, fluid={"slosh_model": "pendulum"}))
    assert scene.load_scene(sc.to_dict()).fluid.slosh_model == "pendulum"  # round trip


@pytest.mark.parametrize("bad", ["pendulums", "ANCF", 3, True])
def test_an_invalid_slosh_model_names_the_field(bad):
    with pytest.raises(ValueError, match=r"invalid `fluid\.slosh_model`.*'auto', 'ancf', 'pendulum', 'rigid'"):
        scene.load_scene(_with(BRAKING, fluid={"slosh_model": bad}))


def test_the_paper_scenes_keep_the_ancf_model():
    for p in sorted((ROOT / "examples/scenes").glob("crude_*.toml")):
        assert fluid_model.choose_fluid_model(scene.load_scene(p))[0] == "ancf", p.stem


def test_a_pendulum_scene_runs_and_records_its_choice():
    sc = scene.load_scene(BULKHEADS, {"train": {"t_end": 0.2}})
    res = scene.run_scene(sc)
    assert res["fluid_model"] == "pendulum" and "longitudinal" in res["fluid_model_reason"]
    nt = len(res["t"])
    assert res["oil_com_tank"].shape == (nt, 2, 3) and res["slosh_displacement"].shape == (nt, 2, 3)
    model = res["equivalent_model"]
    # The liquid of the ANCF mesh: the full tank's less the two 20 mm bulkhead slabs (half-disks).
    slabs = 2 * 0.02 * np.pi * 1.5**2 / 2 * 850.0
    assert res["fluid_mass"] == pytest.approx(sc.fluid.mass(vehicle.tank_car_parameters()) - slabs, rel=1e-9)
    # At rest the liquid centre of mass is the model's centroid (tank frame, below the axis).
    np.testing.assert_allclose(res["oil_com_tank"][0, 0], model["centroid"], atol=1e-9)
    ds = results.to_dataset(res, sc)
    assert ds.attrs["fluid_model"] == "pendulum" and ds.attrs["fluid_model_reason"] == res["fluid_model_reason"]
    assert ds["slosh_displacement"].attrs["units"] == "m" and ds["oil_com_tank"].attrs["frame"] == "tank"


def test_a_rigid_scene_carries_the_liquid_as_lading():
    sc = scene.load_scene(_with(BRAKING, brake=None, train={"t_end": 0.05, "cars": 1}))
    res = scene.run_scene(sc)
    assert res["fluid_model"] == "rigid" and "oil_com_tank" not in res
    params = vehicle.tank_car_parameters()
    weight = (params["total_mass"] + sc.fluid.mass(params)) * 9.80665
    assert res["wheel_vertical"][-1].sum() == pytest.approx(weight, rel=0.01)


def test_run_equivalent_rejects_bad_parameters_by_name():
    track = [[0, 0, 0, 0, 0, 0], [500, 0, 0, 0, 0, 0]]
    with pytest.raises(ValueError, match="invalid `slosh_axis`"):
        vehicle.run_equivalent(track, slosh_axis="vertical")
    with pytest.raises(ValueError, match="invalid `fill`"):
        vehicle.run_equivalent(track, fill=1.5)
    with pytest.raises(ValueError, match="invalid `bulkheads"):
        vehicle.equivalent_model(0.5, bulkheads=[(9.0, 0.02)])
    with pytest.raises(ValueError, match="invalid `depth fraction"):
        _core.equivalent_lambda(0.99)


def test_rust_lambda_table_matches_the_python_steklov_solve_off_the_grid():
    for fill in (0.055, 0.137, 0.2345, 0.5, 0.6666, 0.777, 0.905, 0.945):
        rust, python = _core.equivalent_lambda(fill), cylinder_lambda(fill)
        assert rust == pytest.approx(python, rel=3e-3), fill
    assert _core.equivalent_lambda(0.5) == pytest.approx(1.3557, abs=2e-3)


def test_railslosh_run_prints_and_stores_the_choice(tmp_path, capsys):
    import json

    from railslosh.cli import main

    path = ROOT / "examples/scenes/crude_ecp_braking_light_bulkheads.toml"
    sets = ['fluid.slosh_model="pendulum"', "outputs.snapshot_every=0", "outputs.plots=false"]
    code = main(
        ["run", str(path), "-o", str(tmp_path), "--t-end", "0.1", "-q", *(a for s in sets for a in ("--set", s))]
    )
    assert code == 0
    out = capsys.readouterr().out
    assert "fluid model: pendulum (requested" in out
    summary = json.loads((tmp_path / "run.json").read_text())
    assert summary["fluid_model"] == "pendulum" and "requested" in summary["fluid_model_reason"]
    ds = results.load(tmp_path / "results.nc")
    assert ds.attrs["fluid_model"] == "pendulum" and ds.sizes["mode"] == 3


def test_an_equivalent_run_streams_its_slosh_columns(tmp_path):
    track = [[0, 0, 0, 0, 0, 0], [1000, 0, 0, 0, 0, 0]]
    kw = dict(cars=2, speed=10.0, t_end=0.1, bulkheads=[(0.0, 0.02)], slosh_axis="lateral")
    res = vehicle.run_equivalent(track, **kw, stream=tmp_path / "s.journal")
    back = vehicle.read_stream(tmp_path / "s.journal")
    np.testing.assert_array_equal(back["oil_com_tank"], res["oil_com_tank"])
    np.testing.assert_array_equal(back["slosh_displacement"], res["slosh_displacement"].reshape(len(res["t"]), -1))
    np.testing.assert_array_equal(back["coupler_force"], res["coupler_force"])
