"""Validation records: the one definition of the record every ``railslosh validate`` case prints
(Rust's ``railslosh_cases::Record``: case, quantity, measured, reference, tolerance, passed),
the builders the Python cases use, and the exception of a case that cannot run."""

from __future__ import annotations

import math

Record = dict[str, object]
"""One check of a validation case."""


class CaseSkipped(Exception):
    """A case could not run because its external reference data were not found (not a failure)."""


def record(case: str, quantity: str, measured: float, reference: float, tolerance: float, passed: bool) -> Record:
    """A record with its verdict given."""
    return {
        "case": case,
        "quantity": quantity,
        "measured": float(measured),
        "reference": float(reference),
        "tolerance": float(tolerance),
        "passed": bool(passed),
    }


def within(case: str, quantity: str, measured: float, reference: float, tolerance: float) -> Record:
    """Passes when ``|measured - reference| <= tolerance`` (and ``measured`` is finite)."""
    passed = math.isfinite(measured) and abs(measured - reference) <= tolerance
    return record(case, quantity, measured, reference, tolerance, passed)


def at_most(case: str, quantity: str, measured: float, limit: float) -> Record:
    """Passes when ``|measured| <= limit`` (reference 0, tolerance ``limit``)."""
    return record(case, quantity, measured, 0.0, limit, math.isfinite(measured) and abs(measured) <= limit)


def less_than(case: str, quantity: str, measured: float, limit: float) -> Record:
    """Passes when ``measured < limit`` (reference ``limit``, tolerance 0)."""
    return record(case, quantity, measured, limit, 0.0, not math.isnan(measured) and measured < limit)
