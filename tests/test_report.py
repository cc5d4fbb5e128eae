"""Plots and the HTML report (issues 9 and 19): every plot with data is drawn; the report is one
self-contained page (PNGs embedded) rendered from its jinja2 template, whose summary table is the
data's after the settling phase, with the scene in engineering units and the run's invariant
margins; it renders in headless Chromium."""

import base64
import re
import shutil
import subprocess

import numpy as np
import pytest

from railslosh import plots, report, results, scene

ROOT = __import__("pathlib").Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("run")
    res = scene.run_scene(
        scene.load_scene(ROOT / "examples/scenes/two_car_ecp_braking_rigid.toml", {"train": {"t_end": 0.1}})
    )
    results.save(results.to_dataset(res), d / "results.nc")
    return d, res


@pytest.fixture(scope="module")
def lane_change(tmp_path_factory):
    """The first 0.6 s of the 20 mph lane change: the liquid released from its unloaded start
    pushes the vertical load to about 1.8 x its weight in the first 10 ms (the start-up spike),
    far above anything after it."""
    d = tmp_path_factory.mktemp("lane_change")
    sc = scene.load_scene(ROOT / "examples/scenes/swri_lane_change_20mph.toml", {"solver": {"t_end": 0.6}})
    res = scene.run_scene(sc)
    ds = results.to_dataset(res, sc)
    results.save(ds, d / "results.nc")
    return d, ds


def _row(text, variable, component="", mode="abs"):
    """(SI value, [cell texts]) of a summary-table row."""
    m = re.search(
        rf'<tr data-variable="{variable}" data-component="{component}" data-mode="{mode}" data-si="([^"]+)">(.*?)</tr>',
        text,
        re.S,
    )
    assert m, f"no summary row for {variable} {component} {mode}"
    cells = [re.sub(r"<[^>]+>", "", c).strip() for c in re.findall(r"<td[^>]*>(.*?)</td>", m.group(2), re.S)]
    return float(m.group(1)), cells


def _num(cell):
    return float(cell.replace("\u2009", "").split(" at ")[0])


def test_plots_are_pngs_of_the_present_variables(run_dir, tmp_path):
    d, _ = run_dir
    ds = results.load(d / "results.nc")
    paths = plots.plot_dataset(ds, tmp_path)
    names = {p.stem for p in paths}
    # rigid run: no fluid plots
    assert {"coupler_force", "wheel_loads", "wheel_unloading", "l_over_v", "wheelset_lateral", "speed"} == names
    for p in paths:
        data = p.read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 5000


def test_report_is_self_contained_and_its_peaks_are_the_data(run_dir):
    d, res = run_dir
    html_path = report.write_report(d)
    text = html_path.read_text()
    assert html_path == d / "report.html" and text.startswith("<!DOCTYPE html>")
    imgs = re.findall(r'src="data:image/png;base64,([A-Za-z0-9+/=]+)"', text)
    assert len(imgs) == len(list((d / "plots").glob("*.png"))) == 6
    for b64 in imgs:
        assert base64.b64decode(b64)[:4] == b"\x89PNG"
    assert 'src="http' not in text and "<script" not in text  # nothing fetched from elsewhere
    # a rigid run has no liquid: no settling phase, the summary covers the whole run
    assert "Headline results over the whole run" in text
    si, cells = _row(text, "coupler_force", mode="max")
    assert si == pytest.approx(np.max(res["coupler_force"]))
    si_min, cells_min = _row(text, "coupler_force", mode="min")
    assert si_min == pytest.approx(np.min(res["coupler_force"]))
    unit, f = plots.display_unit("coupler_force", res["coupler_force"])
    assert cells[3] == unit and _num(cells[2]) == pytest.approx(si * f, rel=1e-3)
    assert cells[1] == "coupler 1 (cars 1–2)"
    si_lv, cells_lv = _row(text, "l_over_v", mode="max")
    assert si_lv == pytest.approx(np.max(res["l_over_v"])) and "0.8 (UIC 518" in cells_lv[5]
    assert f'<td>time steps</td><td class="num">{res["stats"]["steps"]}</td>' in text


def test_report_shows_the_scene_in_engineering_units(run_dir):
    d, _ = run_dir
    text = report.write_report(d).read_text()
    scene_html = text[text.index("<h2>Scene</h2>") :]
    assert "<td>speed</td><td>40 km/h</td>" in scene_html and "11.11" not in text
    assert "<td>torques</td><td>0, 0, 7 kN m</td>" in scene_html
    assert "<td>mass</td><td>36 t</td>" in scene_html and "<td>step</td><td>1 ms</td>" in scene_html
    track = re.search(r'<table id="track">(.*?)</table>', text, re.S).group(1)
    assert track.count("<tr>") == 3 and "tangent" in track  # header + 2 rows, one row per table row
    assert "\\u00a7" not in text and "\\u" not in text
    assert '<td>static wheel load Q₀ (kN)</td><td class="num">78.54</td>' in text  # rounded, in kN


def test_report_summary_excludes_a_start_up_spike_larger_than_the_sloshing_peak(lane_change):
    d, ds = lane_change
    s = results.settling(ds)
    z = ds["force_tank"].sel(component="z")
    t = ds["time"].values
    spike = float(np.abs(z).max())
    after = float(np.abs(z.values[t >= s.time]).max())
    assert s.source == "detected" and 0.0 < s.time < 0.2
    assert spike > 1.5 * after, "the scene's start-up spike is larger than anything after it"
    text = report.write_report(d).read_text()
    assert f"Headline results after settling (t ≥ {report.num(s.time, 3, strip=True)} s)" in text
    assert "Settling phase: 0 ≤ t &lt;" in text
    si, cells = _row(text, "force_tank", "z")
    assert abs(si) == pytest.approx(after) and abs(si) < spike / 1.5
    assert float(cells[4]) >= float(report.num(s.time, 4))  # at t (both as the report shows them)
    assert abs(_num(cells[7])) == pytest.approx(spike, rel=1e-3)  # shown, as excluded
    # through the 20 Hz low-pass: the smooth part of the same load, after settling too
    lp = results.extreme(z, after=s.time, cutoff=20.0)
    assert _num(cells[6]) == pytest.approx(lp.value, rel=1e-3) and lp.time >= s.time
    assert 0.5 * after < abs(lp.value) < 1.1 * after  # a Butterworth overshoots a step by up to 7 %
    # the run's invariant margins
    margins = re.search(r'<table id="margins">(.*?)</table>', text, re.S).group(1)
    gap = ds.attrs["margin_worst_gap"] * 1e3
    assert f"{report.num(gap, 3)} mm" in margins and "smallest volume ratio J" in margins
    assert report.num(ds.attrs["margin_min_volume_ratio"], 4) in margins and "energy growth ε" in margins


def test_report_summary_excludes_the_settling_phase_of_a_synthetic_run(tmp_path):
    t = np.linspace(0.0, 2.0, 1001)
    w = 340e3
    f = np.zeros((len(t), 2, 3))
    f[:, :, 2] = (-w * (1 - np.exp(-t / 0.03) * np.cos(2 * np.pi * 50 * t)))[:, None]  # spike 1.7 w
    f[:, :, 2] -= (0.1 * w * np.sin(np.pi * np.clip(t - 0.5, 0, 1)))[:, None]  # braking: up to 1.1 w
    ds = results.to_dataset({"t": t, "fluid_force_tank": f})
    results.save(ds, tmp_path / "results.nc")
    text = report.write_report(tmp_path).read_text()
    si, cells = _row(text, "fluid_force_tank", "z")
    assert si == pytest.approx(-1.1 * w, rel=2e-3) and cells[3] == "kN"
    assert _num(cells[2]) == pytest.approx(-1.1 * w / 1e3, rel=2e-3)
    assert _num(cells[7]) < -1.6 * w / 1e3  # the spike is in the excluded column only
    # the braking load has no content above 20 Hz: the low-pass keeps its peak
    assert _num(cells[6]) == pytest.approx(-1.1 * w / 1e3, rel=2e-3)
    # declared settling time: honoured and said
    ds.attrs["settle_time"] = 0.5
    results.save(ds, tmp_path / "declared" / "results.nc")
    text = report.write_report(tmp_path / "declared").read_text()
    assert "after settling (t ≥ 0.5 s)" in text and "declared: the scene" in text


def test_report_of_a_directory_without_results_is_a_clear_error(tmp_path):
    with pytest.raises(ValueError, match=r"invalid `results_dir`.*results.nc"):
        report.write_report(tmp_path)


def test_report_of_a_results_file_that_is_not_netcdf_is_a_clear_error(tmp_path):
    (tmp_path / "results.nc").write_text("not netCDF")
    with pytest.raises(ValueError, match=r"invalid results file `.*results\.nc`: not a netCDF file"):
        report.write_report(tmp_path)


def _chromium():
    for name in ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable", "headless_shell"):
        found = shutil.which(name)
        if found:
            return found
    return None


def test_report_in_headless_chromium(lane_change, tmp_path):
    chromium = _chromium()
    if chromium is None:
        pytest.skip("no headless Chromium (chromium, chromium-browser, google-chrome or headless_shell on PATH)")
    d, _ = lane_change
    page = report.write_report(d, tmp_path / "report.html")
    shot = tmp_path / "report.png"
    base = [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars", "--disable-dev-shm-usage"]
    r = subprocess.run(
        [*base, "--window-size=1280,1800", f"--screenshot={shot}", page.as_uri()],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert r.returncode == 0 and shot.is_file(), r.stderr[-3000:]
    import matplotlib.image

    rgb = (matplotlib.image.imread(shot)[..., :3] * 255).round().astype(int)
    assert rgb.shape[:2] == (1800, 1280)
    assert len(np.unique(rgb.reshape(-1, 3), axis=0)) > 50, "blank screenshot"
    assert (rgb < 200).any(axis=2).mean() > 0.01, "almost no text or lines on the page"
    saturated = (rgb.max(axis=2) - rgb.min(axis=2) > 60).sum()
    assert saturated > 300, f"no coloured plot lines visible ({saturated} pixels)"
    dom = subprocess.run([*base, "--dump-dom", page.as_uri()], capture_output=True, text=True, timeout=120)
    assert dom.returncode == 0, dom.stderr[-3000:]
    summary = re.search(r'<table id="summary">(.*?)</table>', dom.stdout, re.S)
    assert summary and "Headline results after settling" in summary.group(1)
    assert "Liquid force on the tank, vertical (z)" in summary.group(1)
