"""Work–precision benchmarks of ``railslosh bench``: run time against error.

Each sweep (implemented in Rust, ``railslosh_cases::work_precision``) runs one case over a grid of
time steps, meshes, quadrature rules, Newton tolerances and linear solvers, and measures for
every point its wall time and its errors against a converged reference run:

- ``slosh-tank``: seed 003's rectangular tank under a 0.3 g lateral pulse; errors of the
  first-mode frequency (vs the analytic 1.436 Hz and vs the reference) and of the lateral
  centre-of-mass history.
- ``ecp-braking``: the two-car ECP braking study of seed 000 (light crude); errors of the peak
  coupler force and of the front car's longitudinal oil centre-of-mass history.
- ``ecp-braking-spread``: the same with the rear car's brake force 10 % lower, the
  configuration whose coupler force is first order (with identical cars the ECP coupler force
  is a second-order pitch effect, see ``docs/validation.md``).

:func:`write` saves the points as ``work_precision.csv`` and ``work_precision.json`` and plots
error against wall time (``work_precision_<case>.png``). Quick forms take seconds (CI); the
full ``ecp-braking`` sweeps take one to two hours on one core.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path
from typing import Any

from railslosh import _core

Point = dict[str, Any]


def cases() -> list[str]:
    """Names of the sweeps."""
    return list(_core.work_precision_cases())


def run(names: list[str] | None = None, *, quick: bool = False) -> list[Point]:
    """Run the named sweeps (all when empty) and return every point."""
    names = list(names or cases())
    unknown = [n for n in names if n not in cases()]
    if unknown:
        raise ValueError(f"invalid `case` = {unknown}: expected {cases()}")
    points: list[Point] = []
    for n in names:
        points.extend(_core.run_work_precision(n, quick))
    return points


def rows(points: list[Point]) -> list[dict[str, Any]]:
    """Flatten points into table rows (settings and errors become columns)."""
    out = []
    for p in points:
        row: dict[str, Any] = {"case": p["case"], "reference": p["reference"]}
        row.update(p["settings"])
        row.update(
            wall_s=p["wall_s"],
            steps=p["steps"],
            newton_iterations=p["newton_iterations"],
            jacobians=p["jacobians"],
        )
        row.update({f"error_{k}": v for k, v in p["errors"].items()})
        row["failure"] = p["failure"] or ""
        out.append(row)
    return out


def _label(p: Point) -> str:
    s = p["settings"]
    parts = []
    if "elements" in s:
        parts.append(f"{int(s['elements'])} el")
    if "elements_per_tank" in s:
        parts.append(f"{int(s['elements_per_tank'])} el/tank")
    parts.append(f"h {1e3 * s['h_max_s']:g} ms")
    if "penalty_points" in s:
        parts.append(f"pen {int(s['penalty_points'])}^3")
    if s.get("iterative"):
        parts.append("GMRES")
    if "rel_tol" in s:
        parts.append(f"tol {s['rel_tol']:g}")
    return ", ".join(parts)


def write(points: list[Point], out_dir: str | Path, *, plot: bool = True) -> list[Path]:
    """Write CSV, JSON and (if matplotlib is installed and ``plot``) one PNG per case."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    table = rows(points)
    columns: list[str] = []
    for r in table:
        columns.extend(k for k in r if k not in columns)
    with open(out / "work_precision.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=columns)
        w.writeheader()
        w.writerows(table)
    written.append(out / "work_precision.csv")

    def clean(v: Any) -> Any:
        return None if isinstance(v, float) and not math.isfinite(v) else v

    with open(out / "work_precision.json", "w") as f:
        json.dump(
            [
                {**p, "errors": {k: clean(v) for k, v in p["errors"].items()}, "settings": dict(p["settings"])}
                for p in points
            ],
            f,
            indent=1,
        )
    written.append(out / "work_precision.json")
    if not plot:
        return written
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib.ticker import NullFormatter
    except ImportError:
        return written
    for case in dict.fromkeys(p["case"] for p in points):
        pts = [p for p in points if p["case"] == case and not p["reference"]]
        metrics = [k for k in (pts[0]["errors"] if pts else {}) if k.endswith("_rel")]
        if not metrics:
            continue
        fig, axes = plt.subplots(1, len(metrics), figsize=(5.2 * len(metrics), 4.2), squeeze=False)
        for ax, m in zip(axes[0], metrics, strict=True):
            for p in pts:
                e = p["errors"][m]
                if p["failure"] or not (isinstance(e, float) and math.isfinite(e)):
                    continue
                ax.loglog(p["wall_s"], max(e, 1e-16), "o")
                ax.annotate(
                    _label(p), (p["wall_s"], max(e, 1e-16)), fontsize=6, xytext=(3, 3), textcoords="offset points"
                )
            walls = [p["wall_s"] for p in pts if p["wall_s"] > 0]
            errs = [p["errors"][m] for p in pts if isinstance(p["errors"][m], float) and p["errors"][m] > 0]
            if walls:
                ax.set_xlim(min(walls) / 2.0, max(walls) * 2.0)
            if errs:
                # at least a decade on each axis, so that major ticks are labelled
                ax.set_ylim(min(errs) / 3.0, max(errs) * 3.0)
            ax.xaxis.set_minor_formatter(NullFormatter())
            ax.yaxis.set_minor_formatter(NullFormatter())
            ax.set_xlabel("wall time (s)")
            ax.set_ylabel(m.replace("_", " "))
            ax.grid(True, which="both", alpha=0.3)
        ref = next((p for p in points if p["case"] == case and p["reference"]), None)
        title = f"{case}: error vs wall time"
        if ref is not None:
            title += f" (reference: {_label(ref)}, {ref['wall_s']:.1f} s)"
        fig.suptitle(title, fontsize=9)
        fig.tight_layout()
        path = out / f"work_precision_{case}.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        written.append(path)
    return written
