"""One validation-record definition (``railslosh.records``) for every Python case, and no import
cycle between the validation registry and the modules whose cases it lists."""

from __future__ import annotations

import math
import subprocess
import sys

from railslosh import records, validate


def test_record_builders_give_the_documented_verdicts():
    assert records.within("c", "q", 1.05, 1.0, 0.1)["passed"]
    assert not records.within("c", "q", 1.2, 1.0, 0.1)["passed"]
    assert not records.within("c", "q", math.nan, 1.0, 0.1)["passed"]
    assert records.at_most("c", "q", -0.5, 0.5)["passed"] and not records.at_most("c", "q", 0.6, 0.5)["passed"]
    lt = records.less_than("c", "q", 0.9, 1.0)
    assert lt["passed"] and lt["reference"] == 1.0 and lt["tolerance"] == 0.0
    assert not records.less_than("c", "q", 1.0, 1.0)["passed"]
    assert set(records.record("c", "q", 1, 2, 3, True)) == {
        "case",
        "quantity",
        "measured",
        "reference",
        "tolerance",
        "passed",
    }
    assert validate.CaseSkipped is records.CaseSkipped


def test_case_modules_do_not_import_the_registry():
    """``railslosh.validate`` imports the case modules; they must not import it back."""
    code = (
        "import sys, railslosh.fmu, railslosh.swri_cases, railslosh.cosim.cases; "
        "print('railslosh.validate' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"
