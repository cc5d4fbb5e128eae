"""Fluids: the five constitutive models of seed 000 §3 and the crude oils of its Table 2.

Penalty parameters (seed 000 §4.1): ``bulk_penalty`` k_IC is a bulk modulus (Pa) and
``bulk_damping`` c_TD a bulk viscosity (Pa s). When ``bulk_penalty`` is not given it follows
:func:`default_bulk_penalty`. ``shear_stabilization`` G_s (Pa) is the zero-energy-mode control
that makes the discrete liquid's rest state stable (``ancf_core::constitutive``, "Shear
stabilization"), off by default; :func:`default_shear_stabilization` gives the recommended value
(scene key ``mesh.shear_stabilization``).
"""

from __future__ import annotations

from railslosh import _core
from railslosh._core import Fluid

#: Seed 000 Table 2 and water: density (kg/m^3), dynamic viscosity (Pa s), yield stress (Pa)
#: (``rail_mbs::defaults::Oil``, the table vehicle runs use).
LIQUIDS: dict[str, tuple[float, float, float]] = dict(_core.crude_oils())
#: The three crude oils of seed 000 Table 2.
CRUDE_OILS: dict[str, tuple[float, float, float]] = {k: v for k, v in LIQUIDS.items() if k != "water"}


def default_bulk_penalty(density: float, depth: float, strain: float = 1e-3) -> float:
    """Penalty bulk modulus that limits the hydrostatic volume strain to ``strain``.

    The hydrostatic pressure at the bottom of a liquid of depth H is rho g H, which
    compresses the penalty fluid by rho g H / k. Choosing k = rho g H / strain
    (default strain 1e-3, so k = 1000 rho g H) keeps the mean volume error near
    0.05 %, while k stays 2-3 orders below the physical bulk modulus of oil (~1.5 GPa),
    which keeps the system far less stiff (the dilatational wave speed is sqrt(k/rho)).
    The rule is ``rail_mbs::defaults::default_bulk_penalty``, the one vehicle runs use.
    """
    if not (density > 0 and depth > 0 and strain > 0):
        raise ValueError(f"invalid `density`/`depth`/`strain` = {density}/{depth}/{strain}: expected numbers > 0")
    return _core.default_bulk_penalty(density, depth, strain)


def default_bulk_damping(bulk_penalty: float, density: float, element_height: float) -> float:
    """Default penalty bulk viscosity c_TD = 0.2 sqrt(k_IC rho) h_el (Pa s) for elements
    ``element_height`` m high (``rail_mbs::defaults::default_bulk_damping``)."""
    return _core.default_bulk_damping(bulk_penalty, density, element_height)


def default_shear_stabilization(density: float, element_height: float, heads_depth: float | None = None) -> float:
    """Recommended shear stabilization G_s = 0.006 rho g h_el (Pa) for elements ``element_height``
    m high and, for the liquid ``heads_depth`` m deep in a tank with heads, at least 0.005 rho g H
    (``rail_mbs::defaults::default_shear_stabilization``): the smallest factors, with a margin,
    that make the rest state of the default meshes and of every tank-car mesh up to four layers
    stable; it also raises the first sloshing frequency by about 0.8 % on coarse meshes and by
    1-2 % on the tank car (docs/validation.md, "A stable rest state")."""
    return _core.default_shear_stabilization(density, element_height, heads_depth)


def _penalty(density: float, bulk_penalty: float | None, depth: float) -> float:
    return default_bulk_penalty(density, depth) if bulk_penalty is None else bulk_penalty


def newtonian(
    density: float,
    viscosity: float,
    *,
    bulk_penalty: float | None = None,
    bulk_damping: float = 0.0,
    shear_stabilization: float = 0.0,
    depth: float = 1.5,
) -> Fluid:
    """Newtonian fluid sigma = 2 mu D."""
    return Fluid(
        density,
        "newtonian",
        viscosity=viscosity,
        bulk_penalty=_penalty(density, bulk_penalty, depth),
        bulk_damping=bulk_damping,
        shear_stabilization=shear_stabilization,
    )


def bingham(
    density: float,
    viscosity: float,
    yield_stress: float,
    *,
    bulk_penalty: float | None = None,
    bulk_damping: float = 0.0,
    shear_stabilization: float = 0.0,
    depth: float = 1.5,
    shear_rate_reg: float = 1e-2,
) -> Fluid:
    """Bingham fluid (seed 000 eq. 1), regularized below ``shear_rate_reg`` (1/s)."""
    return Fluid(
        density,
        "bingham",
        viscosity=viscosity,
        yield_stress=yield_stress,
        bulk_penalty=_penalty(density, bulk_penalty, depth),
        bulk_damping=bulk_damping,
        shear_stabilization=shear_stabilization,
        shear_rate_reg=shear_rate_reg,
    )


def herschel_bulkley(
    density: float,
    consistency: float,
    power_index: float,
    yield_stress: float,
    *,
    bulk_penalty: float | None = None,
    bulk_damping: float = 0.0,
    shear_stabilization: float = 0.0,
    depth: float = 1.5,
    shear_rate_reg: float = 1e-2,
) -> Fluid:
    """Herschel-Bulkley fluid tau = tau0 + K gdot^n (seed 000 eq. 2)."""
    return Fluid(
        density,
        "herschel-bulkley",
        consistency=consistency,
        power_index=power_index,
        yield_stress=yield_stress,
        bulk_penalty=_penalty(density, bulk_penalty, depth),
        bulk_damping=bulk_damping,
        shear_stabilization=shear_stabilization,
        shear_rate_reg=shear_rate_reg,
    )


def oldroyd(
    density: float,
    viscosity: float,
    yield_stress: float,
    *,
    elastic_modulus: float | None = None,
    bulk_penalty: float | None = None,
    bulk_damping: float = 0.0,
    shear_stabilization: float = 0.0,
    depth: float = 1.5,
    shear_rate_reg: float = 1e-2,
) -> Fluid:
    """Oldroyd fluid (seed 000 eq. 3): Bingham above yield, Hookean (G = 50 tau0 default) below."""
    return Fluid(
        density,
        "oldroyd",
        viscosity=viscosity,
        yield_stress=yield_stress,
        elastic_modulus=elastic_modulus,
        bulk_penalty=_penalty(density, bulk_penalty, depth),
        bulk_damping=bulk_damping,
        shear_stabilization=shear_stabilization,
        shear_rate_reg=shear_rate_reg,
    )


def casson(
    density: float,
    viscosity: float,
    yield_stress: float,
    *,
    bulk_penalty: float | None = None,
    bulk_damping: float = 0.0,
    shear_stabilization: float = 0.0,
    depth: float = 1.5,
    shear_rate_reg: float = 1e-2,
) -> Fluid:
    """Casson fluid sqrt(tau) = sqrt(tau0) + sqrt(mu gdot) (seed 000 eq. 4)."""
    return Fluid(
        density,
        "casson",
        viscosity=viscosity,
        yield_stress=yield_stress,
        bulk_penalty=_penalty(density, bulk_penalty, depth),
        bulk_damping=bulk_damping,
        shear_stabilization=shear_stabilization,
        shear_rate_reg=shear_rate_reg,
    )


def crude_oil(
    kind: str, *, depth: float = 1.5, bulk_penalty: float | None = None, shear_stabilization: float = 0.0
) -> Fluid:
    """Light, medium or heavy crude of seed 000 Table 2, with the Oldroyd model as in the paper.
    ``shear_stabilization`` (Pa, default 0) as in :func:`oldroyd`; :func:`default_shear_stabilization`
    gives the recommended value."""
    if kind not in CRUDE_OILS:
        raise ValueError(f"invalid `kind` = {kind!r}: expected one of {sorted(CRUDE_OILS)}")
    rho, mu, tau0 = CRUDE_OILS[kind]
    return oldroyd(rho, mu, tau0, depth=depth, bulk_penalty=bulk_penalty, shear_stabilization=shear_stabilization)


def water(*, depth: float = 1.5, bulk_penalty: float | None = None, shear_stabilization: float = 0.0) -> Fluid:
    """Water at 20 C: 998 kg/m^3, 1.0e-3 Pa s (``LIQUIDS["water"]``). ``shear_stabilization`` (Pa,
    default 0) as in :func:`newtonian`; :func:`default_shear_stabilization` gives the recommended
    value."""
    rho, mu, _ = LIQUIDS["water"]
    return newtonian(rho, mu, depth=depth, bulk_penalty=bulk_penalty, shear_stabilization=shear_stabilization)
