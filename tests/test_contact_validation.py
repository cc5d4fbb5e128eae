"""Quick forms of the wheel/rail contact validation cases, run through the installed wheel.

`manchester-contact-left` compares with CONTACT's reference output for the Manchester benchmark
A2.2; it reads the data from the shared data directory and is skipped (never failed) when they
are absent. `klingel-wavelength` is kinematic and needs no data; nor do the four cases across the
profile (issue 21: mirror symmetry, sweep refinement across the jumps, variable friction, Nadal
flange climb), which run on the analytic S1002 wheel and UIC 60 rail.
"""

import json
import math
import os
import subprocess
import sys

import pytest

from railslosh import validate

CONTACT_CASES = [
    "manchester-contact-left",
    "klingel-wavelength",
    "contact-mirror-symmetry",
    "contact-sweep-refinement",
    "contact-variable-friction",
    "contact-nadal-climb",
]


def run_cli(*args, env=None):
    full_env = None if env is None else {**os.environ, **env}
    return subprocess.run(
        [sys.executable, "-m", "railslosh", *args], capture_output=True, text=True, check=False, env=full_env
    )


def quick_records(case):
    try:
        return validate.run([case], quick=True)
    except validate.CaseSkipped as exc:
        pytest.skip(str(exc))


@pytest.mark.parametrize("case", CONTACT_CASES)
def test_quick_contact_case_passes(case):
    records = quick_records(case)
    assert len(records) >= 2
    failed = [r for r in records if not r["passed"]]
    assert not failed, failed


def test_manchester_records_cover_position_normal_force_and_creep():
    records = quick_records("manchester-contact-left")
    text = " ".join(str(r["quantity"]) for r in records)
    for word in ("lateral position", "vertical load balance", "normal force", "FX", "FS"):
        assert word in text, word
    position = next(r for r in records if "lateral position on the rail" in str(r["quantity"]))
    assert position["tolerance"] == 1.0 and position["measured"] < 1.0
    creep = [r for r in records if "creep force" in str(r["quantity"])]
    assert creep and all(r["tolerance"] == 0.15 for r in creep)


def test_klingel_is_labelled_kinematic_and_within_three_percent():
    records = quick_records("klingel-wavelength")
    wave = next(r for r in records if "wavelength" in str(r["quantity"]))
    assert "kinematic" in str(wave["quantity"])
    assert abs(wave["measured"] - wave["reference"]) <= 0.03 * wave["reference"]
    assert wave["tolerance"] == pytest.approx(0.03 * wave["reference"])


def test_the_mirror_sweep_crosses_both_contact_point_jumps():
    records = quick_records("contact-mirror-symmetry")
    assert "201 shifts" in str(records[0]["quantity"])
    jumps = next(r for r in records if "jumps" in str(r["quantity"]))
    assert jumps["measured"] >= 2
    for rec in records:
        if "worst" in str(rec["quantity"]):
            assert rec["tolerance"] == 1e-9


def test_the_nadal_case_compares_with_nadal_at_70_degrees():
    records = quick_records("contact-nadal-climb")
    peak = next(r for r in records if "largest L/V" in str(r["quantity"]))
    mu, tan = 0.3, math.tan(math.radians(70.0))
    assert peak["reference"] == pytest.approx((tan - mu) / (1 + mu * tan), rel=1e-12)
    assert peak["tolerance"] == pytest.approx(2e-3 * peak["reference"])


def test_cli_json_for_the_manchester_case():
    out = run_cli("validate", "manchester-contact-left", "--quick", "--json")
    assert out.returncode == 0, out.stderr
    doc = json.loads(out.stdout)
    if doc["skipped"]:
        pytest.skip(doc["skipped"][0]["reason"])
    assert doc["failed"] == 0 and doc["passed"] == len(doc["records"]) >= 6
    for rec in doc["records"]:
        assert set(rec) == {"case", "quantity", "measured", "reference", "tolerance", "passed"}
        assert rec["case"] == "manchester-contact-left"


def test_missing_data_is_reported_as_skipped_not_failed(tmp_path):
    cases = ["manchester-contact-left", "klingel-wavelength"]
    out = run_cli("validate", *cases, "--quick", "--json", env={"RAILSLOSH_SHARED_DATA": str(tmp_path)})
    assert out.returncode == 0, out.stderr
    assert "skipped: data not found" in out.stderr
    doc = json.loads(out.stdout)
    assert [s["case"] for s in doc["skipped"]] == ["manchester-contact-left"]
    assert str(tmp_path) in doc["skipped"][0]["reason"]
    assert {r["case"] for r in doc["records"]} == {"klingel-wavelength"}
    assert doc["failed"] == 0


def test_missing_data_raises_case_skipped_from_python(monkeypatch, tmp_path):
    monkeypatch.setenv("RAILSLOSH_SHARED_DATA", str(tmp_path / "absent"))
    with pytest.raises(validate.CaseSkipped, match="data not found"):
        validate.run(["manchester-contact-left"], quick=True)
    skipped = []
    assert validate.run(["manchester-contact-left"], quick=True, skipped=skipped) == []
    assert skipped[0]["case"] == "manchester-contact-left"


def test_contact_cases_are_listed():
    out = run_cli("validate", "--list")
    assert out.returncode == 0
    for case in CONTACT_CASES:
        assert case in out.stdout
