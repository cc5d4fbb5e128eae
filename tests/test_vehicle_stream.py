"""Vehicle runs write their results incrementally (`stream=`), so an interrupted run loses
nothing already computed (issue 8)."""

from __future__ import annotations

import numpy as np
import pytest

from railslosh import vehicle

TRACK = [[0, 0, 0, 0, 0, 0], [4000, 0, 0, 0, 0, 0]]
BRAKE = vehicle.design_brake_torque(64e3)


def _rigid(**kw):
    return vehicle.run(TRACK, cars=2, speed=40 / 3.6, t_end=0.3, record_every=0.02, brake=BRAKE, **kw)


def test_rigid_stream_equals_the_returned_results_bit_for_bit(tmp_path):
    path = tmp_path / "run.jrnl"
    res = _rigid(stream=path)
    s = vehicle.read_stream(path)
    assert len(s["t"]) == len(res["t"]) > 10
    for key in ("t", "wheel_vertical", "wheel_lateral", "wheelset_lateral", "coupler_force", "tank_speed"):
        assert s[key].shape == res[key].shape, key
        assert np.array_equal(s[key], res[key]), key
    assert s["wheel_vertical"].shape[1:] == (8, 2) and s["coupler_force"].shape[1] == 1


def test_fluid_stream_carries_the_oil_outputs(tmp_path):
    path = tmp_path / "fluid.jrnl"
    res = vehicle.run_fluid(TRACK, cars=1, speed=40 / 3.6, t_end=0.1, counts=(2, 2, 2), oil="heavy", stream=path)
    s = vehicle.read_stream(path)
    for key in ("oil_com_tank", "fluid_force_tank", "volume_error", "wheel_vertical"):
        assert np.array_equal(s[key], res[key]), key


def test_interrupted_run_keeps_every_sample_already_computed(tmp_path):
    full = _rigid()
    path = tmp_path / "cut.jrnl"
    calls = []

    def stop(t, t_end, steps, newton, rejected):
        calls.append(t)
        if t > 0.15:
            raise KeyboardInterrupt("user stopped the run")

    with pytest.raises(KeyboardInterrupt):
        _rigid(stream=path, progress=stop)
    s = vehicle.read_stream(path)
    n = len(s["t"])
    assert 0 < n < len(full["t"])
    assert s["t"][-1] <= calls[-1] + 1e-12
    assert np.array_equal(s["t"], full["t"][:n])
    # the loads of the last sample are the hat mean over the part of its window run before the
    # stop (issue 16 §3); every earlier sample is final
    for key in ("wheel_vertical", "coupler_force"):
        assert np.array_equal(s[key][:-1], full[key][: n - 1]), key
    assert np.isfinite(s["coupler_force"][-1]).all()
    # a torn last row (the process killed while writing) is dropped, the rest reads back
    data = path.read_bytes()
    path.write_bytes(data[:-3])
    assert len(vehicle.read_stream(path)["t"]) == n - 1


def test_stream_errors_name_the_field(tmp_path):
    with pytest.raises(ValueError, match="stream"):
        _rigid(stream=tmp_path / "missing-dir" / "x.jrnl")
    bad = tmp_path / "bad.jrnl"
    bad.write_bytes(b"not a journal")
    with pytest.raises(ValueError, match="path"):
        vehicle.read_stream(bad)


def test_slosh_run_resumed_from_its_checkpoint_continues_bitwise(tmp_path):
    import railslosh as rs

    mesh = rs.mesh.box((0.416, 0.324, 0.132), (2, 3, 2), origin=(-0.208, -0.162, 0.0))
    tank = rs.slosh.TankGeometry.box((-0.208, -0.162, 0.0), (0.208, 0.162, 0.3))
    motion = rs.slosh.Motion().pulse("y", 0.3 * 9.81, 0.0, 0.3)
    water = rs.fluids.water(depth=0.132)
    ck = tmp_path / "run.ckpt"
    full = rs.slosh.run(mesh, water, tank, motion, t_end=0.6, step=0.004, checkpoint=ck, checkpoint_every=40)
    assert ck.stat().st_size > 0
    rest = rs.slosh.run(mesh, water, tank, motion, t_end=0.6, step=0.004, resume_from=ck)
    k = int(np.flatnonzero(full["t"] == rest["t"][0])[0])
    assert 0 < k < len(full["t"]) - 1
    assert len(rest["t"]) == len(full["t"]) - k
    # the checkpoint carries the energy account too (issue 18): energy error, input work and
    # the invariants go on as in the uninterrupted run
    assert ck.read_bytes()[:8] == b"RSLSLOCK"
    for key in (
        "t",
        "force_tank",
        "moment_tank",
        "com_tank",
        "volume",
        "kinetic_energy",
        "max_penetration",
        "input_work",
        "energy_error",
        "containment_gap",
        "min_volume_ratio",
    ):
        assert np.array_equal(rest[key], full[key][k:]), key
    assert rest["input_work"][0] != 0.0
    assert np.array_equal(rest["newton_iterations"][1:], full["newton_iterations"][k + 1 :])
    with pytest.raises(ValueError, match="resume_from"):
        rs.slosh.run(mesh, water, tank, motion, t_end=0.6, step=0.004, resume_from=tmp_path / "none.ckpt")
    with pytest.raises(ValueError, match="checkpoint_every"):
        rs.slosh.run(mesh, water, tank, motion, t_end=0.6, step=0.004, checkpoint=ck, checkpoint_every=0)


def test_explicit_slosh_run_resumed_from_its_checkpoint_continues_bitwise(tmp_path):
    """Issue 17: explicit runs write checkpoints too (counted in explicit steps), and a run
    resumed from one continues bit for bit; asking for the other stepper is refused."""
    import railslosh as rs

    mesh = rs.mesh.box((0.416, 0.324, 0.132), (2, 3, 2), origin=(-0.208, -0.162, 0.0))
    tank = rs.slosh.TankGeometry.box((-0.208, -0.162, 0.0), (0.208, 0.162, 0.3))
    motion = rs.slosh.Motion().pulse("y", 0.3 * rs.constants.GRAVITY, 0.0, 0.3)
    water = rs.fluids.water(depth=0.132)
    ck = tmp_path / "explicit.ckpt"
    kw = dict(t_end=0.12, step=0.004, stepper="explicit")
    full = rs.slosh.run(mesh, water, tank, motion, **kw, checkpoint=ck, checkpoint_every=400)
    assert ck.read_bytes()[:8] == b"RSLSLOCK"
    rest = rs.slosh.run(mesh, water, tank, motion, **kw, resume_from=ck)
    k = int(np.flatnonzero(full["t"] == rest["t"][0])[0])
    assert 0 < k < len(full["t"]) - 1
    for key in ("t", "force_tank", "moment_tank", "com_tank", "volume", "kinetic_energy", "input_work", "energy_error"):
        assert np.array_equal(rest[key], full[key][k:]), key
    with pytest.raises(ValueError, match="stepper"):
        rs.slosh.run(mesh, water, tank, motion, t_end=0.12, step=0.004, stepper="implicit", resume_from=ck)


def test_fluid_vehicle_runs_record_their_invariants_per_car_and_sample(tmp_path):
    """Issue 16 §1 for vehicle runs: every sample carries each car's containment gap, smallest
    volume ratio and energy growth (the last accepted step; at t = 0 the initial state, growth 0),
    in the results, the stream and the Dataset; the run's margins are their worst values or worse
    (margins cover every step, samples a subset)."""
    from railslosh import results

    path = tmp_path / "fluid.jrnl"
    res = vehicle.run_fluid(TRACK, cars=2, speed=40 / 3.6, t_end=0.2, counts=(2, 2, 2), stream=path)
    s = vehicle.read_stream(path)
    nt = len(res["t"])
    for key in ("containment_gap", "min_volume_ratio", "energy_error"):
        arr = np.asarray(res[key])
        assert arr.shape == (nt, 2) and np.all(np.isfinite(arr)), key
        assert np.array_equal(s[key], arr), key
    m = res["margins"]
    assert res["energy_error"][0].tolist() == [0.0, 0.0]
    assert 0.0 <= res["containment_gap"].max() <= m["worst_gap"] < m["gap_limit"]
    assert 1.0 >= res["min_volume_ratio"].min() >= m["min_volume_ratio"] > 0.9
    assert res["energy_error"].max() <= max(m["worst_energy_error"], 0.0) + 1e-12
    ds = results.to_dataset(res)
    assert ds["containment_gap"].dims == ("time", "car") and ds["containment_gap"].attrs["units"] == "m"
