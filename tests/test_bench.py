"""`railslosh bench`: the work-precision harness (quick form) as a user runs it."""

from __future__ import annotations

import csv
import json
import math

import pytest

from railslosh import bench
from railslosh.cli import main


def test_sweep_names_and_bad_case():
    assert bench.cases() == ["slosh-tank", "ecp-braking", "ecp-braking-spread"]
    with pytest.raises(ValueError, match="invalid `case`"):
        bench.run(["nope"])


@pytest.fixture(scope="module")
def quick_slosh(tmp_path_factory):
    out = tmp_path_factory.mktemp("bench")
    assert main(["bench", "slosh-tank", "--quick", "-o", str(out)]) == 0
    return out


def test_quick_slosh_sweep_writes_table_json_and_plot(quick_slosh):
    rows = list(csv.DictReader(open(quick_slosh / "work_precision.csv")))
    assert len(rows) == 3
    assert sum(r["reference"] == "True" for r in rows) == 1
    points = json.load(open(quick_slosh / "work_precision.json"))
    assert (quick_slosh / "work_precision_slosh-tank.png").stat().st_size > 10_000
    ref = next(p for p in points if p["reference"])
    # the reference has zero error against itself, and its frequency is within 5 % of the analytic 1.436 Hz
    assert ref["errors"]["frequency_vs_reference_rel"] == 0.0
    assert ref["errors"]["com_history_rel"] == 0.0
    assert ref["errors"]["frequency_vs_analytic_rel"] < 0.05
    for p in points:
        assert p["failure"] is None
        assert p["wall_s"] > 0 and p["steps"] > 0 and p["newton_iterations"] >= p["steps"]
        assert len(p["history"]) == len(p["history_t"]) == 201
    others = [p for p in points if not p["reference"]]
    # coarser settings differ from the reference, but stay close (frequency < 2 %, centre-of-mass history < 5 %)
    for p in others:
        e = p["errors"]
        assert 0.0 < e["com_history_rel"] < 0.05, e
        assert e["frequency_vs_reference_rel"] < 0.02, e
        assert all(math.isfinite(v) for v in e.values())
    # the coarser mesh (16 elements) is less accurate than the reference mesh at a larger step
    by_el = {p["settings"]["elements"]: p for p in others}
    assert by_el[16.0]["errors"]["com_history_rel"] > by_el[36.0]["errors"]["com_history_rel"]
