"""The command-line tool as a user runs it."""

import json
import re
import subprocess
import sys

import pytest

import railslosh as rs
from railslosh import cli, scene, validate


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "railslosh", *args], capture_output=True, text=True, check=False)


def test_validate_lists_its_cases():
    out = run_cli("validate", "--list")
    assert out.returncode == 0
    for case in (
        "element-mass",
        "element-jacobians",
        "rigid-motion-invariance",
        "hydrostatic-cylinder",
        "slosh-rect-tank",
        "tank-frame-equivalence",
        "slosh-cylinder-half",
        "slosh-viscous-decay",
        "bulkhead-longitudinal",
    ):
        assert case in out.stdout


def test_validate_json_records_have_the_required_keys_and_pass():
    out = run_cli("validate", "--quick", "--json", "element-mass", "element-jacobians", "rigid-motion-invariance")
    assert out.returncode == 0, out.stderr
    doc = json.loads(out.stdout)
    assert doc["failed"] == 0 and doc["passed"] == len(doc["records"]) > 20
    for rec in doc["records"]:
        assert set(rec) == {"case", "quantity", "measured", "reference", "tolerance", "passed"}
    cases = {r["case"] for r in doc["records"]}
    assert cases == {"element-mass", "element-jacobians", "rigid-motion-invariance"}


def test_validate_default_output_is_json_lines():
    out = run_cli("validate", "element-mass")
    assert out.returncode == 0
    lines = out.stdout.strip().splitlines()
    assert all(json.loads(line)["case"] == "element-mass" for line in lines)
    assert "0 failed" in out.stderr


def test_a_failing_case_sets_a_nonzero_exit_status(monkeypatch, capsys):
    def failing(quick):
        return [dict(case="always-fails", quantity="x", measured=1.0, reference=0.0, tolerance=0.1, passed=False)]

    monkeypatch.setitem(validate.CASES, "always-fails", validate.Case("always-fails", "test", failing))
    assert cli.main(["validate", "always-fails"]) == 1
    assert cli.main(["validate", "element-mass"]) == 0
    capsys.readouterr()


def test_unknown_case_is_a_usage_error():
    out = run_cli("validate", "no-such-case")
    assert out.returncode == 2
    assert "no-such-case" in out.stderr


@pytest.mark.parametrize("oil", ["light", "heavy"])
def test_demo_runs_and_reports(oil):
    out = run_cli("demo", "--oil", oil, "--t-end", "1.0")
    assert out.returncode == 0, out.stderr
    assert "1260 coordinates" in out.stdout
    assert "peak longitudinal load" in out.stdout
    assert "0 failed" in out.stdout


# --- run / plot / report / sweep (issue 9) -----------------------------------------------------

EXAMPLES = __import__("pathlib").Path(__file__).resolve().parents[1] / "examples" / "scenes"


def test_run_plot_report_as_a_user_does(tmp_path):
    out = tmp_path / "ecp"
    r = run_cli("run", str(EXAMPLES / "two_car_ecp_braking_rigid.toml"), "-o", str(out), "--t-end", "0.05")
    assert r.returncode == 0, r.stderr
    assert "100.0% t = 0.050/0.05 s" in r.stderr and "ETA" in r.stderr and "Newton" in r.stderr
    for f in ("results.nc", "run.json", "plots/coupler_force.png"):
        assert (out / f).is_file(), f
    summary = json.loads((out / "run.json").read_text())
    assert summary["t_reached"] == 0.05 and summary["stats"]["steps"] > 0 and summary["error"] is None
    # plot and report in-process (the same entry point as the command; saves two interpreter starts)
    assert cli.main(["plot", str(out / "results.nc"), "-o", str(tmp_path / "p")]) == 0
    assert (tmp_path / "p" / "wheel_loads.png").is_file()
    assert cli.main(["report", str(out)]) == 0 and (out / "report.html").is_file()


def test_a_run_with_overrides_is_titled_with_them(tmp_path, capsys):
    """Plots, report and results.nc of ``--set fluid.oil=heavy`` on a light-crude scene do not say
    "light crude" alone."""
    from railslosh import results

    scene_file = str(EXAMPLES / "two_car_ecp_braking_rigid.toml")
    args = ["run", scene_file, "-q", "--t-end", "0.02"]
    assert cli.main([*args, "-o", str(tmp_path / "a"), "--set", "train.speed_kmh=30"]) == 0
    assert cli.main([*args, "-o", str(tmp_path / "b"), "--set", "scene.name=slow"]) == 0
    assert cli.main([*args, "-o", str(tmp_path / "c")]) == 0
    capsys.readouterr()
    titles = [results.load(tmp_path / d / "results.nc").attrs["title"] for d in "abc"]
    name = titles[2] or "two_car_ecp_braking_rigid"  # a scene without [scene] name: its file's stem
    assert titles == [f"{name} [train.speed_kmh=30]", "slow", titles[2]]


def test_run_set_overrides_and_errors(tmp_path, capsys):
    scene_file = str(EXAMPLES / "two_car_ecp_braking_rigid.toml")
    r = run_cli("run", scene_file, "-o", str(tmp_path), "--set", "train.speed_kmh=500", "-q")
    assert r.returncode == 2 and "invalid `train.speed_kmh` = 500: expected a speed" in r.stderr

    def status(*args):
        code = cli.main(list(args))
        return code, capsys.readouterr().err

    code, err = status("run", scene_file, "--set", "speed=5")
    assert code == 2 and "invalid `--set`" in err
    code, err = status("run", str(tmp_path / "missing.toml"))
    assert code == 2 and "missing.toml" in err
    code, err = status("plot", str(tmp_path / "none.nc"))
    assert code == 2 and "invalid `results`" in err


def test_progress_bar_line_shows_time_eta_and_newton_statistics():
    import io

    bar = cli.ProgressBar(stream=io.StringIO(), every=0.0)
    bar.start -= 10.0  # 10 s of wall time so far
    line = bar.line(2.5, 10.0, 200, 900, 7)
    assert "25.0%" in line and "t = 2.500/10 s" in line and "200 steps (7 rejected)" in line
    assert "Newton 4.50/step" in line
    eta = float(re.search(r"ETA\s+([0-9.]+) s", line).group(1))
    assert eta == pytest.approx(30.0, rel=0.01)  # 10 s for the first quarter: 30 s to go
    bar(10.0, 10.0, 400, 1800, 7)
    assert bar.stream.getvalue().strip().startswith("100.0% t = 10.000/10 s")


def test_progress_true_shows_a_rich_bar_on_a_terminal_and_lines_elsewhere(capsys):
    """Issue 19: API runs show progress with `progress=True` (a rich bar on a terminal, a plain
    line per few seconds and at the end otherwise); the bar is closed when the run fails too."""
    import io

    from railslosh import progress

    class Terminal(io.StringIO):
        def isatty(self):
            return True

    bar = progress.ProgressBar(stream=Terminal(), description="demo run")
    bar(5.0, 10.0, 100, 450, 2)
    assert bar._bar is not None
    bar(10.0, 10.0, 200, 900, 2)
    assert bar._bar is None  # stopped at the end
    drawn = bar.stream.getvalue()
    assert "demo run" in drawn and "100.0%" in drawn and "Newton 4.50/step" in drawn
    sc = scene.load_scene(EXAMPLES / "swri_lane_change_20mph.toml", {"solver": {"t_end": 0.05}})
    args, kw = sc.run_args()
    rs.slosh.run(*args, **{**kw, "progress": True})
    err = capsys.readouterr().err
    assert "100.0% t = 0.050/0.05 s" in err and "Newton" in err
    with pytest.raises(ValueError, match="invalid `progress` = 'yes'"):
        rs.slosh.run(*args, **{**kw, "progress": "yes"})


def test_sweep_command_writes_one_dataset(tmp_path):
    r = run_cli(
        "sweep",
        str(EXAMPLES / "two_car_ecp_braking_rigid.toml"),
        "--grid",
        "braking=ecp,conventional",
        "--set",
        "train.t_end=0.03",
        "--workers",
        "2",
        "-o",
        str(tmp_path),
    )
    assert r.returncode == 0, r.stderr
    from railslosh import results

    ds = results.load(tmp_path / "sweep.nc")
    assert ds.sizes["braking"] == 2 and "2/2 runs done" in r.stderr


# --- every user mistake is one line on stderr, in one form, exit 2, no traceback (issue 19) --------

SWRI = str(EXAMPLES / "swri_lane_change_20mph.toml")
RIGID = str(EXAMPLES / "two_car_ecp_braking_rigid.toml")


@pytest.fixture(scope="module")
def mistakes(tmp_path_factory):
    """Files a user gets wrong: a scene with a misspelled section, an empty scene, a 'results.nc'
    that is not netCDF, a results directory holding one."""
    d = tmp_path_factory.mktemp("mistakes")
    (d / "typo.toml").write_text('[solver]\nt_end = 1.0\n[manuever]\ntype = "pulse"\n')
    (d / "empty.toml").write_text("# nothing here\n")
    (d / "some.toml").write_text('[track]\npreset = "tangent"\n')
    (d / "results.nc").write_text("not netCDF\n")
    (d / "run").mkdir()
    (d / "run" / "results.nc").write_text("not netCDF either\n")
    return d


CLI_MISTAKES = [
    # (arguments, with {d} the mistakes directory; what stderr must say)
    (["run", "{d}/typo.toml"], "invalid `manuever`: unknown section (did you mean `maneuver`?)"),
    (
        ["run", "{d}/empty.toml"],
        "invalid `scene` = '{d}/empty.toml': expected a vehicle scene ([track], [train], ...) or a slosh scene "
        "([maneuver], [tank], ...); the file is empty (no sections)",
    ),
    (["run", "{d}/missing.toml"], "invalid `scene` = '{d}/missing.toml': no such file"),
    (["run", "{d}/missing"], "invalid `scene` = '{d}/missing': no such file"),
    (["run", "{d}/run"], "invalid `scene` = '{d}/run': a directory"),
    (["run", SWRI, "--set", "solver.t_end=-1"], "invalid `solver.t_end` = -1: expected a time > 0 s and ≤ 600 s"),
    (["run", SWRI, "--set", "solver.t_end=abc"], "invalid `solver.t_end` = 'abc': expected a time"),
    (["run", SWRI, "--set", "solver.tend=1"], "invalid `solver.tend`: unknown key (did you mean `solver.t_end`?)"),
    (
        ["run", SWRI, "--set", "outputs.snapshot_every=0.001"],
        "invalid `outputs.snapshot_every` = 0.001: expected 0 (none) or an interval ≥ solver.step = 0.01 s",
    ),
    (["run", SWRI, "--set", "fluid.fill=0.99"], "invalid `fluid.fill` = 0.99: expected a volume fraction from 0.03"),
    (["run", SWRI, "--set", "a.b.c=1"], "invalid `--set` = 'a.b.c': expected a field section.key"),
    (["run", SWRI, "--set", "solver"], "invalid `--set` = 'solver': expected section.key=VALUE"),
    (["run", RIGID, "-o", "{d}/some.toml"], "invalid `--out` = '{d}/some.toml': expected a directory"),
    (["plot", "{d}/results.nc"], "invalid `results` = '{d}/results.nc': expected a results.nc written by"),
    (["plot", "{d}/some.toml"], "(this is not a netCDF file)"),
    (["plot", "{d}/none.nc"], "invalid `results` = '{d}/none.nc': no such file"),
    (["report", "{d}/run"], "invalid `results_dir/results.nc` = '{d}/run/results.nc': expected a results.nc"),
    (["report", "{d}/nodir"], "invalid `results_dir` = '{d}/nodir': expected a directory written by"),
    (["sweep", SWRI, "--grid", "fil=0.5,0.6"], "invalid `--grid fil`: unknown grid name (did you mean `fill`?)"),
    (["sweep", SWRI, "--grid", "fill"], "invalid `--grid` = 'fill': expected NAME=V1,V2,..."),
    (["sweep", SWRI, "--grid", "fill=0.5,2"], "sweep point {'fill': 2}: invalid `fluid.fill` = 2: expected"),
    (["sweep", "{d}/missing.toml", "--grid", "fill=0.5"], "invalid `scene` = '{d}/missing.toml': no such file"),
    (["sweep", SWRI, "--grid", "fill=0.5", "--workers", "0"], "argument --workers: '0': expected a whole number ≥ 1"),
    (["demo", "--fill", "0.99"], "argument --fill: '0.99': expected a volume fraction from 0.03 to 0.97"),
    (["validate", "no-such-case"], "invalid `case` = ['no-such-case']: expected"),
    (["bench", "no-such-sweep"], "invalid `case` = ['no-such-sweep']: expected"),
]


def _id(args):
    return " ".join(a.rsplit("/", 1)[-1] for a in args)


@pytest.mark.parametrize(("args", "says"), CLI_MISTAKES, ids=[_id(a) for a, _ in CLI_MISTAKES])
def test_a_user_mistake_is_one_line_and_exit_2(mistakes, args, says):
    r = run_cli(*(a.replace("{d}", str(mistakes)) for a in args))
    assert r.returncode == 2, r.stderr
    assert "Traceback" not in r.stderr and says.replace("{d}", str(mistakes)) in r.stderr, r.stderr
    if not any(a.startswith("--") and "argument" in says for a in args):  # argparse adds its usage line
        assert len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "invalid parameter" not in r.stderr and "allowed" not in r.stderr


def test_help_has_examples_and_no_markup():
    top = run_cli("--help").stdout
    assert "examples:" in top and "railslosh run examples/scenes/" in top and "``" not in top
    for command in ("demo", "run", "plot", "report", "sweep", "validate", "bench"):
        text = run_cli(command, "--help").stdout
        assert "examples:" in text and f"railslosh {command}" in text, command
    parser = cli.build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    for name, p in sub.choices.items():
        for action in p._actions:
            assert action.help, f"railslosh {name} {action.option_strings or action.dest} has no help"
    run = run_cli("run", "--help").stdout
    sweep = run_cli("sweep", "--help").stdout
    assert "repeat --set" in " ".join(run.split()) and "repeat --grid" in " ".join(sweep.split())
    assert "seconds" not in run_cli("bench", "--help").stdout.split("--quick")[1].split("\n")[0]
