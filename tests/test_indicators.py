"""The indicators users expect (issue 20 §2): ride (Sperling Wz, ISO 2631-1 weighted RMS),
derailment (Nadal, Weinstock, wheel unloading, the 50 ms duration rule), roll-over (load transfer
ratio) and load spectra (ASTM E1049 rainflow, damage-equivalent load, level crossings), checked
against the standards' worked examples and tables and against hand-computed answers; and
``add_indicators`` on a real vehicle run stores them with units."""

import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from railslosh import indicators, plots, results, scene

ROOT = Path(__file__).resolve().parents[1]


# --- load spectra --------------------------------------------------------------------------------

ASTM_E1049_FIG6 = [-2, 1, -3, 5, -1, 3, -4, 4, -2]
# ASTM E1049-85 Table 4 (rainflow counting of Fig. 6): range -> cycle counts; other ranges 0
ASTM_E1049_TABLE4 = {10: 0.0, 9: 0.5, 8: 1.0, 7: 0.0, 6: 0.5, 5: 0.0, 4: 1.5, 3: 0.5, 2: 0.0, 1: 0.0}


def test_rainflow_counts_the_astm_e1049_worked_example():
    ranges, means, counts = indicators.rainflow_cycles(ASTM_E1049_FIG6)
    total: dict[float, float] = {}
    for r, c in zip(ranges, counts, strict=True):
        total[float(r)] = total.get(float(r), 0.0) + float(c)
    assert total == {r: c for r, c in ASTM_E1049_TABLE4.items() if c}
    assert set(counts) <= {0.5, 1.0} and len(means) == len(ranges)
    # binned by range, one unit-wide bin per range 1..10: the table's column
    edges, hist = indicators.load_spectrum(ASTM_E1049_FIG6, bins=np.arange(0.5, 11.0, 1.0))
    assert list(hist) == [ASTM_E1049_TABLE4[r] for r in range(1, 11)]
    assert hist.sum() == 4.0
    # equal bins up to the largest range (9) keep every cycle
    edges, hist = indicators.load_spectrum(ASTM_E1049_FIG6, bins=3)
    assert edges[-1] == 9.0 and list(hist) == [0.0, 2.0, 2.0]


@pytest.mark.parametrize("m", [3.0, 5.0, 10.0])
def test_the_damage_equivalent_load_of_a_sine_is_its_amplitude(m):
    amplitude, cycles = 2.5e3, 10
    t = np.arange(cycles * 40 + 1) / 40.0  # 40 samples a period, starting and ending at a peak
    x = 7.0e3 + amplitude * np.cos(2 * np.pi * t)  # the mean does not matter
    assert indicators.damage_equivalent_load(x, m, cycles) == pytest.approx(amplitude, rel=1e-12)
    # the same damage spread over twice the cycles: amplitude × 2^(-1/m)
    assert indicators.damage_equivalent_load(x, m, 2 * cycles) == pytest.approx(amplitude * 0.5 ** (1 / m), rel=1e-12)


def test_level_crossings_count_upward_above_and_downward_below_the_reference():
    x = [0.0, 2.0, -2.0, 2.0, -2.0, 0.0]
    # level 1 (above the reference 0): rises 0 -> 2 and -2 -> 2; level -1: falls 2 -> -2 twice
    assert list(indicators.level_crossings(x, [-1.0, 1.0], reference=0.0)) == [2.0, 2.0]
    t = np.arange(0, 5.0, 0.01)
    sine = np.sin(2 * np.pi * t)  # 5 periods about the mean 0
    assert list(indicators.level_crossings(sine, [-0.5, 0.5, 1.5])) == [5.0, 5.0, 0.0]


# --- ride ----------------------------------------------------------------------------------------


def _sperling_closed_form(amplitude, f, direction):
    """Sperling's Wz = 0.896 (a³ F(f)/f)^(1/10) of one harmonic, a in cm/s² (Garg & Dukkipati 1984)."""
    if direction == "vertical":
        F = 0.325 * f**2 if f < 5.9 else (400.0 / f**2 if f < 20.0 else 1.0)
    else:
        F = 0.8 * f**2 if f < 5.4 else (650.0 / f**2 if f < 26.0 else 1.0)
    return 0.896 * ((100.0 * amplitude) ** 3 * F / f) ** 0.1


@pytest.mark.parametrize(
    ("direction", "f"),
    [("vertical", 1.0), ("vertical", 4.0), ("vertical", 8.0), ("vertical", 25.0), ("lateral", 2.0), ("lateral", 12.0)],
)
def test_sperling_of_a_sine_is_the_closed_form(direction, f):
    fs, duration, amplitude = 200.0, 10.0, 0.4
    t = np.arange(int(fs * duration)) / fs
    acc = amplitude * np.sin(2 * np.pi * f * t + 0.3)
    expected = _sperling_closed_form(amplitude, f, direction)
    assert indicators.sperling_wz(t, acc, direction) == pytest.approx(expected, rel=1e-2)


def test_sperling_sums_the_tenth_powers_of_the_components():
    t = np.arange(2000) / 200.0
    acc = 0.3 * np.sin(2 * np.pi * 1.5 * t) + 0.2 * np.sin(2 * np.pi * 7.0 * t)
    parts = [_sperling_closed_form(0.3, 1.5, "vertical"), _sperling_closed_form(0.2, 7.0, "vertical")]
    expected = (parts[0] ** 10 + parts[1] ** 10) ** 0.1
    assert indicators.sperling_wz(t, acc) == pytest.approx(expected, rel=1e-2)
    assert indicators.sperling_wz(t, acc) > max(parts)


# ISO 2631-1:1997 Table 3: weighting factors at the one-third-octave frequencies
@pytest.mark.parametrize(
    ("axis", "f", "factor"),
    [
        ("z", 1.0, 0.482),
        ("z", 2.0, 0.531),
        ("z", 4.0, 0.967),
        ("z", 8.0, 1.036),
        ("x", 0.5, 0.853),
        ("x", 1.0, 1.011),
        ("y", 2.0, 0.890),
    ],
)
def test_iso2631_weighted_rms_of_a_sine_is_the_tabulated_weighting(axis, f, factor):
    fs, duration, amplitude = 500.0, 20.0, 1.3
    t = np.arange(int(fs * duration)) / fs
    acc = amplitude * np.sin(2 * np.pi * f * t)
    rms = amplitude / math.sqrt(2)
    assert indicators.iso2631_weighted_rms(t, acc, axis) / rms == pytest.approx(factor, abs=5e-4)
    assert abs(indicators.iso2631_weighting(f, axis)) == pytest.approx(factor, abs=5e-4)


def test_iso2631_weighting_removes_a_constant_acceleration():
    t = np.arange(4000) / 200.0
    assert indicators.iso2631_weighted_rms(t, np.full(t.size, 9.81), "z") == pytest.approx(0.0, abs=1e-12)


def test_unevenly_sampled_accelerations_are_resampled():
    t = np.sort(np.concatenate([np.arange(2000) / 200.0, [3.0025, 7.0051]]))
    acc = 0.5 * np.sin(2 * np.pi * 4.0 * t)
    assert indicators.iso2631_weighted_rms(t, acc, "z") == pytest.approx(0.967 * 0.5 / math.sqrt(2), rel=2e-2)


# --- the load low-pass ---------------------------------------------------------------------------


def test_the_load_low_pass_keeps_the_slosh_band_and_removes_penalty_ringing():
    # unevenly spaced times, as an adaptive run records them (0.5 ms +- 30 %)
    rng = np.random.default_rng(3)
    t = np.arange(8001) * 5e-4
    t[1:-1] += rng.uniform(-1.5e-4, 1.5e-4, t.size - 2)
    slosh = 100.0 * np.sin(2 * np.pi * 1.4 * t)
    ringing = 40.0 * np.sin(2 * np.pi * 45.0 * t)
    grid, y = indicators.low_pass(t, slosh + ringing)
    assert grid[1] - grid[0] == pytest.approx(1.0 / (50 * indicators.LOAD_CUTOFF), rel=1e-3)
    inner = (grid > 0.5) & (grid < 3.5)
    # forward-backward 4th-order Butterworth: gain 1/(1 + (f/fc)^8) at 1.4 Hz and 45 Hz
    expected = 100.0 / (1 + (1.4 / 20) ** 8) * np.sin(2 * np.pi * 1.4 * grid)
    assert np.abs(y - expected)[inner].max() < 40.0 / (1 + (45 / 20) ** 8) + 0.05
    # the gain of the pair at the cut-off is 1/2
    grid, y = indicators.low_pass(t, np.sin(2 * np.pi * 20.0 * t))
    assert np.abs(y[inner]).max() == pytest.approx(0.5, rel=0.02)


def test_the_load_low_pass_has_zero_phase_and_filters_each_component():
    t = np.linspace(0.0, 1.0, 2001)
    pulse = np.exp(-(((t - 0.4) / 0.03) ** 2))
    grid, y = indicators.low_pass(t, np.column_stack([pulse, -2.0 * pulse]))
    assert y.shape == (grid.size, 2)
    assert grid[np.argmax(y[:, 0])] == pytest.approx(0.4, abs=1e-3)
    np.testing.assert_allclose(y[:, 1], -2.0 * y[:, 0], rtol=1e-12, atol=1e-12)
    # a constant load passes unchanged
    grid, y = indicators.low_pass(t, np.full(t.size, 137.3))
    np.testing.assert_allclose(y, 137.3, rtol=1e-9)


# --- derailment and roll-over --------------------------------------------------------------------


@pytest.mark.parametrize("angle", [70.0, 75.0])
def test_nadal_limit_is_the_formula(angle):
    tan, mu = math.tan(math.radians(angle)), 0.5
    assert indicators.nadal_limit(angle, mu) == pytest.approx((tan - mu) / (1 + mu * tan), abs=1e-9)
    # one implementation: the plots' limit is this one
    assert plots.nadal_limit is indicators.nadal_limit
    assert plots.L_OVER_V_LIMIT == indicators.L_OVER_V_LIMIT and plots.UNLOADING_LIMIT == indicators.UNLOADING_LIMIT


def test_weinstock_sums_the_absolute_l_over_v_of_an_axle():
    lv = np.array([[0.5, -0.3], [0.9, 0.7], [1.2, 0.0]])
    np.testing.assert_allclose(indicators.weinstock_sum(lv), [0.8, 1.6, 1.2])
    assert indicators.WEINSTOCK_LIMIT == 1.5


def test_load_transfer_ratio_of_a_group_of_wheels():
    q = np.array([[[40.0, 60.0], [30.0, 70.0]], [[0.0, 50.0], [0.0, 50.0]], [[50.0, 50.0], [50.0, 50.0]]])
    # (130 - 70)/200; the left side lifted off; balanced
    np.testing.assert_allclose(indicators.load_transfer_ratio(q), [0.3, 1.0, 0.0])


def test_wheel_unloading_against_the_static_load():
    np.testing.assert_allclose(indicators.wheel_unloading([30.0, 50.0, 80.0, 0.0], 50.0), [0.4, 0.0, -0.6, 1.0])


def test_the_50_ms_rule_keeps_exceedances_of_50_ms_or_longer():
    t = np.arange(31) * 0.01
    x = np.ones(t.size)
    x[5:10] = 2.0  # above 1.5 from 0.045 s to 0.095 s (crossings halfway between samples): 50 ms
    x[14:17] = 2.0  # 0.135 s to 0.165 s: 30 ms, too short
    np.testing.assert_allclose(indicators.exceedances(t, x, 1.5), [[0.045, 0.095]], atol=1e-12)
    assert indicators.time_over_limit(t, x, 1.5) == pytest.approx(0.05, abs=1e-12)
    assert indicators.time_over_limit(t, x, 1.5, min_duration=0.02) == pytest.approx(0.08, abs=1e-12)
    # crossing interpolated linearly: 1 -> 3 crosses 2.5 three quarters of the way
    y = np.ones(t.size)
    y[10:20] = 3.0
    np.testing.assert_allclose(indicators.exceedances(t, y, 2.5), [[0.0975, 0.1925]], atol=1e-12)
    # an exceedance at the start of the record starts there: 45 ms, ignored by the 50 ms rule
    z = np.ones(t.size)
    z[:5] = 2.0
    np.testing.assert_allclose(indicators.exceedances(t, z, 1.5, min_duration=0.0), [[0.0, 0.045]], atol=1e-12)
    assert indicators.time_over_limit(t, z, 1.5) == 0.0


# --- bad input -----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("call", "field"),
    [
        (lambda: indicators.sperling_wz(np.arange(100) / 100, np.zeros(100), "longitudinal"), "direction"),
        (lambda: indicators.iso2631_weighted_rms(np.arange(100) / 100, np.zeros(100), "w"), "axis"),
        (lambda: indicators.iso2631_weighted_rms(np.zeros(100), np.zeros(100)), "t"),
        (lambda: indicators.iso2631_weighted_rms(np.arange(100) / 100, np.zeros(99)), "acc"),
        (lambda: indicators.damage_equivalent_load([0.0, 1.0, 0.0], 0.0, 1.0), "wohler_exponent"),
        (lambda: indicators.damage_equivalent_load([0.0, 1.0, 0.0], 3.0, -1.0), "n_eq"),
        (lambda: indicators.load_spectrum([0.0, 1.0, 0.0], bins=0), "bins"),
        (lambda: indicators.nadal_limit(95.0), "flange_angle"),
        (lambda: indicators.nadal_limit(70.0, -0.1), "friction"),
        (lambda: indicators.wheel_unloading([1.0], 0.0), "q0"),
        (lambda: indicators.exceedances([0.0, 0.01, 0.02], [0.0, 1.0, 0.0], 0.5, min_duration=-1.0), "min_duration"),
        (lambda: indicators.load_transfer_ratio(np.ones((3, 3))), "wheel_vertical"),
        (lambda: indicators.low_pass([0.0, 0.1, 0.2], [1.0, 2.0, 3.0], cutoff=0.0), "cutoff"),
        (lambda: indicators.low_pass([0.0, 0.1, 0.2], [1.0, 2.0, 3.0], order=9), "order"),
        (lambda: indicators.low_pass([0.0, 0.1, 0.1], [1.0, 2.0, 3.0]), "t"),
        (lambda: indicators.low_pass([0.0, 0.1, 0.2], [1.0, 2.0]), "x"),
    ],
)
def test_bad_input_is_a_value_error_in_the_one_form(call, field):
    with pytest.raises(ValueError) as info:
        call()
    assert str(info.value).startswith(f"invalid `{field}` = ") and ": expected " in str(info.value)


# --- a results Dataset ---------------------------------------------------------------------------


def _synthetic_wheels():
    """One car, 4 wheelsets, 0.5 s sampled at 100 Hz, a declared settling phase of 0.1 s (45 kN
    wheel loads), then 50 kN on every wheel except: wheelset 1 left drops to 15 kN for
    0.2 ≤ t < 0.3 (ΔQ/Q₀ = 0.7); wheelset 2 has L/V 0.9 left and 0.8 right for 0.3 ≤ t < 0.36."""
    t = np.round(np.arange(51) * 0.01, 10)
    q = np.full((t.size, 4, 2), 50e3)
    q[t < 0.1] = 45e3
    q[(t >= 0.2) & (t < 0.3), 0, 0] = 15e3
    lv = np.full(q.shape, 0.1)
    lv[(t >= 0.3) & (t < 0.36), 1] = [0.9, 0.8]
    res = {"t": t, "wheel_vertical": q, "wheel_lateral": lv * q, "l_over_v": lv, "tank_station": t[:, None] * 10.0}
    ds = results.to_dataset(res)
    ds.attrs["settle_time"] = 0.1
    ds.attrs["static_wheel_load"] = 45e3
    return ds


def test_add_indicators_on_hand_computed_wheel_loads():
    ds = indicators.add_indicators(_synthetic_wheels())
    assert ds.attrs["indicators_after"] == pytest.approx(0.1)
    # Q₀ is each wheel's load at the end of the settling phase, not the static attribute
    np.testing.assert_allclose(ds["wheel_load_reference"].values, 50e3)
    assert "settling" in ds["wheel_load_reference"].attrs["source"]
    assert ds["unloading_max"].sel(wheelset=1, side="left") == pytest.approx(0.7)
    assert float(ds["unloading_max"].drop_sel(wheelset=1).max()) == pytest.approx(0.0)
    # above 0.6 from 0.19 + 6/7 × 0.01 s to 0.29 + 1/7 × 0.01 s
    assert ds["unloading_time_over_limit"].sel(wheelset=1, side="left") == pytest.approx(0.1 - 0.05 / 7, abs=1e-12)
    # Weinstock: 1.7 on axle 2 from 0.29 + 13/15 × 0.01 s to 0.35 + 2/15 × 0.01 s (> 50 ms)
    assert ds["weinstock_max"].values.tolist() == pytest.approx([0.2, 1.7, 0.2, 0.2])
    assert ds["weinstock_time_over_limit"].sel(wheelset=2) == pytest.approx(0.06 - 0.011 / 1.5, abs=1e-12)
    assert ds["weinstock_time_over_limit"].sel(wheelset=1) == 0.0
    # L/V 0.9 stays below Nadal's 0.947 (S1002, μ = 0.5)
    assert ds["l_over_v_max"].sel(wheelset=2, side="left") == pytest.approx(0.9)
    assert float(ds["l_over_v_time_over_limit"].max()) == 0.0
    assert ds["l_over_v_max"].attrs["limit"] == pytest.approx(indicators.nadal_limit(70.0))
    # LTR with wheelset 1 left at 15 kN: bogie 1 (100 - 65)/165, the car (200 - 165)/365
    assert ds["load_transfer_bogie_max"].values.tolist() == pytest.approx([35 / 165, 0.0], abs=1e-12)
    assert ds["load_transfer_car_max"].values.tolist() == pytest.approx([35 / 365], abs=1e-12)
    # no tank speed, no acceleration: no ride indicators, and it says so
    assert "sperling_wz" not in ds and "iso2631_weighted_rms" not in ds
    assert "ride" in ds.attrs["indicators_skipped"]


def test_add_indicators_rates_a_recorded_car_body_acceleration():
    t = np.arange(1000) / 100.0
    acc = np.zeros((t.size, 1, 3))
    acc[:, 0, 1] = 0.2 * np.sin(2 * np.pi * 1.0 * t)
    acc[:, 0, 2] = 0.5 * np.sin(2 * np.pi * 4.0 * t)
    ds = xr.Dataset(
        {indicators.ACCELERATION_VARIABLE: (("time", "car", "component"), acc, {"units": "m/s2"})},
        coords={"time": t, "car": [1], "component": ["x", "y", "z"]},
    )
    out = indicators.add_indicators(ds)
    assert out["sperling_wz"].sel(car=1, direction="vertical") == pytest.approx(indicators.sperling_wz(t, acc[:, 0, 2]))
    assert out["sperling_wz"].sel(car=1, direction="lateral") == pytest.approx(
        _sperling_closed_form(0.2, 1.0, "lateral"), rel=1e-2
    )
    assert out["iso2631_weighted_rms"].sel(car=1, iso_axis="z") == pytest.approx(0.967 * 0.5 / math.sqrt(2), abs=5e-4)
    assert out["iso2631_weighted_rms"].sel(car=1, iso_axis="x") == pytest.approx(0.0, abs=1e-12)
    assert out["iso2631_weighted_rms"].attrs["units"] == "m/s2"
    assert "ISO 2631-1" in out["iso2631_weighted_rms"].attrs["standard"]


@pytest.fixture(scope="module")
def braking():
    sc = scene.load_scene(ROOT / "examples/scenes/two_car_ecp_braking_rigid.toml", {"train": {"t_end": 0.4}})
    return results.to_dataset(scene.run_scene(sc), sc)


def test_add_indicators_on_a_vehicle_run_stores_variables_with_units(braking, tmp_path):
    ds = indicators.add_indicators(braking, wohler_exponent=5.0)
    new = [n for n in ds.data_vars if n not in braking.data_vars]
    expected = {
        "l_over_v_max",
        "l_over_v_time_over_limit",
        "weinstock",
        "weinstock_max",
        "weinstock_time_over_limit",
        "wheel_load_reference",
        "unloading_max",
        "unloading_time_over_limit",
        "load_transfer_bogie",
        "load_transfer_bogie_max",
        "load_transfer_car",
        "load_transfer_car_max",
        "coupler_force_rainflow",
        "coupler_force_del",
        "coupler_force_crossings",
        "wheel_vertical_rainflow",
        "wheel_vertical_del",
        "wheel_vertical_crossings",
        "iso2631_weighted_rms",
        "sperling_wz",
    }
    assert set(new) == expected
    for n in new:
        attrs = ds[n].attrs
        assert attrs["units"] and attrs["long_name"] and attrs["standard"], n
    assert ds["coupler_force_del"].attrs["units"] == "N" and ds["coupler_force_del"].attrs["wohler_exponent"] == 5.0
    assert ds["weinstock_time_over_limit"].attrs["units"] == "s"
    # the indicators are those of the run's own series
    np.testing.assert_allclose(ds["l_over_v_max"].values, braking["l_over_v"].max("time").values)
    np.testing.assert_allclose(ds["weinstock"].values, braking["l_over_v"].sum("side").values)
    np.testing.assert_allclose(ds["wheel_load_reference"].values, braking.attrs["static_wheel_load"])
    assert ds.sizes["bogie"] == 4 and np.all(np.abs(ds["load_transfer_bogie"].values) <= 1.0)
    # braking loads the coupler: every rainflow cycle is binned, and the DEL is that of its cycles
    ranges, _, counts = indicators.rainflow_cycles(braking["coupler_force"].sel(coupler=1).values)
    assert ds["coupler_force_rainflow"].sum() == pytest.approx(counts.sum())
    assert ds["coupler_force_del"].sel(coupler=1) == pytest.approx(
        indicators.damage_equivalent_load(braking["coupler_force"].sel(coupler=1).values, 5.0, 0.4)
    )
    assert float(ds["coupler_force_del"].sel(coupler=1)) > 0
    # the ride values come from the recorded car-body acceleration (every vehicle run records it)
    assert ds["iso2631_weighted_rms"].attrs["source"] == "car_acceleration"
    assert ds.sizes["iso_axis"] == 3 and ds["sperling_wz"].sizes["direction"] == 2
    assert "Sperling" not in ds.attrs.get("indicators_skipped", "")
    # without it, the longitudinal ride value is derived from the speed, and says so
    old = indicators.add_indicators(braking.drop_vars("car_acceleration"), wohler_exponent=5.0)
    assert "tank_speed" in old["iso2631_weighted_rms"].attrs["derived"]
    assert "Sperling" in old.attrs["indicators_skipped"]
    # a results file keeps them
    back = results.load(results.save(ds, tmp_path / "results.nc"))
    assert back["weinstock_max"].attrs["standard"] == ds["weinstock_max"].attrs["standard"]
    np.testing.assert_allclose(back["coupler_force_rainflow"].values, ds["coupler_force_rainflow"].values)


def test_add_indicators_rejects_bad_parameters(braking):
    for kwargs, field in (({"wohler_exponent": -3.0}, "wohler_exponent"), ({"bins": 0}, "bins")):
        with pytest.raises(ValueError, match=f"invalid `{field}`"):
            indicators.add_indicators(braking, **kwargs)
