"""The liquid of a scene: ``[fluid]`` (oil or custom rheology, fill), ``[mesh]`` and the bulkheads
and wall damping of ``[tank]``, as a :class:`FluidSpec`."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from railslosh import fluids, mesh
from railslosh.limits import missing
from railslosh.scene.schema import CUSTOM_KEYS, Section, counts, scoped
from railslosh.scene.tank import bulkheads
from railslosh.vehicle import WALL_DAMPING_RATIO

VEHICLE_COUNTS = ((1, 40), (2, 20), (1, 10))
"""Limits of ``[mesh] counts`` of a tank car (length, width, height)."""


@dataclass(frozen=True)
class FluidSpec:
    """The liquid of a scene: ``[fluid]``, ``[mesh]`` and the bulkheads of ``[tank]``."""

    oil: str = "light"
    fill: float = 0.5
    counts: tuple[int, int, int] = (6, 4, 2)
    bulkheads: tuple[tuple[float, float], ...] = ()
    custom: Mapping[str, Any] = field(default_factory=dict)
    """Constructor arguments of :class:`railslosh.Fluid` when ``oil = "custom"``."""
    slosh_model: str = "auto"
    """``[fluid] slosh_model``: ``"auto"``, ``"ancf"``, ``"pendulum"`` or ``"rigid"``."""
    wall_damping_ratio: float = WALL_DAMPING_RATIO
    """``[tank] wall_damping_ratio``: damping ratio of the liquid column on the penalty wall (0 to 10;
    1 removes most wall ringing from the loads: :func:`railslosh.vehicle.run_fluid`)."""
    wall_adhesion: float = 0.0
    """``[tank] wall_adhesion``: suction the wall holds on the wetted liquid, in units of ρ g H (0 to 50;
    0 a unilateral wall: :func:`railslosh.slosh.run`)."""
    shear_stabilization: bool = True
    """``[mesh] shear_stabilization``: the recommended zero-energy-mode control
    (:func:`railslosh.fluids.default_shear_stabilization`), which makes the rest state stable
    (docs/validation.md, "A stable rest state"); on by default in scenes."""

    def make_fluid(self, depth: float, element_height: float | None = None, heads: bool = False) -> Any:
        """The :class:`railslosh.Fluid` for a liquid ``depth`` m deep: penalty ``k = 1000 rho g depth``
        and, when ``element_height`` is given, bulk damping ``0.2 sqrt(k rho) element_height`` (the
        defaults of the slosh validation cases) unless the scene sets them; with
        :attr:`shear_stabilization` (and ``element_height``) also the recommended shear stabilization
        :func:`railslosh.fluids.default_shear_stabilization`, with the floor of a tank with ``heads``."""
        rho = self.density()
        k = float(self.custom.get("bulk_penalty", fluids.default_bulk_penalty(rho, depth)))
        c = 0.0 if element_height is None else fluids.default_bulk_damping(k, rho, element_height)
        c = float(self.custom.get("bulk_damping", c))
        gs = 0.0
        if self.shear_stabilization and element_height is not None:
            gs = fluids.default_shear_stabilization(rho, element_height, depth if heads else None)
        if self.oil == "custom":
            args = {key: v for key, v in self.custom.items() if key not in ("density", "model")}
            args |= {"bulk_penalty": k, "bulk_damping": c, "shear_stabilization": gs}
            try:
                return fluids.Fluid(rho, self.custom["model"], **args)
            except ValueError as exc:
                raise scoped(exc, "fluid") from exc
        if self.oil == "water":
            _, mu, _ = fluids.LIQUIDS["water"]
            return fluids.newtonian(rho, mu, bulk_penalty=k, bulk_damping=c, shear_stabilization=gs)
        _, mu, tau0 = fluids.CRUDE_OILS[self.oil]
        return fluids.oldroyd(rho, mu, tau0, bulk_penalty=k, bulk_damping=c, shear_stabilization=gs)

    def density(self) -> float:
        """Liquid density, kg/m^3."""
        if self.oil == "custom":
            return float(self.custom["density"])
        return fluids.LIQUIDS[self.oil][0]

    def mass(self, params: Mapping[str, float]) -> float:
        """Liquid mass per car, kg (density times the exact liquid volume of the car's tank)."""
        m = mesh.cylinder_tank(
            length=params["tank_length"] - 1.0,
            radius=params["tank_radius"],
            head_depth=0.5,
            fill=self.fill,
            n_length=2,
            n_width=2,
            n_height=2,
        )
        return self.density() * m.exact_volume

    def to_sections(self) -> dict[str, Any]:
        """The ``[fluid]``, ``[mesh]`` and ``[tank]`` tables of this liquid."""
        fl: dict[str, Any] = {"oil": self.oil, "fill": self.fill, **self.custom}
        if self.slosh_model != "auto":
            fl["slosh_model"] = self.slosh_model
        d: dict[str, Any] = {"fluid": fl, "mesh": {"counts": list(self.counts)}}
        if not self.shear_stabilization:
            d["mesh"]["shear_stabilization"] = False
        if self.bulkheads:
            d["tank"] = {"bulkheads": [list(b) for b in self.bulkheads]}
        if self.wall_damping_ratio != WALL_DAMPING_RATIO:
            d.setdefault("tank", {})["wall_damping_ratio"] = self.wall_damping_ratio
        if self.wall_adhesion != 0.0:
            d.setdefault("tank", {})["wall_adhesion"] = self.wall_adhesion
        return d


def oil_and_custom(sec: Section) -> tuple[str, dict[str, Any]]:
    """``oil`` and the custom-fluid constructor arguments of a ``[fluid]`` section."""
    oil = sec.get("oil")
    custom: dict[str, Any] = {}
    if oil != "custom":
        sec.only_with(("model", *CUSTOM_KEYS), 'with oil = "custom"')
        return oil, custom
    for k in ("model", "density"):
        if k not in sec:
            raise missing(f"fluid.{k}", 'a value with oil = "custom"')
    custom["model"] = sec.get("model")
    for k in CUSTOM_KEYS:
        if k in sec:
            custom[k] = sec.get(k)
    return oil, custom


def vehicle_fluid(doc: Mapping[str, Any], params: Mapping[str, float]) -> FluidSpec:
    """The :class:`FluidSpec` of a vehicle scene's ``[fluid]``, ``[mesh]`` and ``[tank]`` for the
    car ``params`` (tank length and radius)."""
    fl = Section("vehicle", "fluid", doc)
    oil, custom = oil_and_custom(fl)
    fill = fl.get("fill")
    slosh_model = fl.get("slosh_model")
    ms = Section("vehicle", "mesh", doc)
    n = counts(ms.values.get("counts", [6, 4, 2]), "mesh.counts", VEHICLE_COUNTS)
    tk = Section("vehicle", "tank", doc)
    half = 0.5 * (params["tank_length"] - 1.0)
    bh = bulkheads(tk.values.get("bulkheads", []), "tank.bulkheads", half, n[0])
    spec = FluidSpec(
        oil=oil,
        fill=fill,
        counts=n,
        bulkheads=bh,
        custom=custom,
        slosh_model=slosh_model,
        wall_damping_ratio=tk.get("wall_damping_ratio"),
        wall_adhesion=tk.get("wall_adhesion"),
        shear_stabilization=ms.get("shear_stabilization"),
    )
    if oil == "custom":
        spec.make_fluid(2.0 * params["tank_radius"] * fill)  # validates the custom fluid now
    return spec
