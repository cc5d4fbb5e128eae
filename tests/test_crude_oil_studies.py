"""The coupled car-oil model from Python (issue 5): a fluid-carrying car run returning the oil's
centre of mass, fluid loads and snapshots, bad input, and the quick forms of the study cases
(coarse meshes, short runs; the full forms are in the long suite, `railslosh validate CASE`)."""

import numpy as np
import pytest

from railslosh import fluids, validate, vehicle

TANGENT = [[0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [3000.0, 0.0, 0.0, 0.0, 0.0, 0.0]]


def test_braking_car_surges_oil_forward_and_conserves_volume():
    times, torques = vehicle.design_brake_torque(64e3)
    assert torques[0] == 0.0 and torques[-1] > 5e3
    res = vehicle.run_fluid(
        TANGENT,
        speed=40 / 3.6,
        t_end=1.5,
        counts=(2, 2, 2),
        brake=(times, torques),
        snapshot_every=0.5,
        oil="light",
    )
    com = res["oil_com_tank"][:, 0, :]
    assert com.shape[1] == 3
    # Liquid below the tank axis, and it moves forward (+x) once the brakes act.
    assert (com[:, 2] < 0).all()
    assert com[-1, 0] > com[0, 0] + 0.01
    assert np.abs(res["volume_error"]).max() < 0.01
    assert res["tank_speed"][-1, 0] < 40 / 3.6
    assert len(res["snapshots"]) == 4
    t0, cars = res["snapshots"][0]
    assert cars[0].shape[1:] == (4, 3)
    # The fluid's load on the tank carries its weight (vertical, tank frame) once settled.
    fz = res["fluid_force_tank"][:, 0, 2]
    assert fz[10] == pytest.approx(-res["fluid_mass"] * 9.80665, rel=0.05)


def test_user_fluid_and_bad_input():
    water = fluids.water()
    res = vehicle.run_fluid(TANGENT, t_end=0.1, counts=(2, 2, 2), fluid=water)
    assert res["fluid_mass"] > 0
    with pytest.raises(ValueError, match="oil"):
        vehicle.run_fluid(TANGENT, oil="olive")
    with pytest.raises(ValueError, match="fill"):
        vehicle.run_fluid(TANGENT, fill=1.2)
    with pytest.raises(ValueError, match="brake_factors"):
        vehicle.run_fluid(TANGENT, cars=2, brake_factors=[1.0, -1.0], t_end=0.1, counts=(2, 2, 2))


@pytest.mark.parametrize(
    "case",
    ["ecp-braking-oils", "conventional-braking", "bulkhead-reduction", "curve-outward-inertia", "mesh-convergence"],
)
def test_quick_study_case_passes(case):
    records = validate.run([case], quick=True)
    assert records
    failed = [r for r in records if not r["passed"]]
    assert not failed, failed
