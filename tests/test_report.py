"""Plots and the HTML report (issue 9): every plot with data is drawn, the report is one
self-contained page (PNGs embedded) whose peak table is the data's."""

import base64
import re

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


def test_plots_are_pngs_of_the_present_variables(run_dir, tmp_path):
    d, _ = run_dir
    ds = results.load(d / "results.nc")
    paths = plots.plot_dataset(ds, tmp_path)
    names = {p.stem for p in paths}
    assert {"coupler_force", "wheel_loads", "l_over_v", "speed"} == names  # rigid run: no fluid plots
    for p in paths:
        data = p.read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 5000


def test_report_is_self_contained_and_its_peaks_are_the_data(run_dir):
    d, res = run_dir
    html_path = report.write_report(d)
    text = html_path.read_text()
    assert html_path == d / "report.html" and text.startswith("<!DOCTYPE html>")
    imgs = re.findall(r'src="data:image/png;base64,([A-Za-z0-9+/=]+)"', text)
    assert len(imgs) == 4
    for b64 in imgs:
        assert base64.b64decode(b64)[:4] == b"\x89PNG"
    assert 'src="http' not in text and "<script" not in text  # nothing fetched from elsewhere
    row = re.search(r"<td>coupler_force</td><td class=\"num\">([^<]+)</td>", text)
    assert float(row.group(1)) == pytest.approx(np.abs(res["coupler_force"]).max(), rel=1e-5)
    assert f"{res['stats']['steps']}" in text


def test_report_of_a_directory_without_results_is_a_clear_error(tmp_path):
    with pytest.raises(ValueError, match=r"invalid parameter `results_dir`.*results.nc"):
        report.write_report(tmp_path)
