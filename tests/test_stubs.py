"""The type stubs of the Rust extension (python/railslosh/_core.pyi) match the built module:
mypy's stubtest compares every function signature, default and class of ``railslosh._core``."""

import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("mypy")

ALLOWLIST = Path(__file__).with_name("stubtest_allowlist.txt")


def test_stubtest_finds_no_mismatch():
    r = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "railslosh._core", "--allowlist", str(ALLOWLIST)],
        capture_output=True,
        text=True,
        check=False,
        timeout=600,
    )
    assert r.returncode == 0, r.stdout[-6000:] + r.stderr[-2000:]
