"""Validation cases of ``railslosh validate``.

Each case returns records with the keys ``case, quantity, measured, reference, tolerance,
passed``: one measured quantity against its reference. Element-level cases are implemented
in Rust (``railslosh._core.run_validation``), so the CLI, the Python tests and the Rust
tests run exactly the same checks.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from railslosh import _core

Record = dict[str, object]


@dataclass(frozen=True)
class Case:
    """A validation case: a name, what it shows, and how to run it."""

    name: str
    description: str
    run: Callable[[bool], list[Record]]


def _rust_case(name: str) -> Callable[[bool], list[Record]]:
    def run(quick: bool) -> list[Record]:
        return list(_core.run_validation(name, quick))

    return run


_DESCRIPTIONS = {
    "element-mass": "ANCF brick mass matrix (Chrono 3843 reference entry, SPD, rho V on box and curved meshes) "
    "and gravity force",
    "element-jacobians": "exact element Jacobians df/de and df/dedot vs central finite differences, "
    "all five constitutive models",
    "rigid-motion-invariance": "rigid motion gives zero viscous and penalty forces; rotating a deformed state "
    "rotates its forces (objectivity)",
    "hydrostatic-cylinder": "half-full tank car at rest settles: vertical load = m g, no horizontal load or moment, "
    "volume conserved, centroid height",
    "slosh-rect-tank": "seed 003 rectangular tank (0.416 x 0.324 m, 0.132 m water), 0.3 g lateral pulse: "
    "first-mode frequency vs analytic 1.436 Hz",
    "slosh-cylinder-half": "half-full horizontal cylinder: transverse mode lambda vs 1.3557 (full form), "
    "longitudinal mode vs the rectangular-tank formula",
    "slosh-viscous-decay": "free sloshing decays faster from water through the crude oils of seed 000 Table 2; "
    "heavy crude settles within one period",
    "bulkhead-longitudinal": "three-compartment tank car has a lower peak longitudinal load than the open tank "
    "under the same braking pulse",
    "tank-frame-equivalence": "same manoeuvre as tank-frame pseudo-forces and as prescribed inertial motion: "
    "same loads within 1 %",
}

CASES: dict[str, Case] = {
    name: Case(name, _DESCRIPTIONS.get(name, ""), _rust_case(name)) for name in _core.validation_cases()
}


def run(names: list[str] | None = None, *, quick: bool = False) -> list[Record]:
    """Run the named cases (all when ``names`` is empty) and return every record."""
    names = list(names or CASES)
    unknown = [n for n in names if n not in CASES]
    if unknown:
        raise ValueError(f"invalid parameter `case` = {unknown}: allowed {sorted(CASES)}")
    records: list[Record] = []
    for n in names:
        records.extend(CASES[n].run(quick))
    return records
