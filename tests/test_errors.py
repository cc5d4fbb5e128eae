"""Bad input gets a clear error naming the field; no Rust panic reaches Python."""

import re

import numpy as np
import pytest

import railslosh as rs
from railslosh import _core


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        (dict(fill=1.5), "fill"),
        (dict(fill=0.0), "fill"),
        (dict(radius=-1.0), "radius"),
        (dict(n_length=0), "n_length"),
        (dict(n_height=0), "n_height"),
        (dict(grading=0.0), "grading"),
        (dict(head_depth=-0.1), "head_depth"),
    ],
)
def test_invalid_mesh_parameters_name_the_field(kwargs, field):
    with pytest.raises(ValueError, match=field) as info:
        rs.mesh.cylinder_tank(**kwargs)
    # the fill is checked in Python (railslosh.limits, shared with scenes), the rest by the kernels:
    # both in the one form
    assert str(info.value).startswith(f"invalid `{field}` = ") and ": expected " in str(info.value)


@pytest.mark.parametrize(
    ("args", "kwargs", "field"),
    [
        ((-850.0, "newtonian"), dict(viscosity=1.0, bulk_penalty=1e6), "density"),
        ((850.0, "newtonian"), dict(viscosity=-1.0, bulk_penalty=1e6), "viscosity"),
        ((850.0, "bingham"), dict(viscosity=1.0, yield_stress=-3.0, bulk_penalty=1e6), "yield_stress"),
        ((850.0, "herschel-bulkley"), dict(consistency=1.0, power_index=-1.0, bulk_penalty=1e6), "power_index"),
        (
            (850.0, "oldroyd"),
            dict(viscosity=1.0, yield_stress=1.0, elastic_modulus=0.0, bulk_penalty=1e6),
            "elastic_modulus",
        ),
        ((850.0, "newtonian"), dict(viscosity=1.0, bulk_penalty=-1.0), "bulk_penalty"),
        ((850.0, "maxwell"), dict(bulk_penalty=1.0), "model"),
    ],
)
def test_invalid_fluid_parameters_name_the_field(args, kwargs, field):
    with pytest.raises(ValueError, match=field):
        rs.Fluid(*args, **kwargs)


def test_zero_elements_and_bad_quadrature_are_rejected():
    with pytest.raises(ValueError, match="n_x"):
        rs.mesh.box((1.0, 1.0, 1.0), (0, 1, 1))
    mesh = rs.mesh.box((1.0, 1.0, 1.0), (1, 1, 1))
    with pytest.raises(ValueError, match="quadrature.viscous"):
        rs.FluidBody(mesh, rs.fluids.water(), viscous_points=2)


def test_wrong_array_length_names_the_argument():
    body = rs.FluidBody(rs.mesh.box((1.0, 1.0, 1.0), (1, 1, 1)), rs.fluids.water())
    with pytest.raises(ValueError, match="`e`"):
        body.internal_forces(np.zeros(5), np.zeros(96))
    with pytest.raises(ValueError, match="index"):
        body.element_tangent(3, np.zeros(96), np.zeros(96))


def test_inverted_element_is_a_railslosh_error_naming_the_element():
    body = rs.FluidBody(rs.mesh.box((1.0, 1.0, 1.0), (2, 1, 1)), rs.fluids.water())
    e = body.reference_coordinates().reshape(-1, 3) * np.array([-1.0, 1.0, 1.0])
    with pytest.raises(rs.RailsloshError, match="element 0 inverted"):
        body.internal_forces(e.ravel(), np.zeros(e.size))


def test_a_rust_panic_becomes_a_railslosh_error():
    with pytest.raises(rs.RailsloshError, match="internal error"):
        _core._panic_for_test()


# --- scene and API input errors: one form, did-you-mean, files said as such (issue 19) ----------

from pathlib import Path  # noqa: E402

from railslosh import limits, scene, vehicle  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SLOSH = {
    "tank": {"shape": "elliptic"},
    "fluid": {"oil": "water", "fill": 0.5},
    "mesh": {"counts": [1, 2, 2]},
    "solver": {"t_end": 1.0, "step": 0.01},
    "maneuver": {"type": "lane_change", "speed_mph": 20.0},
}


def _message(source, overrides=None) -> str:
    with pytest.raises(ValueError) as info:
        scene.load_scene(source, overrides)
    return str(info.value)


def test_one_message_template():
    assert _message(SLOSH, {"solver": {"t_end": -1.0}}) == (
        "invalid `solver.t_end` = -1.0: expected a time > 0 s and ≤ 600 s"
    )
    msg = _message(SLOSH, {"solver": {"step": 2.0}})
    assert msg == "invalid `solver.step` = 2.0: expected a time step from 1e-05 to 0.05 s (≤ solver.t_end)"
    msg = _message(ROOT / "examples/scenes/crude_curve_60kmh.toml", {"train": {"speed_kmh": 500}})
    assert msg == "invalid `train.speed_kmh` = 500: expected a speed from 0 to 252 km/h"


def test_the_awkward_messages_read_plainly():
    msg = _message(SLOSH, {"outputs": {"vtu": 3}})
    assert msg.startswith("invalid `outputs.vtu` = 3: expected"), msg
    msg = _message(SLOSH, {"maneuver": {"speed_mph": 0.0}})
    assert msg == "invalid `maneuver.speed_mph` = 0.0: expected a speed > 0 mph and ≤ 156.586 mph"
    for over in ({"solver": {"t_end": 0.0}}, {"outputs": {"vtu": 3}}, {"tank": {"radius": 1.0}}):
        msg = _message(SLOSH, over)
        assert "allowed" not in msg and "more than" not in msg and "not in a slosh" not in msg, msg


@pytest.mark.parametrize(
    ("section", "typo", "suggestion"),
    [("manuever", "type", "maneuver"), ("solvr", "t_end", "solver"), ("Tank", "shape", "tank")],
)
def test_an_unknown_section_is_named_with_the_closest_name(section, typo, suggestion):
    doc = {k: v for k, v in SLOSH.items() if k != suggestion}
    doc[section] = SLOSH[suggestion]
    msg = _message(doc)
    assert msg.startswith(f"invalid `{section}`: unknown section (did you mean `{suggestion}`?); expected one of")


def test_a_misspelled_maneuver_is_blamed_whatever_the_order_of_the_sections():
    for text in ('[solver]\nt_end = 1.0\n[manuever]\ntype = "pulse"\n', '[manuever]\ntype = "pulse"\n[solver]\n'):
        assert "invalid `manuever`: unknown section (did you mean `maneuver`?)" in _message(text)


def test_an_unknown_key_is_named_with_the_closest_key_and_a_misplaced_one_says_where_it_belongs():
    msg = _message(SLOSH, {"maneuver": {"ofset": 3.0}})
    assert msg.startswith("invalid `maneuver.ofset`: unknown key (did you mean `maneuver.offset`?)")
    msg = _message(SLOSH, {"maneuver": {"height": 0.1}})  # a bump's key in a lane change
    assert msg.startswith("invalid `maneuver.height` = 0.1: expected no `maneuver.height` with type = 'lane_change'")
    msg = _message({**SLOSH, "track": {"preset": "tangent"}})
    assert msg.startswith("invalid `track`: expected one of the sections of a slosh scene")
    assert "[track] belongs to vehicle scenes" in msg


def test_empty_missing_and_directory_scenes_are_said_as_such(tmp_path):
    (tmp_path / "empty.toml").write_text("")
    assert "the file is empty (no sections)" in _message(tmp_path / "empty.toml")
    assert _message({}).startswith("invalid `scene` = {}: expected a vehicle scene")
    assert "the text is empty (no sections)" in _message("\n# only a comment\n")
    with pytest.raises(FileNotFoundError, match="no such file"):
        scene.load_scene(tmp_path / "missing.toml")
    with pytest.raises(FileNotFoundError, match="no such file"):
        scene.load_scene(str(tmp_path / "missing"))  # a path without .toml is not TOML text
    with pytest.raises(IsADirectoryError, match="a directory; expected a scene file"):
        scene.load_scene(tmp_path)


def test_scenes_and_the_api_share_the_fill_limits():
    lo, hi = limits.FILL.lo, limits.FILL.hi
    assert (lo, hi) == (0.03, 0.97)
    expected = f"expected {limits.FILL.expected()}"
    for fill in (lo, hi):
        assert scene.load_scene(SLOSH, {"fluid": {"fill": fill}}).fluid.fill == fill
        assert rs.mesh.cylinder_tank(fill=fill, n_length=2, n_width=2, n_height=1).n_elements == 4
        assert rs.mesh.elliptic_cylinder(fill=fill, n_length=1, n_width=2, n_height=1).n_elements == 2
        assert vehicle.equivalent_model(fill)["mass"] > 0
    track = [[0, 0, 0, 0, 0, 0], [500, 0, 0, 0, 0, 0]]
    for fill in (0.02, 0.98, float("nan"), True):
        assert expected in _message(SLOSH, {"fluid": {"fill": fill}})
        for call, kwargs in (
            (rs.mesh.cylinder_tank, {}),
            (rs.mesh.elliptic_cylinder, {}),
            (vehicle.equivalent_model, {}),
            (vehicle.run_fluid, {"track": track}),
            (vehicle.run_equivalent, {"track": track}),
        ):
            with pytest.raises(ValueError, match=f"invalid `fill` = .*: {expected}"):
                call(fill=fill, **kwargs)


def test_kernel_messages_are_in_the_one_form():
    with pytest.raises(ValueError) as info:
        rs.fluids.newtonian(1000.0, -1.0)
    assert str(info.value) == "invalid `viscosity` = -1: expected a finite number >= 0"
    # a car the kernels reject (in range alone, longer than the truck centres) names the scene field
    msg = _message({"track": {"preset": "tangent"}, "car": {"wheelbase": 15.0}})
    assert msg == "invalid `car.wheelbase` = 15: expected below truck_centers"


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: rs.vehicle.run([[0.0] * 6, [3000.0] + [0.0] * 5], t_end="abc"), "invalid `t_end` = 'abc': "),
        (lambda: rs.vehicle.run([[0.0] * 6, [3000.0] + [0.0] * 5], cars="two"), "invalid `cars` = 'two': "),
        (lambda: _core.default_bulk_penalty(density="heavy", depth=1.0), "invalid `density` = 'heavy': "),
    ],
)
def test_a_wrongly_typed_argument_of_a_compiled_function_is_named_in_the_message(call, message):
    # PyO3 names the argument only in an exception note, which str(error) and one-line CLI errors drop
    with pytest.raises(TypeError) as info:
        call()
    assert str(info.value).startswith(message), str(info.value)


def test_the_run_kernels_take_one_train_dict_and_name_a_bad_key_in_it():
    # issue 18: the three vehicle runs take one `train` dict (and a `cargo` dict), read key by
    # key in the binding; a misspelt key is refused by name instead of silently left at its default
    track = [[0.0] * 6, [3000.0] + [0.0] * 5]
    train = {"track": track, "station": 300.0, "speed": 0.0, "t_end": 0.01}
    with pytest.raises(ValueError, match=r"invalid `train` = stepp: expected keys among \[.*\"step\""):
        _core.run_train({**train, "stepp": 1e-3})
    with pytest.raises(ValueError, match=r"invalid `train.t_end` = missing"):
        _core.run_train({k: v for k, v in train.items() if k != "t_end"})
    with pytest.raises(TypeError, match=r"invalid `record_every` = 'fast': "):
        _core.run_train({**train, "record_every": "fast"})
    with pytest.raises(ValueError, match=r"invalid `cargo` = oill: expected keys among \[.*\"oil\""):
        _core.run_fluid_train(train, {"fill": 0.5, "oill": "heavy"})
    with pytest.raises(ValueError, match=r"invalid `cargo` = axis: expected keys among \[.*\"slosh_axis\""):
        _core.run_equivalent_train(train, {"fill": 0.5, "axis": "lateral"})
    with pytest.raises(ValueError, match=r"invalid `cargo.fill` = missing"):
        _core.run_equivalent_train(train, {})
    # left-out keys take the Rust scenario's defaults: 1 car, 1 ms steps (10 steps to 0.01 s)
    res = _core.run_train(train)
    assert res["stats"]["steps"] == 10
    assert np.asarray(res["wheel_vertical"]).shape[1] == 4


def test_the_slosh_kernel_takes_one_scenario_dict_and_names_a_bad_key_in_it():
    m = rs.mesh.box((1.0, 0.4, 0.3), (1, 1, 1))
    fluid = rs.fluids.newtonian(1000.0, 1e-3, depth=0.3)
    scenario = {"tank_shape": "box", "tank_dims": [-0.5, -0.2, 0.0, 0.5, 0.2, 0.6], "t_end": 0.01, "step": 0.005}
    with pytest.raises(ValueError, match=r"invalid `scenario` = stepsize: expected keys among \[.*\"step\""):
        _core.run_slosh(m, fluid, {**scenario, "stepsize": 1e-3})
    with pytest.raises(ValueError, match=r"invalid `scenario.step` = missing"):
        _core.run_slosh(m, fluid, {k: v for k, v in scenario.items() if k != "step"})
    with pytest.raises(TypeError, match=r"invalid `viscous_points` = 'three': "):
        _core.run_slosh(m, fluid, {**scenario, "viscous_points": "three"})
    # left-out keys take SloshScenario::new's defaults (at rest under gravity); every step recorded
    res = _core.run_slosh(m, fluid, scenario)
    assert res["error"] is None
    assert res["t"][-1] == pytest.approx(0.01)
    assert np.all(np.diff(res["t"]) <= 0.005 + 1e-12)


def test_a_wrongly_typed_number_of_the_fluid_constructor_is_named_in_the_message():
    # PyO3 names a constructor's argument only in an exception note; the Fluid constructor, which
    # every railslosh.fluids function calls, names it in the message itself
    with pytest.raises(TypeError) as info:
        rs.fluids.newtonian(1000.0, "thin")
    assert str(info.value).startswith("invalid `viscosity` = 'thin': "), str(info.value)
    with pytest.raises(TypeError, match=r"^invalid `density` = 'heavy': "):
        rs.Fluid("heavy", "newtonian", viscosity=1e-3, bulk_penalty=1e6)
    with pytest.raises(TypeError, match=r"^invalid `elastic_modulus` = 'stiff': "):
        rs.Fluid(870.0, "oldroyd", viscosity=1.0, yield_stress=1.0, elastic_modulus="stiff", bulk_penalty=1e6)
    # optional numbers still take None as not given
    assert rs.Fluid(870.0, "oldroyd", viscosity=1.0, yield_stress=1.0, elastic_modulus=None, bulk_penalty=1e6)


def test_every_class_constructor_names_a_bad_argument_in_the_message():
    # issue 18: FluidBody, SloshParticipant and Track read each argument by name, as Fluid does: a
    # wrong type is a TypeError, a value the type cannot hold (a negative count, a point of two
    # coordinates) a ValueError, each naming the argument and its value
    mesh = rs.mesh.box((0.4, 0.3, 0.1), (2, 2, 1))
    water = rs.fluids.water(depth=0.1)
    with pytest.raises(TypeError, match=r"^invalid `viscous_points` = '3': "):
        rs.FluidBody(mesh, water, viscous_points="3")
    with pytest.raises(ValueError, match=r"^invalid `mass_points` = -1: expected a non-negative integer"):
        rs.FluidBody(mesh, water, mass_points=-1)
    box = [0.0, 0.0, 0.0, 0.4, 0.3, 0.2]
    with pytest.raises(TypeError, match=r"^invalid `h_max` = 'x': "):
        _core.SloshParticipant(mesh, water, "box", box, h_max="x")
    with pytest.raises(TypeError, match=r"^invalid `tank_dims` = 'abc': "):
        _core.SloshParticipant(mesh, water, "box", "abc")
    with pytest.raises(ValueError, match=r"^invalid `reference_point` = \[1, 2\]: expected a sequence of length 3"):
        _core.SloshParticipant(mesh, water, "box", box, reference_point=[1, 2])
    with pytest.raises(ValueError, match=r"^invalid `penalty_points` = -2: expected a non-negative integer"):
        _core.SloshParticipant(mesh, water, "box", box, penalty_points=-2)
    tangent = {"curvature": [0.0, 0.0], "superelevation": [0.0, 0.0]}
    with pytest.raises(TypeError, match=r"^invalid `gauge` = 'wide': "):
        rs.rail.Track([0.0, 100.0], **tangent, gauge="wide")
    with pytest.raises(ValueError, match=r"^invalid `origin` = \(0, 0\): expected a sequence of length 3"):
        rs.rail.Track([0.0, 100.0], **tangent, origin=(0, 0))
    # what each reads well still builds: an integer gauge, a list origin, the default quadrature
    assert rs.rail.Track([0.0, 100.0], **tangent, gauge=1, origin=[1, 2, 3]) is not None
    assert rs.FluidBody(mesh, water).n_coords > 0


def test_a_compiled_function_names_a_negative_count_and_a_short_point():
    # a negative count (PyO3's OverflowError) and a point of the wrong length (ValueError) carry
    # PyO3's note like a wrong type does; the wrapper names the argument for them too
    with pytest.raises(ValueError, match=r"^invalid `n_length` = -3: expected a non-negative integer"):
        _core.elliptic_cylinder(12.0, 1.5, 1.5, 0.5, n_length=-3, n_width=2, n_height=2)
    with pytest.raises(ValueError, match=r"^invalid `n_length`: expected a non-negative integer"):
        _core.elliptic_cylinder(12.0, 1.5, 1.5, 0.5, -3, 2, 2)


def _keys_the_binding_reads(call) -> set[str]:
    """The keys a kernel's dict may hold, from the binding's message for an unknown key."""
    with pytest.raises(ValueError, match=r"expected keys among \[") as info:
        call()
    listed = re.search(r"expected keys among \[(.*)\]", str(info.value)).group(1)
    return set(re.findall(r'"([a-z_]+)"', listed))


def test_the_kernel_argument_types_list_exactly_the_keys_the_binding_reads():
    # issue 18: the typed dicts are defined once (railslosh.kernel_args, imported by the stub);
    # a key the binding gains or drops without the type (or the other way round) fails here
    from railslosh import kernel_args

    def keys(cls) -> set[str]:
        return set(cls.__required_keys__) | set(cls.__optional_keys__)

    train = {"track": [[0.0] * 6, [3000.0] + [0.0] * 5], "station": 300.0, "speed": 0.0, "t_end": 0.01}
    assert _keys_the_binding_reads(lambda: _core.run_train({**train, "_x": 0})) == keys(kernel_args.TrainArgs)
    fluid_cargo = _keys_the_binding_reads(lambda: _core.run_fluid_train(train, {"fill": 0.5, "_x": 0}))
    assert fluid_cargo == keys(kernel_args.FluidCargoArgs)
    equivalent_cargo = _keys_the_binding_reads(lambda: _core.run_equivalent_train(train, {"fill": 0.5, "_x": 0}))
    assert equivalent_cargo == keys(kernel_args.EquivalentCargoArgs)
    m = rs.mesh.box((1.0, 0.4, 0.3), (1, 1, 1))
    fluid = rs.fluids.newtonian(1000.0, 1e-3, depth=0.3)
    scenario = {"tank_shape": "box", "tank_dims": [-0.5, -0.2, 0.0, 0.5, 0.2, 0.6], "t_end": 0.01, "step": 0.005}
    assert _keys_the_binding_reads(lambda: _core.run_slosh(m, fluid, {**scenario, "_x": 0})) == keys(
        kernel_args.SloshArgs
    )
    # the required keys are the ones the binding reports missing
    assert kernel_args.TrainArgs.__required_keys__ == {"track", "station", "speed", "t_end"}
    assert kernel_args.SloshArgs.__required_keys__ == {"tank_shape", "tank_dims", "t_end", "step"}
