"""The sections both kinds of scene have: ``[scene]`` (title) and ``[outputs]`` (what
``railslosh run`` writes)."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from railslosh.limits import invalid
from railslosh.scene.schema import Section


@dataclass(frozen=True)
class Outputs:
    """What ``railslosh run`` writes (``[outputs]``)."""

    netcdf: bool = True
    """``results.nc``: the time series as an xarray Dataset."""
    vtu: bool = True
    """``fluid/*.vtu`` and ``fluid.pvd``: fluid mesh snapshots for ParaView (needs ``snapshot_every``)."""
    plots: bool = True
    """PNG plots of the main time series."""
    snapshot_every: float = 0.0
    """Interval of fluid mesh snapshots, s (0 = none)."""

    def to_section(self) -> dict[str, Any]:
        """The ``[outputs]`` table."""
        return dataclasses.asdict(self)


def meta(kind: str, doc: Mapping[str, Any]) -> tuple[str, str]:
    """``[scene] name`` and ``description``."""
    sec = Section(kind, "scene", doc)
    return sec.get("name"), sec.get("description")


def settle_time(kind: str, doc: Mapping[str, Any]) -> float | None:
    """``[scene] settle_time``: the declared settling phase, s (``None``: detected from the results,
    :func:`railslosh.results.settling`)."""
    value = Section(kind, "scene", doc).get("settle_time")
    return None if value is None else float(value)


def vehicle_outputs(doc: Mapping[str, Any], has_snapshots: bool, record_every: float) -> Outputs:
    """``[outputs]`` of a vehicle scene; snapshots need liquid cargo and are no finer than the
    recording."""
    sec = Section("vehicle", "outputs", doc)
    flags = {k: sec.get(k) for k in ("netcdf", "vtu", "plots")}
    snap = sec.get("snapshot_every")
    if 0.0 < snap < record_every:
        raise invalid(
            "outputs.snapshot_every", snap, f"0 (none) or an interval ≥ the recording interval {record_every:g} s"
        )
    if snap > 0 and not has_snapshots:
        raise invalid("outputs.snapshot_every", snap, "0: a scene without [fluid] has no fluid mesh to snapshot")
    return Outputs(snapshot_every=snap, **flags)


def slosh_outputs(doc: Mapping[str, Any], step: float) -> Outputs:
    """``[outputs]`` of a slosh scene: results, plots and fluid snapshots (in the tank frame), no
    finer than the solver's largest step."""
    sec = Section("slosh", "outputs", doc)
    flags = {k: sec.get(k) for k in ("netcdf", "vtu", "plots")}
    snap = sec.get("snapshot_every")
    if 0.0 < snap < step:
        raise invalid("outputs.snapshot_every", snap, f"0 (none) or an interval ≥ solver.step = {step:g} s")
    return Outputs(snapshot_every=snap, **flags)
