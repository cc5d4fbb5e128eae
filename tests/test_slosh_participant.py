"""Python binding of the Rust slosh co-simulation participant (``railslosh._core.SloshParticipant``,
issue 6): input dicts in both forms, exact rollback, added mass, and errors naming the field."""

import numpy as np
import pytest

from railslosh import _core
from railslosh.constants import GRAVITY

G = GRAVITY
L = (0.4, 0.3, 0.1)
TANK = [-0.2, -0.15, 0.0, 0.2, 0.15, 0.25]


@pytest.fixture(scope="module")
def parts():
    if not hasattr(_core, "SloshParticipant"):
        pytest.skip("railslosh._core was built without SloshParticipant")
    k = 1000 * 998 * G * L[2]
    fluid = _core.Fluid(998.0, "newtonian", viscosity=0.05, bulk_penalty=k, bulk_damping=0.2 * np.sqrt(k * 998) * 0.05)
    mesh = _core.box_mesh([-0.2, -0.15, 0.0], list(L), [2, 2, 2])
    return mesh, fluid


def make(parts, **kw):
    mesh, fluid = parts
    return _core.SloshParticipant(mesh, fluid, "box", TANK, **kw)


def test_pose_and_tank_frame_dicts_agree_and_rollback_is_exact(parts):
    # tank yawed by 90 deg: global y acceleration is tank x acceleration
    a = 0.5
    pose = {"quaternion": [np.sqrt(0.5), 0, 0, np.sqrt(0.5)], "acceleration": [0.0, a, 0.0], "position": [1, 2, 3]}
    tank = {"acceleration": [a, 0.0, 0.0], "gravity": [0.0, 0.0, -G]}
    p1, p2 = make(parts), make(parts)
    for k in range(5):
        f1, m1 = p1.advance(0.02 * (k + 1), pose, pose)
        f2, m2 = p2.advance(0.02 * (k + 1), tank, tank)
        scale = np.abs(np.concatenate([f2, m2])).max()
        assert np.abs(f1 - f2).max() <= 1e-9 * scale and np.abs(m1 - m2).max() <= 1e-9 * scale
    state = p2.save_state()
    assert state.time == pytest.approx(0.1)
    first = p2.advance(0.13, tank, {"acceleration": [0.0, 1.0, 0.0]})
    p2.restore_state(_core.SloshParticipantState.from_bytes(state.to_bytes()))
    assert p2.time == state.time
    again = p2.advance(0.13, tank, {"acceleration": [0.0, 1.0, 0.0]})
    assert np.array_equal(first[0], again[0]) and np.array_equal(first[1], again[1])


def test_added_mass_translational_block_is_the_fluid_mass(parts):
    p = make(parts, reference_point=[0.0, 0.0, 0.0])
    ma = p.added_mass()
    assert ma.shape == (6, 6)
    np.testing.assert_allclose(ma[:3, :3], p.fluid_mass * np.eye(3), atol=1e-9 * p.fluid_mass)
    np.testing.assert_allclose(ma, ma.T, atol=1e-9 * p.fluid_mass)
    assert p.fluid_mass == pytest.approx(998.0 * np.prod(L), rel=1e-9)


@pytest.mark.parametrize(
    ("call", "field"),
    [
        (lambda p: p.advance(0.0, {}, {}), "t_end"),
        (lambda p: p.advance(0.1, {"acceleraton": [0, 0, 0]}, {}), "input_start.acceleraton"),
        (lambda p: p.advance(0.1, {}, {"gravity": [0, 0]}), "input_end.gravity"),
        (lambda p: p.advance(0.1, {"rotation": [[1, 1, 0], [0, 1, 0], [0, 0, 1]]}, {}), "rotation"),
        (lambda p: p.advance(0.1, {"quaternion": [2, 0, 0, 0]}, {}), "quaternion"),
    ],
)
def test_bad_inputs_raise_value_error_naming_the_field(parts, call, field):
    p = make(parts)
    with pytest.raises(ValueError, match=f"`{field}`"):
        call(p)
    assert p.time == 0.0


@pytest.mark.parametrize(
    ("kw", "field"),
    [
        ({"h_max": -1.0}, "h_max"),
        ({"gravity": float("nan")}, "gravity"),
        ({"reference_point": [0, float("inf"), 0]}, "reference_point"),
    ],
)
def test_bad_config_raises_value_error_naming_the_field(parts, kw, field):
    with pytest.raises(ValueError, match=f"`{field}`"):
        make(parts, **kw)
    mesh, fluid = parts
    with pytest.raises(ValueError, match="`tank`"):
        _core.SloshParticipant(mesh, fluid, "sphere", [1.0])


def test_seed003_maneuvers_are_sampled_tank_motions():
    if not hasattr(_core, "seed003_maneuvers"):
        pytest.skip("railslosh._core was built without seed003_maneuvers")
    mans = _core.seed003_maneuvers(dt=0.01, t_after=0.5)
    names = [m["name"] for m in mans]
    assert names == [
        "lane_change_20mph",
        "lane_change_40mph",
        "half_round_9in_10mph",
        "half_round_12in_5mph",
        "trapezoid_9in_15mph",
        "trapezoid_12in_10mph",
    ]
    for m in mans:
        n = len(m["t"])
        assert m["acceleration"].shape == (n, 3) and m["rotation"].shape == (n, 3, 3)
        # tank-frame vectors are the global ones rotated into tank axes: R^T v
        rt = np.transpose(m["rotation"], (0, 2, 1))
        np.testing.assert_allclose(np.einsum("nij,nj->ni", rt, m["pose_acceleration"]), m["acceleration"], atol=1e-12)
        np.testing.assert_allclose(np.linalg.norm(m["gravity"], axis=1), G, rtol=1e-12)
    # the AVTP double lane change: one lane (3.66 m) to the left, then back
    assert mans[0]["position"][:, 1].max() == pytest.approx(3.66) and abs(mans[0]["position"][-1, 1]) < 1e-9


def test_settle_keeps_the_clock_and_loads_the_walls(parts):
    p = make(parts)
    f0, _ = p.loads()
    assert abs(f0[2]) < 1e-9  # the mesh starts unloaded
    f, _ = p.settle(0.6, {})
    assert p.time == 0.0
    w = p.fluid_mass * G
    assert abs(f[2] + w) < 0.02 * w
    with pytest.raises(ValueError, match="`duration`"):
        p.settle(0.0, {})


def test_the_participant_reports_its_invariant_margins_with_a_balanced_energy_account(parts):
    """Issue 16 §1 for the co-simulation participant: every window checks containment, element
    validity and the tank-frame energy balance; the worst margins are reported as a slosh run's."""
    p = make(parts)
    p.settle(0.3, {})
    push = {"acceleration": [0.0, 0.3 * G, 0.0]}
    for k in range(40):
        p.advance(0.01 * (k + 1), push if k < 15 else {}, push if k < 14 else {})
    m = p.margins
    assert set(m) >= {"worst_gap", "gap_limit", "worst_energy_error", "min_volume_ratio", "dissipated"}
    assert 0.0 <= m["worst_gap"] < m["gap_limit"] and m["min_volume_ratio"] > 0.5
    assert m["worst_energy_error"] is not None and m["worst_energy_error"] <= 1e-3
    assert m["dissipated"] > 0.0
