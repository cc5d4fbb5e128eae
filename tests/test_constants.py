"""One definition of each physical constant (issue 18): the Python modules, the binding's defaults
and the FMU use the Rust crate's standard gravity, and no library source carries another value."""

from __future__ import annotations

import inspect
import re
from pathlib import Path

import numpy as np
import pytest

import railslosh as rs
from railslosh import _core, constants, fluid_model, fluids, rail, robustness
from railslosh import fmu as rfmu
from railslosh.cosim import emulators

ROOT = Path(__file__).resolve().parents[1]


def test_every_module_uses_the_one_standard_gravity():
    assert constants.GRAVITY == _core.GRAVITY == 9.80665
    for g in (rail.GRAVITY, rfmu.GRAVITY, robustness.G, fluid_model.G, emulators.GRAVITY):
        assert g == constants.GRAVITY
    assert (constants.FOOT, constants.INCH, constants.MPH) == (0.3048, 0.0254, 0.44704)
    assert inspect.signature(rs.slosh.run).parameters["gravity"].default == (0.0, 0.0, -constants.GRAVITY)


def test_the_binding_defaults_are_the_standard_gravity():
    """The co-simulation participant and the manoeuvre library default to the same g: the
    participant at rest carries its weight at standard gravity, and the seed-003 manoeuvres give
    gravity of that magnitude before they start."""
    k = 1000 * 998 * constants.GRAVITY * 0.1
    fluid = _core.Fluid(998.0, "newtonian", viscosity=0.05, bulk_penalty=k, bulk_damping=0.2 * np.sqrt(k * 998) * 0.05)
    mesh = _core.box_mesh([-0.2, -0.15, 0.0], [0.4, 0.3, 0.1], [1, 1, 1])
    p = _core.SloshParticipant(mesh, fluid, "box", [-0.2, -0.15, 0.0, 0.2, 0.15, 0.25])
    assert p.gravity == constants.GRAVITY
    man = _core.seed003_maneuvers(dt=0.01, t_after=0.1)[0]
    assert np.linalg.norm(np.asarray(man["gravity"])[0]) == pytest.approx(constants.GRAVITY, rel=1e-15)


def _library_lines(pattern: re.Pattern[str], home: str) -> list[str]:
    offenders = []
    for path in [*(ROOT / "python" / "railslosh").rglob("*.py"), *(ROOT / "crates").glob("*/src/**/*.rs")]:
        if path.relative_to(ROOT).as_posix() == home:
            continue
        text = path.read_text()
        if path.suffix == ".rs" and "#[cfg(test)]" in text:
            text = text.split("#[cfg(test)]")[0]  # unit-test systems may use any g
        for n, line in enumerate(text.splitlines(), 1):
            if pattern.search(line):
                offenders.append(f"{path.relative_to(ROOT)}:{n}: {line.strip()}")
    return offenders


def test_no_library_source_defines_another_gravity():
    """9.81 (or 9.8) as a number in library code is a second, rounded gravity."""
    offenders = _library_lines(re.compile(r"(?<![\d.])9\.81?(?![\d])"), "crates/ancf-core/src/constants.rs")
    assert not offenders, "\n".join(offenders)


def test_the_us_units_are_defined_once():
    """Foot, inch and mile per hour appear as numbers only in ``ancf_core::constants``."""
    pattern = re.compile(r"(?<![\d.])(0\.3048|0\.0254|0\.44704)(?![\d])")
    offenders = [o for o in _library_lines(pattern, "crates/ancf-core/src/constants.rs") if ">>>" not in o]
    assert not offenders, "\n".join(offenders)


def test_the_liquids_and_penalty_rules_are_the_rust_defaults():
    """One oil table and one penalty rule (``rail_mbs::defaults``) for Python fluids, scenes and vehicle runs."""
    assert fluids.LIQUIDS == dict(_core.crude_oils())
    assert fluids.CRUDE_OILS["light"] == (850.0, 0.005, 0.0) and "water" in fluids.LIQUIDS
    light = fluids.crude_oil("light", depth=1.5)
    assert light.bulk_penalty == _core.default_bulk_penalty(850.0, 1.5) == 850.0 * constants.GRAVITY * 1.5 / 1e-3
    assert fluids.default_bulk_damping(2.0e6, 850.0, 0.5) == pytest.approx(0.2 * np.sqrt(2.0e6 * 850.0) * 0.5)
    with pytest.raises(ValueError, match="element_height"):
        _core.default_bulk_damping(2.0e6, 850.0, -1.0)
    # the preset liquids take the recommended shear stabilization like the laws they wrap
    gs = fluids.default_shear_stabilization(998.0, 0.066)
    assert fluids.water(depth=0.132, shear_stabilization=gs).shear_stabilization == gs > 0.0
    assert fluids.crude_oil("heavy", shear_stabilization=12.5).shear_stabilization == 12.5
    assert fluids.water().shear_stabilization == fluids.crude_oil("light").shear_stabilization == 0.0


def test_the_non_affine_mode_control_is_a_fluid_parameter_named_in_its_errors():
    """``Fluid(..., hourglass_stabilization=G_h)`` (Pa; 0 by default): the non-affine-mode control
    of ``FluidBody`` (docs/validation.md, "The ECP scenes' lateral channels"); a negative value is
    refused naming the field."""
    f = rs.Fluid(850.0, "newtonian", viscosity=0.005, bulk_penalty=1.25e7, hourglass_stabilization=250.0)
    assert f.hourglass_stabilization == 250.0
    assert rs.Fluid(850.0, "newtonian", bulk_penalty=1.25e7).hourglass_stabilization == 0.0
    with pytest.raises(ValueError, match="hourglass_stabilization"):
        rs.Fluid(850.0, "newtonian", bulk_penalty=1.25e7, hourglass_stabilization=-1.0)
