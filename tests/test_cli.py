"""The command-line tool as a user runs it."""

import json
import subprocess
import sys

import pytest

from railslosh import cli, validate


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
