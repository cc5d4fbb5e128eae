"""A self-contained HTML report of a results directory (``railslosh report DIR``): the scene, the
solver statistics, a table of peak values and every plot, with the PNGs embedded as data URIs
(the page can be mailed or archived alone).

    >>> from railslosh import report
    >>> report.write_report("out/ecp_light")        # -> out/ecp_light/report.html
"""

from __future__ import annotations

import base64
import html
import json
import os
from pathlib import Path

__all__ = ["write_report"]

_CSS = """
body { font-family: system-ui, sans-serif; margin: 2em auto; max-width: 1100px; color: #222; }
h1 { font-size: 1.6em; margin-bottom: 0.2em; } h2 { font-size: 1.2em; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; font-size: 0.9em; } td, th { border: 1px solid #ddd; padding: 3px 8px; }
th { background: #f0f3f7; text-align: left; } td.num { text-align: right; font-family: monospace; }
figure { display: inline-block; margin: 0.5em; } img { max-width: 520px; border: 1px solid #ddd; }
pre { background: #f6f8fa; padding: 0.8em; overflow-x: auto; font-size: 0.8em; }
.meta { color: #555; }
"""


def _img(path: Path) -> str:
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    return f'<figure><img alt="{html.escape(path.stem)}" src="data:image/png;base64,{data}"></figure>'


def write_report(results_dir: str | os.PathLike[str], out: str | os.PathLike[str] | None = None) -> Path:
    """Writes ``report.html`` for a directory made by ``railslosh run`` (``results.nc`` and
    ``plots/*.png``; plots are drawn first when missing). Returns the HTML path."""
    from railslosh import plots, results

    d = Path(results_dir)
    nc = d / "results.nc"
    if not nc.is_file():
        raise ValueError(f"invalid parameter `results_dir` = {str(d)!r}: allowed a directory with results.nc")
    ds = results.load(nc)
    pngs = sorted((d / "plots").glob("*.png"))
    if not pngs:
        pngs = plots.plot_dataset(ds, d / "plots")
    title = ds.attrs.get("title") or d.name
    stats = {k[6:]: v for k, v in ds.attrs.items() if k.startswith("stats_")}
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>railslosh report - {html.escape(str(title))}</title><style>{_CSS}</style></head><body>",
        f"<h1>{html.escape(str(title))}</h1>",
        f'<p class="meta">{html.escape(str(ds.attrs.get("scene_description", "")))} &middot; '
        f"{html.escape(str(ds.attrs.get('source', '')))} &middot; {html.escape(str(ds.attrs.get('history', '')))} "
        f"&middot; simulated {float(ds['time'].values[-1]):.3f} s</p>",
    ]
    if "error" in ds.attrs:
        parts.append(f"<p><b>The run stopped early:</b> {html.escape(str(ds.attrs['error']))}</p>")
    parts.append("<h2>Solver</h2><table><tr><th>statistic</th><th>value</th></tr>")
    for k, v in stats.items():
        parts.append(f'<tr><td>{html.escape(k)}</td><td class="num">{html.escape(str(v))}</td></tr>')
    for k in ("dof", "static_wheel_load", "fluid_mass", "elements"):
        if k in ds.attrs:
            parts.append(f'<tr><td>{k}</td><td class="num">{ds.attrs[k]}</td></tr>')
    parts.append("</table><h2>Peak values</h2><table><tr><th>variable</th><th>max |value|</th><th>units</th>")
    parts.append("<th>at t (s)</th><th>frame</th></tr>")
    for name, units, peak, t in plots.peak_table(ds):
        frame = ds[name].attrs.get("frame", "")
        parts.append(
            f'<tr><td>{html.escape(name)}</td><td class="num">{peak:.6g}</td><td>{html.escape(units)}</td>'
            f'<td class="num">{t:.3f}</td><td>{html.escape(frame)}</td></tr>'
        )
    parts.append("</table><h2>Figures</h2>")
    parts.extend(_img(p) for p in pngs)
    pvd = sorted(d.glob("*.pvd"))
    if pvd:
        parts.append(
            f"<p>Fluid snapshots for ParaView: <code>{html.escape(pvd[0].name)}</code> (open it in ParaView, "
            "then play the time series).</p>"
        )
    if "scene_json" in ds.attrs:
        try:
            scene_txt = json.dumps(json.loads(ds.attrs["scene_json"]), indent=1)
        except ValueError:
            scene_txt = str(ds.attrs["scene_json"])
        parts.append(f"<h2>Scene</h2><pre>{html.escape(scene_txt)}</pre>")
    parts.append("</body></html>")
    path = Path(out) if out is not None else d / "report.html"
    path.write_text("\n".join(parts), encoding="utf-8")
    return path
