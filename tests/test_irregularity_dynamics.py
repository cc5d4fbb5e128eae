"""Issue 20 dynamics on irregular track: where the liquid behaves as a rigid body (a nearly full
tank, excited vertically), the rigid-lading model and the equivalent slosh model give the same wheel
loads (the ride index and the cross-level findings are in docs/validation.md, "Track irregularities")."""

import dataclasses
from pathlib import Path

import numpy as np

from railslosh import irregularity, vehicle
from railslosh.scene import load_scene

ROOT = Path(__file__).resolve().parents[1]
TANGENT = [[0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [3000.0, 0.0, 0.0, 0.0, 0.0, 0.0]]


def test_rigid_and_equivalent_models_agree_in_wheel_load_rms_on_an_irregular_track_with_a_full_tank():
    """Light crude at fill 0.9 (the sloshing mass is 3 % of the liquid), 60 km/h on FRA class 5
    vertical profile (1-70 m wavelengths). The rigid lading carries the liquid's pitch and yaw inertia
    (``car.lading_length``) as the equivalent model's fixed masses do; with the lading as a point mass
    the two differed by 5-24 % per wheel (measured on a 2 km realization).

    The wheel-load RMS of a run over random track is an estimate whose scatter shrinks with the
    record length; the two models see the same track, and their ratio per wheel converges towards 1
    as the record grows (measured 2026-11-26 after the contact search fix, wheel loads from 2.5 s to
    the end): 6 s run 0.94-1.12, 12 s 0.96-1.10, 24 s 0.98-1.06, 40 s 0.981-1.044. Before that fix
    (its fall-back contact points damped the wheels spuriously) a 6 s run gave 0.990-1.042. The test
    uses 40 s."""
    sc = load_scene(ROOT / "examples/scenes/crude_curve_60kmh.toml")
    sc = dataclasses.replace(sc, fluid=dataclasses.replace(sc.fluid, fill=0.9), t_end=40.0)
    irr = irregularity.generate("fra", 5, length=900.0, start=sc.station + 30.0, taper=30.0, channels=["vertical"])
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


def test_the_empty_car_rides_within_sperlings_running_range_on_class_5_track_at_100_kmh():
    """Issue 20 (dynamics): the empty tank car driven at 100 km/h over FRA class 5 vertical profile
    (1-70 m, from 70 m with a 30 m taper, seed 1). Sperling's ride index Wz of the tank's vertical
    acceleration after 1.5 s must lie on the part of Sperling's scale where freight cars run: from
    3 ("satisfactory") to 4.5 ("not acceptable for running"); 4 is "still acceptable for running".
    Measured 2026-11-26: 4.03 (2.59 at 60 km/h). An empty freight car rides worse than a loaded
    one; this run had stopped at 3.48 s on a 2.1e-10 s step before ``Hht::step_toward`` took such
    remainders in one step, and the contact search's fall-back points had damped it to 3.39."""
    from railslosh import indicators

    v = 100 / 3.6
    irr = irregularity.generate("fra", 5, length=v * 8.0 + 100.0, start=70.0, taper=30.0, channels=["vertical"])
    res = vehicle.run(
        TANGENT, cars=1, station=50.0, speed=v, t_end=8.0, step=2e-3, record_every=0.005, drive=True, irregularity=irr
    )
    t = np.asarray(res["t"])
    a = np.asarray(res["car_acceleration"])[:, 0, :]
    m = t >= 1.5
    wz = indicators.sperling_wz(t[m], a[m, 2], "vertical")
    print(f"Wz vertical {wz:.3f}")
    assert 3.0 <= wz <= 4.5, wz
