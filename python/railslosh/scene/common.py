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


def slosh_outputs(doc: Mapping[str, Any]) -> Outputs:
    """``[outputs]`` of a slosh scene: results and plots; fluid snapshots come from vehicle scenes."""
    sec = Section("slosh", "outputs", doc, extra=("snapshot_every",))
    why = "a slosh scene writes no fluid snapshots (they come from vehicle scenes)"
    if "vtu" in sec and sec.values["vtu"] is not False:
        raise invalid("outputs.vtu", sec.values["vtu"], f"false: {why}")
    if "snapshot_every" in sec:
        raise invalid("outputs.snapshot_every", sec.values["snapshot_every"], f"no snapshot interval: {why}")
    return Outputs(netcdf=sec.get("netcdf"), plots=sec.get("plots"), vtu=False)
