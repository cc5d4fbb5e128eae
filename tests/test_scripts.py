"""Post-processing scripts run as documented."""

import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def test_swri_lateral_loads_script_writes_csv_and_plot(tmp_path):
    out = subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "swri_lateral_loads.py"), "--quick", "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert out.returncode == 0, out.stderr
    data = np.loadtxt(tmp_path / "swri_lateral_loads.csv", delimiter=",", skiprows=1)
    assert data.shape[1] == 7 and data.shape[0] > 100
    # during the +y pulse the fluid pushes the tank towards -y
    t, fy = data[:, 0], data[:, 2]
    assert fy[(t > 0.2) & (t < 0.5)].mean() < 0
    assert (tmp_path / "swri_lateral_loads.png").stat().st_size > 10_000
