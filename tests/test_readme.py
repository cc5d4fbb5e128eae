"""The README's examples run as a user copies them (issue 16 §3: the rectangular-tank snippet's
lateral load used to carry wall chatter, zero crossings at 2.08 Hz against a 1.38 Hz slosh)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def _python_blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", (ROOT / "README.md").read_text(encoding="utf-8"), flags=re.S)


def _crossing_and_spectral_frequency(t: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """f from the zero crossings of y about its mean (interpolated), and the spectral peak in
    0.3-4 Hz (Hann window, resampled at 1 ms, zero-padded 16x)."""
    y0 = y - y.mean()
    zc = np.flatnonzero(np.diff(np.sign(y0)) != 0)
    tz = t[zc] - y0[zc] * (t[zc + 1] - t[zc]) / (y0[zc + 1] - y0[zc])
    f_raw = (tz.size - 1) / (2.0 * (tz[-1] - tz[0]))
    tu = np.arange(t[0], t[-1], 1e-3)
    yu = np.interp(tu, t, y0)
    spec = np.abs(np.fft.rfft(yu * np.hanning(yu.size), 16 * yu.size))
    f = np.fft.rfftfreq(16 * yu.size, 1e-3)
    band = (f > 0.3) & (f < 4.0)
    return f_raw, float(f[band][np.argmax(spec[band])])


def test_the_readme_slosh_example_gives_a_lateral_load_without_chatter():
    block = next(b for b in _python_blocks() if "rs.slosh.run(" in b)
    code = block.replace("t_end=3.0", "t_end=2.5").replace("progress=True", "progress=False")
    assert code != block
    scope: dict = {}
    exec(compile(code, "README.md", "exec"), scope)  # noqa: S102 - the README's own example
    res = scope["res"]
    t, fy = np.asarray(res["t"]), np.asarray(res["force_tank"])[:, 1]
    keep = t >= 0.7
    f_raw, f_spec = _crossing_and_spectral_frequency(t[keep], fy[keep])
    # seed 003's first lateral mode is 1.436 Hz (linear theory); the mesh gives 1.38 Hz
    assert 1.3 < f_spec < 1.5, f_spec
    # no chatter: zero crossings and the spectral peak agree within 3 % (issue 16 §3); with the
    # library's default walls and quadrature this example gave 2.08 Hz against 1.38 Hz over 0.7-4 s
    assert abs(f_raw / f_spec - 1.0) <= 0.03, (f_raw, f_spec)
