"""Fuzzing of the scene parser (issue 8): raw and mutated TOML text, fluid-vehicle scenes and
prescribed-motion slosh scenes with random values at any depth. Every input either loads or
raises ``ValueError`` -- naming the dotted field for schema errors, or saying "invalid scene
TOML" for syntax errors -- never another exception type. (Vehicle-scene documents of random
structure are fuzzed in test_scene.py.)"""

import copy
import math
import re
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from railslosh import scene

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE_TEXTS = [p.read_text() for p in sorted((ROOT / "examples" / "scenes").glob("*.toml"))]

FLUID_BASE = {
    "track": {"preset": "tangent", "length": 2000.0},
    "train": {"cars": 1, "station": 300.0, "speed_kmh": 40.0, "t_end": 0.2, "step": 0.004},
    "brake": {"design": True, "design_v1_kmh": 5.0, "design_duration": 10.0, "scope": "all"},
    "fluid": {"oil": "custom", "model": "herschel-bulkley", "density": 900.0, "consistency": 0.5,
              "power_index": 0.8, "yield_stress": 5.0, "fill": 0.6},
    "mesh": {"counts": [6, 4, 2]},
    "tank": {"bulkheads": [[0.0, 0.01]]},
    "outputs": {"snapshot_every": 0.1, "netcdf": False, "vtu": False, "plots": False},
}  # fmt: skip

SLOSH_BASE = {
    "tank": {"shape": "box", "lower": [-0.208, -0.162, 0.0], "upper": [0.208, 0.162, 0.3]},
    "fluid": {"oil": "water", "fill": 0.44},
    "mesh": {"counts": [3, 6, 2]},
    "solver": {"t_end": 1.0, "step": 0.01, "frame": "inertial"},
    "maneuver": {"type": "pulse", "axis": "y", "acceleration": 2.9, "t0": 0.0, "t1": 0.5, "ramp": 0.01},
}

_FIELD = re.compile(r"^invalid `[^`]+`")

_scalars = (
    st.none()
    | st.booleans()
    | st.integers(min_value=-(10**30), max_value=10**30)
    | st.floats(allow_nan=True, allow_infinity=True)
    | st.floats(min_value=-10.0, max_value=1000.0)
    | st.sampled_from(["box", "cylinder", "elliptic", "pulse", "samples", "bump", "lane_change", "water", "custom"])
    | st.text(max_size=6)
)
_values = st.recursive(
    _scalars,
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=6), inner, max_size=3),
    max_leaves=10,
)


def _check(source) -> None:
    try:
        sc = scene.load_scene(source)
    except ValueError as exc:
        msg = str(exc)
        assert _FIELD.match(msg) or msg.startswith("invalid scene TOML"), msg
        assert "invalid parameter" not in msg and ": allowed" not in msg, msg  # one form (railslosh.limits)
    else:
        assert isinstance(sc, scene.Scene | scene.SloshScene)


def _leaf_paths(doc, prefix=()):
    """Every path to a value (tables, list items and scalars) in a nested doc."""
    if isinstance(doc, dict):
        for k, v in doc.items():
            yield (*prefix, k)
            yield from _leaf_paths(v, (*prefix, k))
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            yield (*prefix, i)
            yield from _leaf_paths(v, (*prefix, i))


def _set(doc, path, value):
    node = doc
    for p in path[:-1]:
        node = node[p]
    node[path[-1]] = value


def test_the_base_scenes_are_valid():
    assert isinstance(scene.load_scene(FLUID_BASE), scene.Scene)
    assert isinstance(scene.load_scene(SLOSH_BASE), scene.SloshScene)


@pytest.mark.parametrize("base", [FLUID_BASE, SLOSH_BASE], ids=["fluid_vehicle", "slosh"])
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_fuzz_any_value_at_any_depth(base, data):
    doc = copy.deepcopy(base)
    paths = list(_leaf_paths(doc))
    path = data.draw(st.sampled_from(paths))
    _set(doc, path, data.draw(_values))
    _check(doc)


@pytest.mark.parametrize("base", [FLUID_BASE, SLOSH_BASE], ids=["fluid_vehicle", "slosh"])
@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_fuzz_extra_and_missing_keys(base, data):
    doc = copy.deepcopy(base)
    section = data.draw(st.sampled_from(sorted(doc)))
    if data.draw(st.booleans()) and isinstance(doc[section], dict) and doc[section]:
        del doc[section][data.draw(st.sampled_from(sorted(doc[section])))]
    else:
        doc[section][data.draw(st.text(min_size=1, max_size=8))] = data.draw(_values)
    _check(doc)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(text=st.text(max_size=200))
def test_fuzz_random_toml_text(text):
    # Multi-line text is parsed as TOML (a single line could name a file).
    _check("\n" + text)


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_fuzz_mutated_example_toml_text(data):
    text = data.draw(st.sampled_from(EXAMPLE_TEXTS))
    for _ in range(data.draw(st.integers(1, 4))):
        i = data.draw(st.integers(0, len(text)))
        op = data.draw(st.sampled_from(["delete", "insert", "replace"]))
        piece = data.draw(st.sampled_from(["=", "[", "]", '"', "\n", "-", "1e400", "nan", "inf", ",", "x", "0"]))
        if op == "delete":
            text = text[:i] + text[i + data.draw(st.integers(1, 8)) :]
        elif op == "insert":
            text = text[:i] + piece + text[i:]
        else:
            text = text[:i] + piece + text[i + 1 :]
    _check(text)


@pytest.mark.parametrize(
    ("path", "value", "field"),
    [
        (("fluid", "fill"), 0.98, "fluid.fill"),  # limits.FILL: 0.03 to 0.97
        (("fluid", "fill"), math.nan, "fluid.fill"),
        (("mesh", "counts"), [6, 4, 0], "mesh.counts"),
        (("train", "step"), -1.0, "train.step"),
        (("fluid", "density"), math.inf, "fluid.density"),
    ],
)
def test_fluid_scene_errors_name_the_field(path, value, field):
    doc = copy.deepcopy(FLUID_BASE)
    _set(doc, path, value)
    with pytest.raises(ValueError, match=re.escape(f"`{field}")):
        scene.load_scene(doc)


def test_invalid_utf8_file_is_a_value_error(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_bytes(b"[track]\npreset = \xff\xfe\n")
    with pytest.raises(ValueError):  # UnicodeDecodeError is a ValueError
        scene.load_scene(p)
