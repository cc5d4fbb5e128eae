"""Validation cases of ``railslosh validate``.

Each case returns records with the keys ``case, quantity, measured, reference, tolerance,
passed``: one measured quantity against its reference. Element-level cases are implemented
in Rust (``railslosh._core.run_validation``), so the CLI, the Python tests and the Rust
tests run exactly the same checks. Cases that only exercise Python code (the co-simulation
masters, ``railslosh.cosim.cases``) are registered from Python.

Cases that compare with external reference data (``manchester-contact-left`` reads the CONTACT
benchmark files from ``$RAILSLOSH_SHARED_DATA/manchester-contact``, by default from
``../shared/data`` next to the repository or ``shared/data`` in a parent of the current
directory) raise :class:`CaseSkipped` when the data are absent; ``railslosh validate`` reports
them as "skipped: data not found" and they count neither as passed nor as failed.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from railslosh import _core
from railslosh.records import CaseSkipped, Record


@dataclass(frozen=True)
class Case:
    """A validation case: a name, what it shows, and how to run it."""

    name: str
    description: str
    run: Callable[[bool], list[Record]]


def _rust_case(name: str) -> Callable[[bool], list[Record]]:
    def run(quick: bool) -> list[Record]:
        try:
            return list(_core.run_validation(name, quick))
        except _core.DataNotFoundError as exc:
            raise CaseSkipped(f"{name}: skipped: {exc}") from exc

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
    "slosh-cylinder-half": "half-full horizontal cylinder: stable rest state, transverse mode lambda vs 1.3557 "
    "(linear modes; full form also the pulse response), longitudinal mode vs the rectangular-tank formula",
    "slosh-viscous-decay": "free sloshing decays faster from water through the crude oils of seed 000 Table 2 "
    "(water and light crude ordered by viscous power per kinetic energy); heavy crude settles within one period",
    "bulkhead-longitudinal": "three-compartment tank car has a lower peak longitudinal load than the open tank "
    "under the same braking pulse",
    "tank-frame-equivalence": "same manoeuvre as tank-frame pseudo-forces and as prescribed inertial motion: "
    "same loads within 1 %",
    "slosh-linear-potential-flow": "seed 003 rectangular tank, 0.03 g lateral pulse (linear regime): lateral load "
    "history vs the 50-mode linear potential-flow solution, RMS difference over 0.5-4 s <= 10 % of its peak; "
    "first-mode frequency from zero crossings vs 1.436 Hz; viscous power per kinetic energy vs the modes' "
    "8 nu k^2 (Lamb)",
    "slosh-load-convergence": "seed 003 rectangular tank, 0.3 g lateral pulse: peak lateral load after the pulse and "
    "f1 from zero crossings of the raw load change <= 5 % between the two finest of three meshes and two step sizes; "
    "raw zero-crossing frequency within 3 % of the spectral peak (no chatter)",
    "rest-state": "the liquid at rest on the default and shipped meshes (SwRI, rectangular tank, tank car with heads), "
    "with the recommended shear stabilization: smallest eigenvalue of the linearization about the settled state >= 0",
    "manchester-contact-left": "Manchester contact benchmark A2.2, left wheel (S1002 on UIC60 1:40, 10 kN, shifts "
    "0-10 mm) vs CONTACT: contact position, normal force, creep forces; full form also Polach, FASTSIM and the "
    "Kik-Piotrowski patch (needs shared data)",
    "static-wheel-loads": "68-DOF tank car (36 t rigid lading) settles on tangent track: every wheel load equals "
    "its static share within 1 %, no drift",
    "balance-speed-curving": "tank car on a 1000 m curve (balance speed 60 km/h): outer/inner wheel loads equal "
    "within 5 % at the balance speed, outer heavier above it, inner heavier below it",
    "lateral-stability": "tank car at 60 km/h on tangent track: a 2 mm lateral wheelset disturbance decays",
    "ecp-braking-oils": "two cars with half-full tanks of crude, ECP braking 40 -> 5 km/h in 10 s: peak coupler force "
    "heavy 15-45 % below light (paper ~30 %), coupler oscillation dies out sooner for the heavy crude",
    "conventional-braking": "front car only braking: coupler compressive, mean magnitude several times ECP, "
    "oils differ little",
    "bulkhead-reduction": "light crude, ECP: two bulkheads cut the peak coupler force by 50-85 % (paper ~70 %) and the "
    "front/rear bogie normal-force difference",
    "curve-outward-inertia": "one car on the Table 1 curve at 60 and 100 km/h: outward inertia force of the oil vs the "
    "in-plane gravity component, growing with density",
    "mesh-convergence": "one car braking with light crude on three meshes: oil centre-of-mass trajectories agree",
    "coupler-force-convergence": "two cars braking (ECP with identical brakes and with a 10 % weaker rear brake, "
    "conventional) with light crude: peak of the low-passed "
    "coupler force, its RMS and steady mean change <= 5 % between the two finest of three meshes and two steps",
    "klingel-wavelength": "kinematic (no-slip) free coned wheelset: lateral oscillation wavelength vs Klingel's "
    "2 pi sqrt(r0 b / lambda)",
    "contact-mirror-symmetry": "S1002 on UIC60 1:40, 60 kN: the right wheel at shift y, yaw, roll equals the mirrored "
    "left wheel at -y, -yaw, -roll to 1e-9 (forces, moments, normal forces), 201 shifts -10..+10 mm across the "
    "contact-point jumps (quick: one yaw/roll pose, full: three)",
    "contact-sweep-refinement": "S1002 on UIC60 1:40, 60 kN, swept 0-10 mm towards the flange in steps down to "
    "0.05 mm with the search warm-started: contact points equal a fresh search's, jump locations nest as the step "
    "is refined (quick: left wheel, 0.5 and 0.25 mm)",
    "contact-variable-friction": "S1002 on UIC60 1:40, lubricated gauge face (mu 0.1) and dry top (mu 0.4): each "
    "patch of a two-point contact saturates at the mu of its own location; uniform map = scalar friction",
    "contact-nadal-climb": "S1002 on UIC60 1:40, 50 kN, saturated lateral creepage: in flange contact L/V equals "
    "Nadal's (tan d - mu)/(1 + mu tan d) at each contact angle and peaks at Nadal's limit at 70 deg "
    "(quick: mu 0.3; full: mu 0.3 and 0.5)",
}

CASES: dict[str, Case] = {
    name: Case(name, _DESCRIPTIONS.get(name, ""), _rust_case(name)) for name in _core.validation_cases()
}


def _python_cases() -> dict[str, Case]:
    """Cases implemented in Python (name -> (description, run(quick) -> records))."""
    from railslosh.cosim.cases import PY_CASES
    from railslosh.fmu import FMU_CASES
    from railslosh.irregularity import VALIDATION_CASES as IRREGULARITY_CASES
    from railslosh.swri_cases import SWRI_CASES
    from railslosh.truck_cases import TRUCK_CASES

    cases = {**PY_CASES, **FMU_CASES, **SWRI_CASES, **IRREGULARITY_CASES, **TRUCK_CASES}
    return {name: Case(name, desc, fn) for name, (desc, fn) in cases.items()}


CASES.update(_python_cases())


def run(
    names: list[str] | None = None, *, quick: bool = False, skipped: list[dict[str, str]] | None = None
) -> list[Record]:
    """Run the named cases (all when ``names`` is empty) and return every record.

    A case whose reference data are missing raises :class:`CaseSkipped`, unless a ``skipped`` list is
    given: then ``{"case": name, "reason": message}`` is appended to it and the other cases still run.
    """
    names = list(names or CASES)
    unknown = [n for n in names if n not in CASES]
    if unknown:
        raise ValueError(f"invalid `case` = {unknown}: expected {sorted(CASES)}")
    records: list[Record] = []
    for n in names:
        try:
            records.extend(CASES[n].run(quick))
        except CaseSkipped as exc:
            if skipped is None:
                raise
            skipped.append({"case": n, "reason": str(exc)})
    return records
