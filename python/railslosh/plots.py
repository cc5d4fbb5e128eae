"""PNG plots of a results Dataset (:func:`railslosh.results.to_dataset`), drawn with matplotlib's
Agg backend (no display needed).

    >>> from railslosh import plots, results
    >>> paths = plots.plot_dataset(results.load("out/results.nc"), "out/plots")
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["PLOTS", "plot_dataset"]

# (file stem, title, variables); each variable is drawn per car / wheelset / component.
PLOTS: tuple[tuple[str, str, tuple[str, ...]], ...] = (
    ("coupler_force", "Coupler forces (tension positive)", ("coupler_force",)),
    ("fluid_force", "Force of the liquid on each tank (tank frame)", ("fluid_force_tank",)),
    ("oil_com", "Liquid centre of mass (tank frame)", ("oil_com_tank",)),
    ("wheel_loads", "Vertical wheel loads Q", ("wheel_vertical",)),
    ("l_over_v", "Derailment quotient L/V", ("l_over_v",)),
    ("speed", "Tank speed", ("tank_speed",)),
    ("slosh_force", "Force of the liquid on the tank (tank frame)", ("force_tank",)),
    ("slosh_moment", "Moment of the liquid on the tank (tank frame)", ("moment_tank",)),
    ("slosh_com", "Liquid centre of mass (tank frame)", ("com_tank",)),
    ("energy", "Energies of the liquid", ("kinetic_energy", "potential_energy")),
)


def _label(da: Any, index: dict[str, Any]) -> str:
    parts = [f"{d} {v}" for d, v in index.items()]
    return ", ".join(parts) if parts else str(da.name)


def _lines(ax: Any, da: Any) -> int:
    """Draws every time series of ``da`` (dims ``time`` + others) on ``ax``; returns the count."""
    other = [d for d in da.dims if d != "time"]
    t = da["time"].values
    n = 0
    if not other:
        ax.plot(t, da.values, label=str(da.name))
        return 1
    stacked = da.stack(series=other) if len(other) > 1 else da.rename({other[0]: "series"})
    for k in range(stacked.sizes["series"]):
        s = stacked.isel(series=k)
        index = {d: s[d].values.item() for d in other} if len(other) > 1 else {other[0]: s["series"].values.item()}
        ax.plot(t, s.values, label=_label(da, index), lw=1.2)
        n += 1
    return n


def plot_dataset(ds: Any, out_dir: str | os.PathLike[str], *, dpi: int = 100) -> list[Path]:
    """Writes one PNG per plot of :data:`PLOTS` whose variables are in ``ds``; returns the paths."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    title = ds.attrs.get("title", "")
    paths = []
    for stem, what, names in PLOTS:
        present = [n for n in names if n in ds.data_vars]
        if not present or ds.sizes.get("time", 0) < 2:
            continue
        fig, ax = plt.subplots(figsize=(8, 4.5))
        n = 0
        for name in present:
            n += _lines(ax, ds[name])
        units = {ds[n].attrs.get("units", "") for n in present}
        frame = ds[present[0]].attrs.get("frame", "")
        ax.set_xlabel("time (s)")
        ax.set_ylabel(f"{', '.join(present)} ({'/'.join(sorted(units))})")
        ax.set_title(f"{what}{f' - {title}' if title else ''}", fontsize=10)
        ax.grid(True, alpha=0.3)
        if 1 < n <= 12:
            ax.legend(fontsize=7, ncol=2 if n > 6 else 1)
        if frame:
            ax.annotate(f"frame: {frame}", (0.99, 0.01), xycoords="axes fraction", ha="right", fontsize=7)
        fig.tight_layout()
        p = out / f"{stem}.png"
        fig.savefig(p, dpi=dpi)
        plt.close(fig)
        paths.append(p)
    return paths


def peak_table(ds: Any) -> list[tuple[str, str, float, float]]:
    """``(variable, units, max |value|, time of the max)`` of every variable, for reports."""
    rows = []
    for name, da in ds.data_vars.items():
        v = np.abs(np.asarray(da.values, dtype=float))
        if v.size == 0 or not np.isfinite(v).any():
            continue
        flat = np.nanargmax(v)
        it = np.unravel_index(flat, v.shape)[0]
        rows.append((str(name), da.attrs.get("units", ""), float(v.flat[flat]), float(ds["time"].values[it])))
    return rows
