"""Tank building: bulkheads (both kinds of scene), the rigid tank of a slosh scene
(``[tank] shape``) and the fluid mesh that fills it."""

from __future__ import annotations

from typing import Any

from railslosh import mesh
from railslosh.limits import Limit, invalid
from railslosh.scene.schema import Section, triple, variant_keys
from railslosh.slosh import TankGeometry

MAX_BULKHEADS = 10
_THICKNESS = Limit(0.001, 0.5, "m", "a thickness")
_POSITION = Limit(-50.0, 50.0, "m", "a position")
_CORNER = Limit(-50.0, 50.0, "m", "a coordinate")


def bulkheads(value: Any, field: str, half_length: float, n_length: int) -> tuple[tuple[float, float], ...]:
    """Bulkheads ``[[x, thickness], ...]``: inside the shell (0.05 m clear of its ends), increasing,
    not overlapping, and every compartment at least one element (``mesh.counts[0]``) long."""
    if not isinstance(value, list | tuple) or len(value) > MAX_BULKHEADS:
        raise invalid(field, value, f"a list of at most {MAX_BULKHEADS} [x, thickness] pairs")
    out: list[tuple[float, float]] = []
    for i, b in enumerate(value):
        if not isinstance(b, list | tuple) or len(b) != 2:
            raise invalid(f"{field}[{i}]", b, "a pair [x (m), thickness (m)]")
        th = _THICKNESS.check(b[1], f"{field}[{i}][1] (thickness)")
        lim = half_length - th / 2 - 0.05
        x = _POSITION.check(b[0], f"{field}[{i}][0] (x)", lo=-lim, hi=lim, note=" (inside the cylindrical shell)")
        if out and x - th / 2 <= out[-1][0] + out[-1][1] / 2:
            raise invalid(
                f"{field}[{i}][0] (x)", x, f"a position after and clear of the previous bulkhead (> {out[-1][0]:g} m)"
            )
        out.append((x, th))
    if len(out) + 1 > n_length:
        raise invalid("mesh.counts[0]", n_length, f"at least {len(out) + 1} elements along the tank, one a compartment")
    return tuple(out)


def slosh_tank(sec: Section, counts: tuple[int, int, int]) -> TankGeometry:
    """The rigid tank of ``[tank]`` (a slosh scene); ``counts`` = the mesh's element counts."""
    shape = sec.get("shape")
    allowed = variant_keys("slosh", "tank", shape)
    for k, v in sec.values.items():
        if k not in ("shape", "wall_damping_ratio", "wall_adhesion") and k not in allowed:
            raise invalid(f"tank.{k}", v, f"no `tank.{k}` with shape = {shape!r} (its keys: {', '.join(allowed)})")
    if shape == "elliptic":
        return TankGeometry.elliptic(*(sec.get(k, variant=shape) for k in ("length", "semi_axis_y", "semi_axis_z")))
    if shape == "cylinder":
        length = sec.get("length", variant=shape)
        radius = sec.get("radius", variant=shape)
        head = sec.get("head_depth", variant=shape, hi=radius, note=" (≤ tank.radius)")
        bh = bulkheads(sec.values.get("bulkheads", []), "tank.bulkheads", length / 2, counts[0])
        return TankGeometry.cylinder(length, radius, head, bh)
    lo = [_CORNER.check(x, f"tank.lower[{i}]") for i, x in enumerate(triple(sec.values.get("lower"), "tank.lower"))]
    hi = [_CORNER.check(x, f"tank.upper[{i}]") for i, x in enumerate(triple(sec.values.get("upper"), "tank.upper"))]
    for i in range(3):
        if hi[i] <= lo[i] + 0.01:
            raise invalid(f"tank.upper[{i}]", hi[i], f"a coordinate > tank.lower[{i}] + 0.01 = {lo[i] + 0.01:g} m")
    return TankGeometry.box((lo[0], lo[1], lo[2]), (hi[0], hi[1], hi[2]))


def tank_mesh(tank: TankGeometry, fill: float, counts: tuple[int, int, int]) -> Any:
    """The fluid mesh of a tank filled to the volume fraction ``fill`` (reference configuration,
    tank frame)."""
    d, (nl, nw, nh) = tank.dims, counts
    if tank.shape == "elliptic":
        return mesh.elliptic_cylinder(
            length=d[0], semi_axis_y=d[1], semi_axis_z=d[2], fill=fill, n_length=nl, n_width=nw, n_height=nh
        )
    if tank.shape == "cylinder":
        return mesh.cylinder_tank(
            length=d[0], radius=d[1], head_depth=d[2], fill=fill, n_length=nl, n_width=nw, n_height=nh
        )
    lo, hi = d[:3], d[3:]
    size = (hi[0] - lo[0], hi[1] - lo[1], fill * (hi[2] - lo[2]))
    return mesh.box(size, (nl, nw, nh), origin=(lo[0], lo[1], lo[2]))
