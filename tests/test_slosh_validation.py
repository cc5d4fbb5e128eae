"""Quick forms of the sloshing validation cases (issue 3), run through the installed wheel.

Each case integrates the ANCF fluid in a tank with the HHT integrator and compares with an
analytic reference; the full forms run with `railslosh validate <case>`.
"""

import pytest

from railslosh import validate


@pytest.mark.parametrize(
    "case",
    [
        "hydrostatic-cylinder",
        "slosh-rect-tank",
        "slosh-cylinder-half",
        "slosh-viscous-decay",
        "tank-frame-equivalence",
        "bulkhead-longitudinal",
        "slosh-linear-potential-flow",
        "slosh-load-convergence",
        "rest-state",
    ],
)
def test_quick_slosh_case_passes(case):
    records = validate.run([case], quick=True)
    assert len(records) >= 1
    failed = [r for r in records if not r["passed"]]
    assert not failed, failed
