"""Vehicle scene files (issue 4): the example scenes load and run, the track presets and US units
convert as documented, every schema error is a ValueError naming its dotted field, and random
input never raises anything else."""

import copy
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import railslosh
from railslosh import rail, scene

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples" / "scenes").glob("*.toml"))

BASE = {
    "track": {"preset": "tangent", "length": 1000.0},
    "train": {"cars": 2, "station": 200.0, "speed": 10.0, "t_end": 0.5},
    "brake": {"times": [0.0, 0.1], "torques": [0.0, 5000.0], "scope": "all"},
    "lading": {"mass": 36000.0, "height": -0.5},
    "car": {"wheelbase": 1.778, "wheel_profile": "s1002"},
}


def test_package_exports_scene():
    assert railslosh.scene is scene


def test_there_are_example_scenes():
    names = {p.name for p in EXAMPLES}
    assert {"two_car_ecp_braking_rigid.toml", "single_car_table1_curve_60kmh.toml"} <= names


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_example_scene_loads_and_runs_short(path):
    full = scene.load_scene(path)
    assert full.t_end <= 2.0, "example scenes are kept short"
    sc = scene.load_scene(path, {"train": {"t_end": 0.1}})
    assert sc.t_end == pytest.approx(0.1)
    res = scene.run_scene(sc)
    assert res["scene"] is sc
    nt = len(res["t"])
    assert res["t"][-1] == pytest.approx(0.1)
    assert res["wheel_vertical"].shape == (nt, 4 * sc.cars, 2)
    assert res["coupler_force"].shape == (nt, sc.cars - 1)
    assert np.isfinite(res["wheel_vertical"]).all()
    # Every wheel carries load (no wheel lifts off in these scenes).
    assert (res["wheel_vertical"][-1] > 0.5 * res["static_wheel_load"]).all()


def test_ecp_example_brakes_both_cars():
    sc = scene.load_scene(ROOT / "examples/scenes/two_car_ecp_braking_rigid.toml")
    assert sc.cars == 2 and sc.brake_scope == "all"
    assert sc.speed == pytest.approx(40 / 3.6)
    assert sc.brake_times == (0.0, 0.1, 0.3)
    assert sc.run_kwargs()["brake"] == ([0.0, 0.1, 0.3], [0.0, 0.0, 7000.0])


def test_table1_example_equals_preset_and_us_conversion():
    sc = scene.load_scene(ROOT / "examples/scenes/single_car_table1_curve_60kmh.toml")
    preset = scene.load_scene('[track]\npreset = "table1"\n')
    assert sc.track_source == "us_rows" and preset.track_source == "preset:table1"
    np.testing.assert_allclose(sc.track_rows, preset.track_rows, rtol=1e-15)
    # Same conversion as the US-unit track constructor of railslosh.rail.
    us = np.array(
        [[0, 0, 0], [100, 0, 0], [300, 3, 3], [600, 3, 3], [800, 0, 0], [1000, 0, 0]]
        + [[1200, -3, -3], [1500, -3, -3], [1700, 0, 0], [2800, 0, 0]],
        dtype=float,
    )
    track = rail.Track.from_us(us[:, 0], us[:, 1], us[:, 2], 0.0, 0.025, -0.025)
    np.testing.assert_allclose(np.asarray(sc.track_rows), track.table, rtol=1e-12, atol=1e-15)
    # 3-degree curve: R = 5729.58 ft / 3; the car starts inside it at 400 ft.
    assert 1 / sc.track().curvature(sc.station) == pytest.approx(5729.578 / 3 * 0.3048, rel=1e-6)
    assert sc.drive is True and sc.speed == pytest.approx(60 / 3.6)
    assert sc.wheel_profile == "aar1b" and sc.lading_mass == 36000.0


def test_si_rows_text_and_defaults():
    text = """
    [track]
    rows = [[0, 0, 0], [500, 0.001, 0.05, 0.0, 0.025, -0.025]]
    """
    sc = scene.load_scene(text)
    assert sc.track_rows[0] == (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    assert sc.track_rows[1] == (500.0, 0.001, 0.05, 0.0, 0.025, -0.025)
    assert (sc.cars, sc.station, sc.speed, sc.drive, sc.brake_times) == (1, 50.0, 0.0, False, None)
    assert sc.run_kwargs()["car"] is None


def test_dict_source_overrides_and_replace():
    sc = scene.load_scene(BASE)
    assert sc.car == {"wheelbase": 1.778}
    assert sc.replace(t_end=0.2).t_end == 0.2
    with pytest.raises(ValueError, match=r"`train\.speed`"):
        sc.replace(speed=500.0)
    over = scene.load_scene(BASE, {"train": {"speed_kmh": 36.0, "speed": None}, "car": {"friction": 0.4}})
    assert over.speed == pytest.approx(10.0) and over.car == {"wheelbase": 1.778, "friction": 0.4}


def _with(path: str, value):
    d = copy.deepcopy(BASE)
    keys = path.split(".")
    node = d
    for k in keys[:-1]:
        node = node.setdefault(k, {})
    if value is _DELETE:
        del node[keys[-1]]
    else:
        node[keys[-1]] = value
    return d


_DELETE = object()

BAD = [
    # (dotted path to change, new value, field the error must name)
    ("tracks", {"preset": "tangent"}, "tracks"),
    ("track", _DELETE, "track"),
    ("track", "tangent", "track"),
    ("track.preset", "table2", "track.preset"),
    ("track.rows", [[0, 0, 0], [1, 0, 0]], "track"),
    ("track.length", 10.0, "track.length"),
    ("track.lenght", 10.0, "track.lenght"),
    ("train.sped", 1.0, "train.sped"),
    ("train.speed", 250.0, "train.speed"),
    ("train.speed", "fast", "train.speed"),
    ("train.speed", True, "train.speed"),
    ("train.speed_kmh", 40.0, "train.speed"),
    ("train.cars", 0, "train.cars"),
    ("train.cars", 2.0, "train.cars"),
    ("train.station", 5.0, "train.station"),
    ("train.station", 990.0, "train.station"),
    ("train.t_end", 0.0, "train.t_end"),
    ("train.t_end", float("nan"), "train.t_end"),
    ("train.step", 0.1, "train.step"),
    ("train.record_every", 1e-5, "train.record_every"),
    ("train.drive", "yes", "train.drive"),
    ("train.wheelset_lateral_offset", 0.02, "train.wheelset_lateral_offset"),
    ("train.coupler_stiffness", -1.0, "train.coupler_stiffness"),
    ("train.coupler_damping", [1.0], "train.coupler_damping"),
    ("brake.scope", "middle", "brake.scope"),
    ("brake.times", [0.0, 0.0], "brake.times[1]"),
    ("brake.times", 0.5, "brake.times"),
    ("brake.torques", [0.0], "brake.torques"),
    ("brake.torques", [0.0, -1.0], "brake.torques[1]"),
    ("brake.torques", _DELETE, "brake.torques"),
    ("brake.force", 1.0, "brake.force"),
    ("lading.mass", -1.0, "lading.mass"),
    ("lading.height", 2.0, "lading.height"),
    ("lading.volume", 2.0, "lading.volume"),
    ("car.wheelbase", -1.0, "car.wheelbase"),
    ("car.wheelbase", 15.0, "car.wheelbase"),  # in range alone, but longer than truck_centers
    ("car.tank_axis_height", 1.0, "car.tank_axis_height"),  # below the tank radius
    ("car.friction", 1.5, "car.friction"),
    ("car.dof", 68, "car.dof"),
    ("car.total_mass", 1e5, "car.total_mass"),
    ("car.no_such_field", 1.0, "car.no_such_field"),
    ("car.wheel_profile", "s1003", "car.wheel_profile"),
    ("car.primary_kz", -5.0, "car.primary_kz"),
]


@pytest.mark.parametrize(("path", "value", "fieldname"), BAD, ids=[f"{b[0]}={b[1]!r}" for b in BAD])
def test_schema_errors_name_the_field(path, value, fieldname):
    with pytest.raises(ValueError, match=rf"invalid parameter `{re.escape(fieldname)}") as err:
        scene.load_scene(_with(path, value))
    assert "allowed" in str(err.value)


@pytest.mark.parametrize(
    ("text", "fieldname"),
    [
        ("[track]\nus_rows = [[0, 0, 0], [100, 45, 0]]\n", "track.us_rows[1][1] (degree_of_curvature)"),
        ("[track]\nrows = [[0, 0, 0], [-1, 0, 0]]\n", "track.rows[1][0] (s)"),
        ("[track]\nrows = [[0, 0], [1, 0]]\n", "track.rows[0]"),
        ("[track]\nrows = [[0, 0, 0]]\n", "track.rows"),
        ("[track]\nrows = [[0, 0, 0], [10, 0, 0]]\nus_rows = [[0, 0, 0], [10, 0, 0]]\n", "track"),
        ("[track]\nrows = [[0, 0, 0], [100, 0, 0.5]]\n", "track.rows[1][2] (superelevation)"),
    ],
)
def test_track_errors_name_the_field(text, fieldname):
    with pytest.raises(ValueError, match=rf"invalid parameter `{re.escape(fieldname)}`"):
        scene.load_scene(text)


def test_toml_syntax_error_is_a_value_error(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text("[track\npreset = 1\n")
    with pytest.raises(ValueError, match="invalid scene TOML"):
        scene.load_scene(p)
    with pytest.raises(ValueError, match="invalid scene TOML"):
        scene.load_scene("[track]\npreset = \n")


def test_missing_file_is_reported():
    with pytest.raises(FileNotFoundError):
        scene.load_scene("no/such/scene.toml")


# --- fuzzing: any parsed document either loads or raises ValueError naming a field -------------

_KEYS = sorted(
    {"preset", "rows", "us_rows", "length", "times", "torques", "scope", "mass", "height", "wheel_profile"}
    | set(scene._TRAIN_KEYS)
    | {"wheelbase", "friction", "tank_radius", "primary_kz", "coupler_reach", "dof"}
)
_scalars = (
    st.none()
    | st.booleans()
    | st.integers(min_value=-(10**30), max_value=10**30)
    | st.floats(allow_nan=True, allow_infinity=True)
    | st.floats(min_value=-100.0, max_value=3000.0)
    | st.sampled_from(["table1", "tangent", "all", "front", "s1002", "aar1b", ""])
    | st.text(max_size=5)
)
_values = st.recursive(
    _scalars,
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.sampled_from(_KEYS) | st.text(max_size=3), inner),
    max_leaves=12,
)
_sections = st.dictionaries(
    st.sampled_from(["track", "train", "brake", "lading", "car"]) | st.text(max_size=4),
    st.dictionaries(st.sampled_from(_KEYS) | st.text(max_size=4), _values, max_size=4) | _values,
    max_size=5,
)


def _check(doc):
    try:
        sc = scene.load_scene(doc)
    except ValueError as exc:
        msg = str(exc)
        assert msg.startswith("invalid parameter `") and "`" in msg[19:], msg
    else:
        assert isinstance(sc, scene.Scene)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_sections)
def test_fuzz_random_documents_raise_only_value_error(doc):
    _check(doc)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.sampled_from(["track", "train", "brake", "lading", "car"]),
    st.sampled_from(_KEYS) | st.text(max_size=4),
    _values,
)
def test_fuzz_one_field_of_a_valid_scene(section, key, value):
    doc = copy.deepcopy(BASE)
    doc[section][key] = value
    _check(doc)
