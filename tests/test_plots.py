"""Plots an engineer can read (issue 19): engineering units, labels in words, a legend entry per
line naming car, wheelset and side, per-car panels, the standard limits drawn in, the settling
phase shaded, every figure drawn in the package's matplotlib style."""

import math
from pathlib import Path

import matplotlib.style
import numpy as np
import pytest

from railslosh import plots, results, scene

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def rigid():
    sc = scene.load_scene(ROOT / "examples/scenes/two_car_ecp_braking_rigid.toml", {"train": {"t_end": 0.4}})
    return results.to_dataset(scene.run_scene(sc))


def _slosh(settle_time=None):
    """A slosh-like Dataset: a start-up spike of the vertical load, then 0.5 s of lateral slosh."""
    t = np.linspace(0.0, 2.0, 1001)
    w = 140.0
    f = np.zeros((len(t), 3))
    f[:, 2] = -w * (1 - np.exp(-t / 0.03) * np.cos(2 * np.pi * 50 * t))
    f[:, 1] = np.where(t > 0.5, 0.3 * w * np.sin(2 * np.pi * 0.8 * (t - 0.5)), 0.0)
    ds = results.to_dataset({"t": t, "force_tank": f, "moment_tank": 0.1 * f, "com_tank": 1e-3 * f / w})
    if settle_time is not None:
        ds.attrs["settle_time"] = settle_time
    return ds


def test_the_wheel_load_plot_has_a_legend_entry_per_line_and_a_panel_per_car(rigid):
    fig = plots.figure(rigid, "wheel_loads")
    axes = [ax for ax in fig.axes if ax.get_lines()]
    assert len(axes) == rigid.sizes["car"] == 2
    for k, ax in enumerate(axes):
        lines = ax.get_lines()
        legend = ax.get_legend()
        assert legend is not None
        texts = [t.get_text() for t in legend.get_texts()]
        assert texts == [ln.get_label() for ln in lines], "one legend entry per line, in order"
        assert len(set(texts)) == len(texts)
        data = [s for s in texts if s.startswith("car ")]
        # 4 wheelsets x 2 sides per car, each named by car, wheelset and side
        first = 4 * k + 1
        expected = {f"car {k + 1}, wheelset {w}, {side}" for w in range(first, first + 4) for side in ("left", "right")}
        assert set(data) == expected
        assert ax.get_ylabel() == "Wheel load Q (kN)"
        # the static load and the unloading limit are lines with their own entries
        q0 = rigid.attrs["static_wheel_load"] / 1e3
        ys = {round(float(ln.get_ydata()[0]), 6) for ln in lines if ln.get_label().startswith(("static", "ΔQ"))}
        assert ys == {round(q0, 6), round(0.4 * q0, 6)}


def test_labels_are_words_with_engineering_units(rigid):
    expect = {
        "coupler_force": "Coupler force",
        "speed": "Speed (km/h)",
        "l_over_v": "L/V",
        "wheelset_lateral": "Lateral displacement (mm)",
    }
    for stem, ylabel in expect.items():
        fig = plots.figure(rigid, stem)
        labels = [ax.get_ylabel() for ax in fig.axes if ax.get_lines()]
        assert labels and all(lab.startswith(ylabel) for lab in labels), (stem, labels)
        assert not any("_" in lab for lab in labels), labels
        assert all(ax.get_xlabel() in ("", "Time (s)") for ax in fig.axes)
    # speed drawn in km/h: 40 km/h at the start
    ax = plots.figure(rigid, "speed").axes[0]
    assert ax.get_lines()[0].get_ydata()[0] == pytest.approx(40.0, rel=1e-3)


def test_display_units_follow_the_magnitude():
    assert plots.display_unit("coupler_force", [-2.5e4, 1e3]) == ("kN", 1e-3)
    assert plots.display_unit("force_tank", [137.0]) == ("N", 1.0)
    assert plots.display_unit("tank_speed", [11.1]) == ("km/h", 3.6)
    assert plots.display_unit("wheelset_lateral", [0.008]) == ("mm", 1e3)
    assert plots.display_unit("oil_com_global", [1234.0]) == ("m", 1.0)
    assert plots.display_unit("l_over_v", [0.3]) == ("", 1.0)
    assert plots.display_unit("something_new", [1.0], "Pa") == ("Pa", 1.0)
    # one name per concept: the liquid's force reads the same from slosh and vehicle runs
    assert plots.label("force_tank") == plots.label("fluid_force_tank") == "Liquid force on the tank"


def test_standard_limits_are_drawn(rigid):
    tan70 = math.tan(math.radians(70))
    assert plots.nadal_limit(70.0, 0.5) == pytest.approx((tan70 - 0.5) / (1 + 0.5 * tan70))
    # the values quoted for Nadal's criterion: 0.95 (70°) and 1.13 (75°, AAR) at μ = 0.5
    assert plots.nadal_limit(70.0, 0.5) == pytest.approx(0.947, abs=1e-3)
    assert plots.nadal_limit(75.0, 0.5) == pytest.approx(1.128, abs=1e-3)
    lv = plots.figure(rigid, "l_over_v")
    for ax in [a for a in lv.axes if a.get_lines()]:
        limit = [ln for ln in ax.get_lines() if "UIC 518" in ln.get_label()]
        assert len(limit) == 1 and limit[0].get_ydata()[0] == pytest.approx(plots.L_OVER_V_LIMIT)
        nadal = [ln for ln in ax.get_lines() if ln.get_label().startswith("Nadal")]
        assert nadal and nadal[0].get_ydata()[0] == pytest.approx(plots.nadal_limit(70.0))  # S1002 profile
    un = plots.figure(rigid, "wheel_unloading")
    for ax in [a for a in un.axes if a.get_lines()]:
        assert any(ln.get_ydata()[0] == pytest.approx(0.6) and "UIC 530-2" in ln.get_label() for ln in ax.get_lines())
    # a limit given with the results replaces the default
    custom = rigid.copy()
    custom.attrs["l_over_v_limit"] = 1.0
    assert plots.limits(custom, "l_over_v")[0][0] == 1.0


def test_the_settling_phase_is_shaded_and_its_spike_clipped():
    ds = _slosh(settle_time=0.3)
    fig = plots.figure(ds, "slosh_force")
    for ax in [a for a in fig.axes if a.get_lines()]:
        spans = [p for p in ax.patches if abs(p.get_x()) < 1e-12 and p.get_width() == pytest.approx(0.3)]
        assert len(spans) == 1, "the settling phase 0 <= t < 0.3 s is shaded"
    vertical = [a for a in fig.axes if a.get_ylabel().startswith("Vertical")][0]
    lo, hi = vertical.get_ylim()
    z = ds["force_tank"].sel(component="z")
    after = z.where(z["time"] >= 0.3, drop=True)
    assert lo <= float(after.min()) and hi >= float(after.max())
    assert lo > float(z.min()), "the start-up spike is clipped, not allowed to set the scale"
    assert any("settling phase clipped" in t.get_text() for t in vertical.texts)
    # without a settling phase nothing is shaded
    ds0 = _slosh(settle_time=0.0)
    assert not any(ax.patches for ax in plots.figure(ds0, "slosh_force").axes)


def test_figures_are_drawn_in_the_package_style(rigid, tmp_path):
    params = matplotlib.rc_params_from_file(plots.STYLE, use_default_template=False)
    assert params["axes.spines.top"] is False and "0072b2" in str(params["axes.prop_cycle"]).lower()
    fig = plots.figure(rigid, "coupler_force")
    ax = fig.axes[0]
    assert not ax.spines["top"].get_visible() and fig.get_layout_engine() is not None
    # the style does not leak into the caller's matplotlib settings
    assert matplotlib.rcParams["axes.spines.top"] is True
    paths = plots.plot_dataset(rigid, tmp_path)
    assert {p.stem for p in paths} == {
        "coupler_force",
        "wheel_loads",
        "wheel_unloading",
        "l_over_v",
        "wheelset_lateral",
        "speed",
    }
    with pytest.raises(ValueError, match="invalid `stem`"):
        plots.figure(rigid, "nope")


def test_liquid_loads_recorded_at_every_step_are_also_drawn_through_the_20_hz_low_pass():
    """A slosh load with 45 Hz penalty ringing: the raw line is drawn faint, the EN 14363 20 Hz
    low-pass over it, each with its legend entry; coarsely recorded runs (vehicle runs at 50 Hz)
    draw the one line."""
    t = np.linspace(0.0, 2.0, 2001)
    f = np.zeros((t.size, 3))
    f[:, 1] = 40.0 * np.sin(2 * np.pi * 1.4 * t) + 10.0 * np.sin(2 * np.pi * 45.0 * t)
    f[:, 2] = -140.0
    ds = results.to_dataset({"t": t, "force_tank": f})
    fig = plots.figure(ds, "slosh_force")
    lateral = [a for a in fig.axes if a.get_ylabel().startswith("Lateral")][0]
    raw, smooth = lateral.get_lines()
    assert raw.get_label().endswith(", raw") and raw.get_alpha() == pytest.approx(0.3)
    assert smooth.get_label().endswith("20 Hz low-pass (EN 14363)")
    assert [x.get_text() for x in lateral.get_legend().get_texts()] == [raw.get_label(), smooth.get_label()]
    x, y = np.asarray(smooth.get_xdata()), np.asarray(smooth.get_ydata())
    inner = (x > 0.3) & (x < 1.7)
    assert np.abs(y - 40.0 * np.sin(2 * np.pi * 1.4 * x))[inner].max() < 0.1
    # recorded every 20 ms (a vehicle run's record_every): nothing above 20 Hz to remove, one line
    coarse = results.to_dataset({"t": t[::20], "force_tank": f[::20]})
    lateral = [a for a in plots.figure(coarse, "slosh_force").axes if a.get_ylabel().startswith("Lateral")][0]
    assert [ln.get_label() for ln in lateral.get_lines()] == ["Liquid force on the tank"]


@pytest.mark.parametrize(
    ("run_title", "one_line"),
    [("ECP braking, light crude", True), ("Light crude at 60 km/h on FRA class 5 track, three-piece trucks", False)],
)
def test_a_long_run_title_goes_on_its_own_line_and_stays_inside_the_figure(run_title, one_line, tmp_path):
    # the FRA class 5 three-piece scene's title ran off both sides of its PNGs on one line
    ds = _slosh()
    ds.attrs["title"] = run_title
    fig = plots.figure(ds, "slosh_force")
    title = fig._suptitle.get_text()
    assert title.endswith(run_title)
    assert ("\n" not in title) == one_line
    fig.savefig(tmp_path / "f.png")  # lays the figure out
    box = fig._suptitle.get_window_extent()
    assert box.x0 >= 0 and box.x1 <= fig.bbox.width, (box, fig.bbox)


def test_the_lateral_panels_of_a_mirror_symmetric_run_are_hatched_from_when_they_stray():
    """Issue 16: when a mirror-symmetric run's lateral liquid load leaves zero
    (``mirror_lateral_valid_until``, railslosh.scene.run.mirror_symmetry), the lateral panels of the
    liquid force and centre of mass are hatched from that time and say why; the other panels, and a
    run without the attribute, are not."""
    t = np.linspace(0.0, 10.0, 501)
    f = np.zeros((t.size, 2, 3))
    f[:, :, 0] = 5e4 * np.sin(0.3 * t)[:, None]
    f[:, :, 1] = 1e-3 * np.exp(1.5 * t)[:, None]
    f[:, :, 2] = -3.4e5
    res = {"t": t, "fluid_force_tank": f, "oil_com_tank": f / 3.4e7, "fluid_mass": 35e3}
    res["mirror_symmetry"] = {"inputs": "mirror-symmetric", "limit": 34.3, "lateral_valid_until": 6.94}
    ds = results.to_dataset(res)
    assert ds.attrs["mirror_lateral_valid_until"] == 6.94

    def notes(fig):
        return {a.get_ylabel().split(" ")[0]: [x.get_text() for x in a.texts] for a in fig.axes}

    for stem in ("fluid_force", "oil_com"):
        texts = notes(plots.figure(ds, stem))
        assert any("after 6.94 s" in x and "discretization error" in x for x in texts["Lateral"]), stem
        assert not any("discretization" in x for k, v in texts.items() if k != "Lateral" for x in v), stem
    del res["mirror_symmetry"]
    clean = notes(plots.figure(results.to_dataset(res), "fluid_force"))
    assert not any("discretization" in x for v in clean.values() for x in v)


def test_the_lateral_panels_of_a_mirror_symmetric_slosh_run_are_hatched_too():
    """Issue 16: slosh runs on mirror-symmetric inputs are watched as vehicle runs are
    (railslosh.scene.run.mirror_symmetry), so their lateral force and centre-of-mass panels carry
    the same hatch from the time the lateral load strays."""
    t = np.linspace(0.0, 2.0, 201)
    f = np.zeros((t.size, 3))
    f[:, 0] = 5.0 * np.sin(3.0 * t)
    f[:, 1] = 1e-6 * np.exp(8.0 * t)
    f[:, 2] = -21.4
    res = {"t": t, "force_tank": f, "com_tank": f / 100.0}
    res["mirror_symmetry"] = {"inputs": "mirror-symmetric", "limit": 0.0137, "lateral_valid_until": 1.2}
    ds = results.to_dataset(res)
    for stem in ("slosh_force", "slosh_com"):
        fig = plots.figure(ds, stem)
        texts = {a.get_ylabel().split(" ")[0]: [x.get_text() for x in a.texts] for a in fig.axes}
        assert any("after 1.2 s" in x and "discretization error" in x for x in texts["Lateral"]), stem
        assert not any("discretization" in x for k, v in texts.items() if k != "Lateral" for x in v), stem
