"""The tool as a user gets it (issue 9): the built wheel installs into a fresh virtual environment,
its ``railslosh`` command runs every example scene (quick forms) and writes results, plots and
ParaView files, and the HTML report renders in headless Chromium.

The wheel is the one ``scripts/test-all`` builds (``$RAILSLOSH_WHEEL``, else the newest
``dist/wheels/railslosh-*.whl``); without one the test is skipped. The fresh environment gets the
wheel itself (no network: its dependencies are taken from the test environment through a ``.pth``
file, after the fresh site-packages, so ``railslosh`` is imported from the fresh install).
Chromium is looked up as ``chromium``, ``chromium-browser``, ``google-chrome`` (or
``$RAILSLOSH_CHROMIUM``); without it the screenshot check is skipped with that reason.
"""

import json
import os
import shutil
import site
import subprocess
import sys
import sysconfig
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples" / "scenes").glob("*.toml"))
QUICK_T_END = 0.02  # s: one recording interval of the fluid scenes


def _wheel() -> Path | None:
    env = os.environ.get("RAILSLOSH_WHEEL")
    if env:
        return Path(env)
    wheels = sorted((ROOT / "dist" / "wheels").glob("railslosh-*.whl"), key=lambda p: p.stat().st_mtime)
    return wheels[-1] if wheels else None


@pytest.fixture(scope="module")
def fresh_venv(tmp_path_factory):
    wheel = _wheel()
    if wheel is None or not wheel.is_file():
        pytest.skip("no built wheel: run `maturin build --release -o dist/wheels` (scripts/test-all does)")
    d = tmp_path_factory.mktemp("fresh")
    venv = d / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True)
    py = venv / "bin" / "python"
    purelib = subprocess.run(
        [str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    # dependencies from this environment, searched after the fresh site-packages
    deps = [p for p in [*site.getsitepackages(), sysconfig.get_paths()["purelib"]] if Path(p).is_dir()]
    Path(purelib, "_railslosh_test_deps.pth").write_text("\n".join(dict.fromkeys(deps)) + "\n")
    r = subprocess.run(
        [sys.executable, "-m", "pip", "--python", str(py), "install", "-q", "--no-index", "--no-deps"]
        + ["--ignore-installed", str(wheel)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert r.returncode == 0, r.stderr
    return venv, d


def _run(venv: Path, *args: str, cwd: Path, timeout: float = 300) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    env["MPLBACKEND"] = "Agg"
    return subprocess.run(
        [str(venv / "bin" / args[0]), *args[1:]], capture_output=True, text=True, cwd=cwd, env=env, timeout=timeout
    )


def test_the_wheel_installs_and_its_command_runs(fresh_venv):
    venv, d = fresh_venv
    r = _run(venv, "python", "-c", "import railslosh, sys; print(railslosh.__file__)", cwd=d)
    assert r.returncode == 0 and r.stdout.strip().startswith(str(venv)), r.stdout + r.stderr
    r = _run(venv, "railslosh", "--version", cwd=d)
    assert r.returncode == 0 and r.stdout.startswith("railslosh ")
    r = _run(venv, "railslosh", "run", "--help", cwd=d)
    assert r.returncode == 0 and "--t-end" in r.stdout


_LOOP = """
import json, sys
from railslosh.cli import main
codes = {}
for path in sys.argv[2:]:
    stem = path.rsplit("/", 1)[-1][:-5]
    # plots are drawn once (first example, and by the report test): they cost more than a quick run
    codes[stem] = main(["run", path, "-o", f"out/{stem}", "--t-end", sys.argv[1], "-q", "--set", "outputs.plots=false"])
print(json.dumps(codes))
"""


def test_every_example_runs_from_the_installed_tool(fresh_venv):
    venv, d = fresh_venv
    first, rest = EXAMPLES[0], EXAMPLES[1:]
    # the first through the console script, exactly as typed by a user, the others in one process
    r = _run(venv, "railslosh", "run", str(first), "-o", f"out/{first.stem}", "--t-end", str(QUICK_T_END), cwd=d)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "100.0%" in r.stderr and "Newton" in r.stderr
    r = _run(venv, "python", "-c", _LOOP, str(QUICK_T_END), *map(str, rest), cwd=d, timeout=900)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    codes = json.loads(r.stdout.strip().splitlines()[-1])
    assert codes == {p.stem: 0 for p in rest}
    for p in EXAMPLES:
        out = d / "out" / p.stem
        summary = json.loads((out / "run.json").read_text())
        assert summary["t_reached"] == pytest.approx(QUICK_T_END) and summary["error"] is None, p.stem
        assert (out / "results.nc").is_file(), p.stem
        assert any((out / "plots").glob("*.png")) == (p == first), p.stem
        if summary["kind"] == "fluid_vehicle" and summary.get("fluid_model") == "ancf":
            # the ANCF liquid's snapshots (a liquid run as rigid lading or pendulum has no mesh)
            assert (out / "fluid.pvd").is_file() and any((out / "fluid").glob("*.vtu")), p.stem


def _chromium() -> str | None:
    env = os.environ.get("RAILSLOSH_CHROMIUM")
    if env:
        return env
    for name in ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable"):
        found = shutil.which(name)
        if found:
            return found
    return None


def test_report_renders_in_headless_chromium(fresh_venv):
    venv, d = fresh_venv
    stem = "two_car_ecp_braking_rigid"
    out = d / "out" / stem
    if not (out / "results.nc").is_file():
        r = _run(
            venv,
            "railslosh",
            "run",
            str(ROOT / f"examples/scenes/{stem}.toml"),
            "-o",
            str(out),
            "--t-end",
            "0.1",
            cwd=d,
        )
        assert r.returncode == 0, r.stderr
    r = _run(venv, "railslosh", "report", str(out), cwd=d)
    assert r.returncode == 0, r.stderr
    html = out / "report.html"
    chromium = _chromium()
    if chromium is None:
        pytest.skip("no headless Chromium (apt-get install chromium; scripts/test-all installs it when it can)")
    shot = d / "report.png"
    width, height = 1280, 1600
    cmd = [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars", "--disable-dev-shm-usage"]
    cmd += [f"--window-size={width},{height}", f"--screenshot={shot}", html.as_uri()]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=120, check=False)
    assert r.returncode == 0 and shot.is_file(), r.stderr[-3000:]
    import matplotlib.image

    img = matplotlib.image.imread(shot)[..., :3]
    assert img.shape[:2] == (height, width)
    rgb = (img * 255).round().astype(int)
    nonwhite = (rgb < 245).any(axis=2).mean()
    assert nonwhite > 0.02, f"screenshot nearly blank ({nonwhite:.3%} non-white pixels)"
    colours = np.unique(rgb.reshape(-1, 3), axis=0)
    assert len(colours) > 50, "screenshot has too few colours to hold the text and the plots"
    # the embedded plots rendered: the page text and tables are grey, the plot lines coloured
    saturated = (rgb.max(axis=2) - rgb.min(axis=2) > 60).sum()
    assert saturated > 300, f"no plot lines visible ({saturated} coloured pixels)"
