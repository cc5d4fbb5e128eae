"""Issue 20 dynamics on irregular track: where the liquid behaves as a rigid body (a nearly full
tank, excited vertically), the rigid-lading model and the equivalent slosh model give the same wheel
loads (the ride index and the cross-level findings are in docs/validation.md, "Track irregularities")."""

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from railslosh import irregularity, vehicle
from railslosh.scene import load_scene

ROOT = Path(__file__).resolve().parents[1]
TANGENT = [[0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [3000.0, 0.0, 0.0, 0.0, 0.0, 0.0]]


@pytest.mark.xfail(
    strict=True,
    reason="open (issue 20): since the contact search fix (docs/validation.md, 'The contact point of a rolling "
    "wheel') the equivalent model's wheel-load RMS differs from the rigid lading's by -6 % (front bogie) and "
    "+10-12 % (rear bogie) at fill 0.9, and still by -4/+8 % at fill 0.97, where the sloshing mass is nearly "
    "zero: a pitch/bounce difference of the two models' fixed parts, not found yet",
)
def test_rigid_and_equivalent_models_agree_in_wheel_load_rms_on_an_irregular_track_with_a_full_tank():
    """Light crude at fill 0.9 (the sloshing mass is 3 % of the liquid), 60 km/h on FRA class 5
    vertical profile (1-70 m wavelengths). The rigid lading carries the liquid's pitch and yaw inertia
    (``car.lading_length``) as the equivalent model's fixed masses do; with the lading as a point mass
    the two differed by 5-24 % per wheel (measured on a 2 km realization). Measured here: ratios
    0.990-1.042 (6 s run, wheel loads over 2.5-6 s; over a 2-4 s window of a 4 s run they are
    1.01-1.07: the statistic needs the longer record)."""
    sc = load_scene(ROOT / "examples/scenes/crude_curve_60kmh.toml")
    sc = dataclasses.replace(sc, fluid=dataclasses.replace(sc.fluid, fill=0.9), t_end=6.0)
    irr = irregularity.generate("fra", 5, length=600.0, start=sc.station + 30.0, taper=30.0, channels=["vertical"])
    rigid = vehicle.run(TANGENT, **(sc.rigid_kwargs() | {"irregularity": irr}))
    equivalent = vehicle.run_equivalent(TANGENT, **(sc.equivalent_kwargs("lateral") | {"irregularity": irr}))
    m = np.asarray(rigid["t"]) >= 2.5
    np.testing.assert_allclose(rigid["t"], equivalent["t"], rtol=0, atol=1e-9)
    q_rigid = np.asarray(rigid["wheel_vertical"])[m].std(axis=0)
    q_equivalent = np.asarray(equivalent["wheel_vertical"])[m].std(axis=0)
    assert q_rigid.min() > 1e3, "the irregularity excites the wheel loads"
    ratio = q_equivalent / q_rigid
    print("equivalent / rigid wheel-load RMS per wheel:", np.round(ratio.ravel(), 4))
    assert np.all(np.abs(ratio - 1.0) < 0.05), ratio
