"""Python API of track geometry, wheel/rail profiles and single-wheel contact (railslosh.rail)."""

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import railslosh as rs
from railslosh import rail

FT = 0.3048
INCH = 0.0254
MANCHESTER = Path(__file__).resolve().parents[2] / "shared" / "data" / "manchester-contact"


def simple_curve(radius=800.0, superelevation=0.1, length=400.0):
    """Tangent, 50 m spiral, constant left curve, 50 m spiral, tangent (SI)."""
    k = 1.0 / radius
    s = [0.0, 100.0, 150.0, 150.0 + length, 200.0 + length, 300.0 + length]
    return rail.Track(s, [0, 0, k, k, 0, 0], [0, 0, superelevation, superelevation, 0, 0])


# --------------------------------------------------------------------------------------
# Track
# --------------------------------------------------------------------------------------


def test_balance_speed_of_a_simple_curve():
    track = simple_curve(radius=800.0, superelevation=0.1)
    v = track.balance_speed(300.0)
    assert v == pytest.approx(math.sqrt(rail.GRAVITY * 800.0 * 0.1 / track.cant_base), rel=1e-12)
    # tangent track: no balance speed; arrays in, arrays out
    vs = track.balance_speed([50.0, 300.0])
    assert vs.shape == (2,) and math.isnan(vs[0]) and vs[1] == pytest.approx(v)
    assert track.curvature(300.0) == pytest.approx(1 / 800.0)
    assert track.superelevation(300.0) == pytest.approx(0.1)
    assert track.bank_angle(300.0) == pytest.approx(-math.asin(0.1 / 1.5))


def test_balance_speed_uses_the_cant_base():
    s, k, e = [0.0, 100.0], [1 / 500.0, 1 / 500.0], [0.12, 0.12]
    v15 = rail.Track(s, k, e).balance_speed(50.0)
    v1435 = rail.Track(s, k, e, cant_base=1.435).balance_speed(50.0)
    assert v1435 == pytest.approx(math.sqrt(rail.GRAVITY * 500.0 * 0.12 / 1.435))
    assert v15 < v1435


def test_adverse_superelevation_has_no_balance_speed_and_flat_curve_zero():
    assert math.isnan(rail.Track([0, 100], [1e-3, 1e-3], [-0.05, -0.05]).balance_speed(50.0))
    assert rail.Track([0, 100], [1e-3, 1e-3], [0.0, 0.0]).balance_speed(50.0) == 0.0


def test_us_and_si_tables_describe_the_same_track():
    dist_ft = np.array([0.0, 300.0, 800.0, 1800.0, 2300.0, 2600.0])
    degree = np.array([0.0, 0.0, 3.0, 3.0, -3.0, -3.0])
    e_in = np.array([0.0, 0.0, 3.0, 3.0, -3.0, -3.0])
    grade_pct = np.array([0.0, 0.5, 0.5, 1.0, 1.0, 0.0])
    cant_r, cant_l = 0.025, -0.025
    us = rail.Track.from_us(dist_ft, degree, e_in, grade_pct, cant_r, cant_l)
    radius_ft = 5729.577951308232
    si = rail.Track(
        dist_ft * FT, degree / (radius_ft * FT), e_in * INCH, grade_pct / 100.0, cant_r, cant_l, cant_base=1.5
    )
    table = rail.Track.from_table(
        np.column_stack([dist_ft, degree, e_in, grade_pct, np.full(6, cant_r), np.full(6, cant_l)]), units="us"
    )
    assert us.units == "us" and si.units == "si"
    np.testing.assert_allclose(us.table, si.table, rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(table.table, si.table, rtol=1e-14, atol=1e-15)
    s = np.linspace(-20.0, 2700 * FT, 57)
    for name in ("curvature", "superelevation", "grade", "heading", "balance_speed"):
        np.testing.assert_allclose(getattr(us, name)(s), getattr(si, name)(s), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(us.position(s), si.position(s), rtol=1e-12, atol=1e-9)
    # 3 degrees of curvature and 3 in of super-elevation, cant base 1.5 m
    r = radius_ft / 3.0 * FT
    assert us.balance_speed(1300 * FT) == pytest.approx(math.sqrt(rail.GRAVITY * r * 3 * INCH / 1.5), rel=1e-12)
    assert us.rail_inward_cant(100.0, "right") == pytest.approx(0.025)
    assert us.rail_inward_cant(100.0, "left") == pytest.approx(0.025)


def test_straight_track_position_and_frame():
    track = rail.Track([0.0, 1000.0], 0.0, 0.0)
    np.testing.assert_allclose(track.position(123.0), [123.0, 0.0, 0.0], atol=1e-12)
    origin, rot = track.frame(123.0)
    np.testing.assert_allclose(origin, [123.0, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(rot, np.eye(3), atol=1e-14)
    np.testing.assert_allclose(track.rail_point(10.0, "left"), [10.0, 1.435 / 2, 0.0], atol=1e-12)
    np.testing.assert_allclose(track.rail_point(10.0, "right"), [10.0, -1.435 / 2, 0.0], atol=1e-12)


def test_full_circle_closes_and_frames_are_orthonormal():
    radius = 100.0
    length = 2 * math.pi * radius
    track = rail.Track([0.0, length], 1 / radius, 0.05)
    np.testing.assert_allclose(track.position(length), [0.0, 0.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(track.position(length / 2), [0.0, 2 * radius, 0.0], atol=1e-9)
    s = np.linspace(0.0, length, 13)
    origins, rots = track.frame(s)
    assert origins.shape == (13, 3) and rots.shape == (13, 3, 3)
    for r in rots:
        np.testing.assert_allclose(r.T @ r, np.eye(3), atol=1e-12)
        assert np.linalg.det(r) == pytest.approx(1.0)
    # right rail raised by e over the cant base: the lateral (left) axis tilts down by asin(e / B)
    assert rots[3][2, 1] == pytest.approx(-0.05 / 1.5)


def test_grade_raises_the_centreline():
    track = rail.Track([0.0, 500.0], 0.0, 0.0, grade=0.02)
    p = track.position(500.0)
    assert p[2] / p[0] == pytest.approx(0.02)
    assert math.hypot(p[0], p[2]) == pytest.approx(500.0)


def test_projection_recovers_the_station():
    track = simple_curve()
    s = np.array([20.0, 180.0, 420.0])
    origins, rots = track.frame(s)
    pts = origins + 0.3 * rots[:, :, 1] + 0.1 * rots[:, :, 2]
    ps, lat, vert = track.project(pts)
    np.testing.assert_allclose(ps, s, atol=1e-8)
    np.testing.assert_allclose(lat, 0.3, atol=1e-8)
    np.testing.assert_allclose(vert, 0.1, atol=1e-8)


@pytest.mark.parametrize(
    ("args", "kwargs", "field"),
    [
        (([0.0, 100.0, 50.0], 0.0, 0.0), {}, "s[2]"),
        (([0.0], 0.0, 0.0), {}, "`s`"),
        (([0.0, 100.0], 0.0, [0.0, 2.0]), {}, "superelevation[1]"),
        (([0.0, 100.0], [0.0, float("nan")], 0.0), {}, "curvature[1]"),
        (([0.0, 100.0], [0.0, 0.0, 0.0], 0.0), {}, "curvature"),
        (([0.0, 100.0], 0.0, 0.0), {"gauge": -1.0}, "gauge"),
        (([0.0, 100.0], 0.0, 0.0), {"cant_base": 0.0}, "cant_base"),
        (([0.0, 100.0], 0.0, 0.0), {"units": "metric"}, "units"),
        (([0.0, 2e6], 0.0, 0.0), {}, "`s`"),
    ],
)
def test_bad_track_tables_name_the_field(args, kwargs, field):
    with pytest.raises(ValueError, match=field.replace("[", r"\[").replace("]", r"\]")):
        rail.Track(*args, **kwargs)


def test_bad_us_tables_name_the_us_field_and_range():
    with pytest.raises(ValueError, match=r"superelevation_in\[1\].*expected.*in") as info:
        rail.Track.from_us([0.0, 100.0], [0.0, 1.0], [0.0, 80.0])
    assert "cant_base" in str(info.value)
    with pytest.raises(ValueError, match=r"distance_ft\[1\]"):
        rail.Track.from_us([0.0, 0.0], 0.0, 0.0)
    with pytest.raises(ValueError, match="rows"):
        rail.Track.from_table([[0.0, 0.0], [1.0, 0.0]])


def test_bad_queries_name_the_field():
    track = simple_curve()
    with pytest.raises(ValueError, match="`s`.*expected"):
        track.position(float("nan"))
    with pytest.raises(ValueError, match="`s`.*expected"):
        track.curvature([0.0, 1e9])
    with pytest.raises(ValueError, match="`side`.*expected"):
        track.rail_point(0.0, "middle")
    with pytest.raises(ValueError, match="points"):
        track.project([1.0, 2.0])


# --------------------------------------------------------------------------------------
# Profiles
# --------------------------------------------------------------------------------------


def test_standard_profiles_sample():
    wheel = rail.Profile.s1002()
    assert wheel.kind == "wheel" and wheel.name == "S1002"
    lo, hi = wheel.y_range
    assert lo == pytest.approx(-0.0695) and hi == pytest.approx(0.060)
    pts = wheel.sample(131)
    assert pts.shape == (131, 2)
    assert pts[0, 0] == pytest.approx(lo) and pts[-1, 0] == pytest.approx(hi)
    assert abs(wheel.z(0.0)) < 1e-6  # tape line
    assert wheel.z(-0.055) < -0.025  # flange: about 28 mm larger radius
    head = rail.Profile.uic60()
    assert head.kind == "rail"
    y_top, z_top = head.highest_point()
    assert abs(y_top) < 1e-6 and abs(z_top) < 1e-9
    assert head.z(0.02) == pytest.approx(head.z(-0.02), abs=1e-12)  # symmetric head
    np.testing.assert_allclose(head.z([0.01, -0.01]), [head.z(0.01), head.z(-0.01)])
    aar = rail.Profile.aar1b_approx()
    assert aar.kind == "wheel" and "approximate" in aar.name
    assert aar.slope(0.02) == pytest.approx(0.05, rel=1e-6)  # 1:20 tread cone


def test_profile_from_points_and_two_column_file(tmp_path):
    y = np.linspace(-0.03, 0.03, 31)
    z = -2.0 * y**2
    p = rail.Profile.from_points(y, z, name="parabola", kind="rail")
    assert p.name == "parabola" and p.kind == "rail"
    np.testing.assert_allclose(p.knots, np.column_stack([y, z]))
    np.testing.assert_allclose(p.z(0.011), -2.0 * 0.011**2, atol=1e-8)
    f = tmp_path / "profile.txt"
    f.write_text(
        "# y z in mm, z down\n" + "\n".join(f"{1e3 * a:.6f}, {-1e3 * b:.9f}" for a, b in zip(y, z, strict=True))
    )
    q = rail.Profile.from_file(f, scale=1e-3, z_down=True)
    np.testing.assert_allclose(q.knots, p.knots, atol=1e-12)
    assert q.name == "profile.txt" and q.kind is None
    m = rail.Profile.from_file(f, scale=1e-3, z_down=True, mirror_y=True)
    np.testing.assert_allclose(m.z(0.011), q.z(-0.011), atol=1e-12)


def test_profile_from_simpack_file(tmp_path):
    rows = "\n".join(f"      {y:.3f}  {0.002 * y * y:.6f}" for y in np.linspace(-30, 30, 61))
    text = f"""  header.begin
    version = 1
    type = 0 ! rail
  header.end
  spline.begin
    comment = 'test rail'
    units.len.f = +1.0e+03
    point.begin
{rows}
    point.end
  spline.end
"""
    f = tmp_path / "test.prr"
    f.write_text(text)
    p = rail.Profile.from_simpack(f)
    assert p.kind == "rail" and p.name == "test.prr"
    # SIMPACK z is down and in mm: z_up(y) = -0.002 (1000 y)^2 / 1000
    assert p.z(0.01) == pytest.approx(-0.002 * 10.0**2 / 1000.0, rel=1e-6)


@pytest.mark.skipif(not MANCHESTER.is_dir(), reason=f"Manchester contact data not found at {MANCHESTER}")
def test_manchester_profiles_read():
    wheel = rail.Profile.from_simpack(MANCHESTER / "MBench_S1002_v3.prw")
    head = rail.Profile.from_simpack(MANCHESTER / "MBench_UIC60_v3.prr")
    assert wheel.kind == "wheel" and head.kind == "rail"
    trimmed = head.trim_steep_ends(10.0)
    assert trimmed.y_range[1] - trimmed.y_range[0] < head.y_range[1] - head.y_range[0]


def test_bad_profile_input():
    with pytest.raises(ValueError, match="`y`.*expected"):
        rail.Profile.from_points([0.0], [0.0])
    with pytest.raises(ValueError, match="`z` has length"):
        rail.Profile.from_points([0.0, 1e-3], [0.0])
    with pytest.raises(ValueError, match="`y`.*expected"):
        rail.Profile.from_points([0.0, float("inf")], [0.0, 0.0])
    with pytest.raises(ValueError, match="strictly increasing"):
        rail.Profile.from_points([0.0, 0.0, 1e-3], [0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="`spacing`.*expected"):
        rail.Profile.s1002(spacing=0.0)
    with pytest.raises(ValueError, match="`n`.*expected"):
        rail.Profile.uic60().sample(1)
    with pytest.raises(ValueError, match="`kind`.*expected"):
        rail.Profile.from_points([0.0, 1e-3], [0.0, 0.0], kind="axle")
    with pytest.raises(FileNotFoundError):
        rail.Profile.from_simpack("/nonexistent/profile.prr")


def test_malformed_profile_files_name_the_line(tmp_path):
    f = tmp_path / "bad.txt"
    f.write_text("0 0\n1 abc\n2 0\n")
    with pytest.raises(ValueError, match=r"bad.txt:2"):
        rail.Profile.from_file(f)
    g = tmp_path / "bad.prw"
    g.write_text("header.begin\ntype = 1\nheader.end\npoint.begin\n0 0\n1 0\n")
    with pytest.raises(ValueError, match="point.end"):
        rail.Profile.from_simpack(g)


# --------------------------------------------------------------------------------------
# Contact
# --------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def s1002_uic60():
    return rail.Profile.s1002(), rail.Profile.uic60()


def test_contact_normal_force_carries_the_vertical_load(s1002_uic60):
    wheel, head = s1002_uic60
    for load in (20e3, 50e3, 100e3):
        res = rail.contact(wheel, head, rail_cant=1 / 40, lateral_shift=0.002, load=load, speed=20.0)
        assert res["vertical_force"] == pytest.approx(load, rel=1e-9)
        assert res["force_on_wheel"][:, 2].sum() == pytest.approx(load, rel=1e-9)
        # tread contact: the normal force is close to the load, the patch a few mm across
        assert res["normal_force"].sum() == pytest.approx(load, rel=0.02)
        assert np.all(res["semi_axis_a"] > 1e-3) and np.all(res["semi_axis_b"] > 1e-3)
        assert np.all(res["semi_axis_a"] < 2e-2) and np.all(res["semi_axis_b"] < 2e-2)
        assert np.all(res["penetration"] > 0)
        assert len(res["y_track"]) == len(res["normal_force"]) >= 1
        assert np.all(np.abs(res["y_track"] - 0.75) < 0.03)  # under the left wheel, on the rail head


def test_normal_force_follows_hertz_in_penetration(s1002_uic60):
    wheel, head = s1002_uic60
    kw = dict(rail_cant=1 / 40, lateral_shift=0.003)
    a = rail.contact(wheel, head, penetration=5e-5, **kw)
    b = rail.contact(wheel, head, penetration=1e-4, **kw)
    assert a["penetration"].max() == pytest.approx(5e-5, rel=1e-9)
    assert len(a["normal_force"]) == len(b["normal_force"]) == 1
    assert b["normal_force"][0] / a["normal_force"][0] == pytest.approx(2**1.5, rel=1e-3)
    # at rest there is no creep force
    assert a["creep_longitudinal"][0] == 0.0 and a["creep_lateral"][0] == 0.0


def test_left_and_right_wheels_mirror(s1002_uic60):
    wheel, head = s1002_uic60
    left = rail.contact(wheel, head, side="left", rail_cant=1 / 40, lateral_shift=0.004, load=50e3)
    right = rail.contact(wheel, head, side="right", rail_cant=1 / 40, lateral_shift=-0.004, load=50e3)
    np.testing.assert_allclose(right["y_track"], -left["y_track"], atol=1e-9)
    np.testing.assert_allclose(right["normal_force"], left["normal_force"], rtol=1e-6)
    assert right["height"] == pytest.approx(left["height"], abs=1e-9)


def test_prescribed_creepages(s1002_uic60):
    wheel, head = s1002_uic60
    kw = dict(rail_cant=1 / 40, load=50e3, speed=20.0, creep_model="linear")
    zero = rail.contact(wheel, head, creepages=(0.0, 0.0, 0.0), **kw)
    assert np.all(zero["creep_longitudinal"] == 0.0) and np.all(zero["creep_lateral"] == 0.0)
    lon = rail.contact(wheel, head, creepages=(1e-4, 0.0, 0.0), **kw)
    lat = rail.contact(wheel, head, creepages=(0.0, 1e-4, 0.0), **kw)
    np.testing.assert_allclose(lon["creepages"][:, 0], 1e-4)
    assert np.all(lon["creep_longitudinal"] < 0) and np.all(lat["creep_lateral"] < 0)  # oppose the slip
    assert lon["vertical_force"] == pytest.approx(50e3, rel=1e-9)
    # linear law: force proportional to creepage
    lon2 = rail.contact(wheel, head, creepages=(2e-4, 0.0, 0.0), **kw)
    np.testing.assert_allclose(lon2["creep_longitudinal"], 2 * lon["creep_longitudinal"], rtol=1e-6)


def test_creep_laws_saturate_at_friction(s1002_uic60):
    wheel, head = s1002_uic60
    for model in ("shen-hedrick-elkins", "polach", "fastsim"):
        res = rail.contact(
            wheel, head, rail_cant=1 / 40, load=50e3, speed=20.0, creepages=(0.05, 0, 0), creep_model=model
        )
        total = np.hypot(res["creep_longitudinal"], res["creep_lateral"])
        # FASTSIM bounds the traction cell by cell: its resultant exceeds mu N by a discretization error
        slack = 1e-2 if model == "fastsim" else 1e-9
        assert np.all(total <= 0.3 * res["normal_force"] * (1 + slack)), model
        assert np.all(total > 0.2 * res["normal_force"]), model


@pytest.mark.skipif(not MANCHESTER.is_dir(), reason=f"Manchester contact data not found at {MANCHESTER}")
def test_manchester_case_through_the_python_helper():
    # Case 11 of A2.2: y_ws = 5 mm, roll -0.3554 mrad, yaw 12 mrad, VPITCH -4.3353637 rad/s, 10 kN
    # vertical force (CONTACT's y is to the right and z down: shift and yaw change sign).
    wheel = rail.Profile.from_simpack(MANCHESTER / "MBench_S1002_v3.prw")
    head = rail.Profile.from_simpack(MANCHESTER / "MBench_UIC60_v3.prr")
    steel = dict(young=2 * 82e9 * 1.28, poisson=0.28, friction=0.3)
    pose = dict(lateral_shift=-0.005, roll=-3.554e-4, yaw=-0.012, speed=2.0, axle_rate=4.3353637)
    res = rail.contact(wheel, head, trim_slope=10.0, load=10e3, **pose, **steel)
    assert len(res["normal_force"]) == 1
    assert abs(res["y_track"][0] * 1e3 - 757.896) < 1.0  # CONTACT's YCP(TR), mm
    assert res["normal_force"][0] == pytest.approx(10030.0, rel=0.01)  # CONTACT's FN
    assert -res["creep_longitudinal"][0] == pytest.approx(837.8, rel=0.15)  # CONTACT's FX (on the rail)
    assert res["creep_lateral"][0] == pytest.approx(-2889.0, rel=0.15)  # CONTACT's FS


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        (dict(load=50e3, penetration=1e-4), "load"),
        (dict(), "load"),
        (dict(load=-1.0), "load"),
        (dict(penetration=0.1), "penetration"),
        (dict(load=50e3, side="middle"), "side"),
        (dict(load=50e3, lateral_shift=0.5), "lateral_shift"),
        (dict(load=50e3, yaw=1.0), "yaw"),
        (dict(load=50e3, nominal_radius=-0.46), "nominal_radius"),
        (dict(load=50e3, speed=-1.0), "speed"),
        (dict(load=50e3, friction=float("nan")), "friction"),
        (dict(load=50e3, poisson=0.7), "poisson"),
        (dict(load=50e3, creep_model="kalker"), "creep_model"),
        (dict(load=50e3, creepages=(0.1, 0.0)), "creepages"),
        (dict(load=50e3, scan_points=-5), "scan_points"),
        (dict(load=50e3, gauge_depth=0.04), "gauge_depth"),
        (dict(load="heavy"), "load"),
    ],
)
def test_bad_contact_input_names_the_field(s1002_uic60, kwargs, field):
    wheel, head = s1002_uic60
    with pytest.raises(ValueError, match=field) as info:
        rail.contact(wheel, head, **kwargs)
    assert ": expected " in str(info.value) and "allowed" not in str(info.value)


def test_wheel_off_its_rail_is_a_clear_error(s1002_uic60):
    wheel, head = s1002_uic60
    with pytest.raises(ValueError, match="lateral_shift"):
        rail.contact(wheel, head, rail_offset=1.0, load=50e3)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    shift=st.floats(-0.05, 0.05),
    yaw=st.floats(-0.05, 0.05),
    load=st.floats(1.0, 3e5),
    speed=st.floats(0.0, 60.0),
    side=st.sampled_from(["left", "right"]),
)
def test_contact_never_panics(s1002_uic60, shift, yaw, load, speed, side):
    wheel, head = s1002_uic60
    try:
        res = rail.contact(
            wheel, head, side=side, rail_cant=1 / 40, lateral_shift=shift, yaw=yaw, load=load, speed=speed
        )
    except (ValueError, rs.RailsloshError):
        return
    assert res["vertical_force"] == pytest.approx(load, rel=1e-6)
    assert np.all(np.isfinite(res["normal_force"]))


def test_a_jump_in_the_contact_force_is_an_error_not_a_wrong_load(s1002_uic60):
    """Found by hypothesis: at 2.7 degrees of yaw the contact search finds the flange contact only
    from 0.57 mm penetration on, so the vertical force jumps from 0 to 331 kN. A load between the
    two cannot be met: the solve says so, naming the jump, instead of returning 331 kN as 1 N."""
    wheel, head = s1002_uic60
    kw = dict(side="right", rail_cant=1 / 40, lateral_shift=-0.0078125, yaw=0.046875, speed=0.0)
    try:
        res = rail.contact(wheel, head, load=1.0, **kw)
    except rs.RailsloshError as exc:
        assert "no wheel height meets the target" in str(exc)
        assert "jumps from" in str(exc)
    else:
        assert res["vertical_force"] == pytest.approx(1.0, rel=1e-6)
    # the same pose under a load above the jump is met exactly
    res = rail.contact(wheel, head, load=400e3, **kw)
    assert res["vertical_force"] == pytest.approx(400e3, rel=1e-6)


def test_a_lubricated_gauge_face_gives_each_contact_point_its_own_friction(s1002_uic60):
    """Issue 21: friction over the rail profile. A wheel pressed against the right rail's gauge face
    (two points: tread and flange root) with a large lateral slip: each point saturates at the μ of its
    own rail location, 0.1 on the lubricated gauge side and 0.4 on the top."""
    wheel, head = s1002_uic60
    table = rail.lubricated_gauge_face(head, mu_top=0.4, mu_gauge=0.1, depth=0.002, width=0.002)
    assert [mu for _, mu in table] == [0.1, 0.4]
    v_edge = table[0][0]
    kw = dict(side="right", rail_cant=1 / 40, load=50e3, speed=20.0, lateral_velocity=1.0)
    found = None
    for shift in np.linspace(-0.0055, -0.0085, 31):
        res = rail.contact(wheel, head, lateral_shift=float(shift), friction_profile=table, **kw)
        if len(res["normal_force"]) == 2 and res["normal_force"].min() > 500.0:
            found = res
            break
    assert found is not None, "a two-point contact"
    tangential = np.hypot(found["creep_longitudinal"], found["creep_lateral"])
    expected = np.where(found["rail_v"] < v_edge, 0.1, np.where(found["rail_v"] > v_edge + 0.002, 0.4, np.nan))
    assert not np.isnan(expected).any(), found["rail_v"]
    assert sorted(expected) == [0.1, 0.4]
    np.testing.assert_allclose(found["friction"], expected, rtol=0, atol=1e-15)
    np.testing.assert_allclose(tangential / found["normal_force"], expected, rtol=1e-9)
    with pytest.raises(ValueError, match=r"`friction.profile\[1\]`"):
        rail.contact(wheel, head, lateral_shift=0.0, friction_profile=[(0.0, 0.2), (0.0, 0.3)], **kw)


def test_kik_piotrowski_patch_model(s1002_uic60):
    """Issue 21, patch models: the Kik-Piotrowski patch carries the same load as Hertz, its pressure
    centroid is the reference point, and Hertz stays the default (same result as naming it)."""
    wheel, head = s1002_uic60
    kw = dict(rail_cant=1 / 40, lateral_shift=0.004, load=50e3, speed=20.0, creep_model="fastsim")
    hertz = rail.contact(wheel, head, **kw)
    named = rail.contact(wheel, head, patch_model="hertz", **kw)
    for key in ("height", "normal_force", "creep_lateral", "semi_axis_b"):
        np.testing.assert_array_equal(hertz[key], named[key])
    np.testing.assert_array_equal(hertz["reference_point"], hertz["point"])
    kp = rail.contact(wheel, head, patch_model="kik_piotrowski", kp_epsilon=0.55, kp_strips=80, **kw)
    assert kp["vertical_force"] == pytest.approx(50e3, rel=1e-9)
    assert kp["normal_force"].sum() == pytest.approx(hertz["normal_force"].sum(), rel=0.02)
    # a patch of the same size class as Hertz's ellipse, centred near the contact point
    assert np.all(kp["patch_width"] > 0.5 * hertz["patch_width"].max())
    assert np.all(kp["patch_width"] < 2.0 * hertz["patch_width"].max())
    assert np.all(np.linalg.norm(kp["reference_point"] - kp["point"], axis=1) < 0.5 * kp["patch_width"])
    assert np.all(np.isfinite(kp["creep_lateral"])) and np.all(kp["max_pressure"] > 0)
    # the published epsilon 0.5 vs 0.55: a smaller virtual penetration, a smaller patch
    small = rail.contact(wheel, head, patch_model="kik_piotrowski", kp_epsilon=0.5, **kw)
    assert small["patch_area"].sum() < kp["patch_area"].sum()


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    shift=st.floats(-0.012, 0.012),
    yaw=st.floats(-0.03, 0.03),
    load=st.floats(1e3, 2e5),
    side=st.sampled_from(["left", "right"]),
)
def test_kik_piotrowski_contact_never_panics(s1002_uic60, shift, yaw, load, side):
    wheel, head = s1002_uic60
    try:
        res = rail.contact(
            wheel,
            head,
            side=side,
            rail_cant=1 / 40,
            lateral_shift=shift,
            yaw=yaw,
            load=load,
            speed=20.0,
            creep_model="fastsim",
            patch_model="kik_piotrowski",
        )
    except (ValueError, rs.RailsloshError):
        return
    assert res["vertical_force"] == pytest.approx(load, rel=1e-6)
    assert np.all(np.isfinite(res["normal_force"])) and np.all(res["patch_area"] > 0)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        (dict(patch_model="kp"), "patch_model"),
        (dict(patch_model="kik_piotrowski", kp_epsilon=1.5), "kp_epsilon"),
        (dict(patch_model="kik_piotrowski", kp_epsilon="big"), "kp_epsilon"),
        (dict(patch_model="kik_piotrowski", kp_strips=2), "kp_strips"),
        (dict(patch_model="kik_piotrowski", kp_strips=10.5), "kp_strips"),
        (dict(kp_epsilon=0.55), "kp_epsilon"),
    ],
)
def test_bad_patch_model_input_names_the_field(s1002_uic60, kwargs, field):
    wheel, head = s1002_uic60
    with pytest.raises(ValueError, match=f"`{field}`") as info:
        rail.contact(wheel, head, rail_cant=1 / 40, load=50e3, **kwargs)
    assert ": expected " in str(info.value)


def test_contacts_patch_rule_makes_one_patch_of_two_close_points(s1002_uic60):
    """Issue 21: with CONTACT's D_SEP/D_COMB rule (`patch_combination="contact"`) the two tread
    points S1002 finds on UIC 60 at 1:40 near the centred position (about 10 mm apart, their
    interpenetration regions overlapping) are one patch carrying the same load, placed between
    them; the default keeps one patch per point."""
    wheel, head = s1002_uic60
    kw = dict(rail_cant=1 / 40, load=60e3, speed=20.0, creep_model="fastsim")
    for shift in (0.0003, 0.0006):
        separate = rail.contact(wheel, head, lateral_shift=shift, **kw)
        assert len(separate["normal_force"]) == 2, shift
        one = rail.contact(wheel, head, lateral_shift=shift, patch_combination="contact", **kw)
        assert len(one["normal_force"]) == 1, shift
        assert one["vertical_force"] == pytest.approx(60e3, rel=1e-9)
        lo, hi = sorted(separate["y_track"])
        assert lo < one["y_track"][0] < hi
        # wider than either separate patch: it spans both regions
        assert one["patch_width"][0] > separate["patch_width"].max()
    # normals about 2 degrees apart: a rule that combines only below 0.5 degrees keeps the two
    apart = rail.contact(wheel, head, lateral_shift=0.0006, patch_combination="contact", a_sep=0.009, **kw)
    assert len(apart["normal_force"]) == 2


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        (dict(patch_combination="merge"), "patch_combination"),
        (dict(d_sep=0.008), "d_sep"),
        (dict(patch_combination="contact", d_sep=0.002, d_comb=0.004), "d_sep"),
        (dict(patch_combination="contact", a_sep=4.0), "a_sep"),
        (dict(patch_combination="contact", d_comb=-1e-3), "d_comb"),
    ],
)
def test_bad_patch_combination_input_names_the_field(s1002_uic60, kwargs, field):
    wheel, head = s1002_uic60
    with pytest.raises(ValueError, match=f"`(patch_combination\\.)?{field}`"):
        rail.contact(wheel, head, rail_cant=1 / 40, load=50e3, **kwargs)


@pytest.mark.parametrize("mu", [0.3, 0.5])
def test_a_wheel_pushed_into_flange_contact_climbs_at_the_nadal_limit(s1002_uic60, mu):
    """Issue 21 (derailment use), quasi-static: the left S1002 wheel carries 50 kN and slides on the
    rail with a saturated lateral creepage (η = -0.05, the climbing direction, no longitudinal creep).
    Shifted into flange contact, the L/V it holds is Nadal's (tan δ − μ)/(1 + μ tan δ) at each point's
    own contact angle δ; the largest L/V over the shifts, where the wheel starts to climb (beyond it
    the contact angle falls as the flange rides up), is Nadal's limit at the profile's flange angle."""
    from railslosh import indicators

    wheel, head = s1002_uic60
    lv = []
    jumps = 0
    for shift in np.linspace(0.0070, 0.0110, 41):
        try:
            res = rail.contact(
                wheel,
                head,
                side="left",
                rail_cant=1 / 40,
                lateral_shift=float(shift),
                load=50e3,
                speed=5.0,
                creepages=(0.0, -0.05, 0.0),
                friction=mu,
            )
        except rs.RailsloshError as exc:  # the jump from the flange root onto the flange: no height carries 50 kN
            assert "discontinuous" in str(exc)
            jumps += 1
            continue
        if len(res["normal_force"]) != 1:
            continue
        delta = float(res["contact_angle"][0])
        ratio = -res["lateral_force"] / res["vertical_force"]
        # the flange's angles: Nadal at each point (nadal_limit takes degrees)
        if delta > math.radians(45.0):
            assert ratio == pytest.approx(indicators.nadal_limit(math.degrees(delta), mu), rel=1e-9)
        lv.append((ratio, math.degrees(delta)))
    assert len(lv) >= 30 and jumps <= 6, (len(lv), jumps)
    peak, steepest = max(lv)
    # the steepest point is the S1002 flange angle (70°; measured 70.03-70.04° on the spline of the
    # tabulated profile), and the wheel climbs at Nadal's limit there: 0.1-0.2 % above the 70° value
    print(f"mu = {mu}: steepest contact angle {steepest:.4f} deg, L/V {peak:.6f}")
    assert steepest == pytest.approx(indicators.FLANGE_ANGLE["s1002"], abs=0.15), steepest
    assert peak == pytest.approx(indicators.nadal_limit(steepest, mu), rel=1e-9)
    assert peak == pytest.approx(indicators.nadal_limit(indicators.FLANGE_ANGLE["s1002"], mu), rel=2e-3)


def test_the_tangential_laws_take_their_parameters(s1002_uic60):
    """Issue 21: Polach's k_A/k_S and FASTSIM's grid are parameters, not fixed. Polach with
    k_A = k_S = 1 is the default; smaller reduction factors lower the creep force; FASTSIM converges
    with its grid; unknown or out-of-range parameters name the field."""
    wheel, head = s1002_uic60
    kw = dict(rail_cant=1 / 40, lateral_shift=0.002, load=50e3, speed=20.0, creepages=(1e-3, 0.0, 0.0))

    def fx(model, params=None):
        return rail.contact(wheel, head, creep_model=model, creep_parameters=params, **kw)["creep_longitudinal"].sum()

    assert fx("polach", {"k_a": 1.0, "k_s": 1.0}) == fx("polach")
    assert abs(fx("polach", {"k_a": 0.3, "k_s": 0.3})) < abs(fx("polach"))
    coarse, fine, finest = (fx("fastsim", {"nx": n, "ny": n}) for n in (10, 40, 160))
    assert abs(fine - finest) < abs(coarse - finest), (coarse, fine, finest)
    assert fine == pytest.approx(finest, rel=0.02)
    assert fx("fastsim", {"nx": 40, "ny": 40}) == fx("fastsim")
    with pytest.raises(ValueError, match=r"`creep_parameters`"):
        fx("polach", {"nx": 10})
    with pytest.raises(ValueError, match=r"`creep_parameters.k_a` = 1.5"):
        fx("polach", {"k_a": 1.5})
    with pytest.raises(ValueError, match=r"`creep_parameters.nx` = 1"):
        fx("fastsim", {"nx": 1})
