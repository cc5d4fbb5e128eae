"""Reader of results streams: the append-only journal files written by ``stream=`` runs
(``rail_mbs::integrator::Journal``; format in docs/robustness.md). A file of an interrupted run
reads back every complete sample; a torn last row is dropped."""

from __future__ import annotations

import os

import numpy as np

MAGIC = b"RSLJRNL1"


def read_journal(path: str | os.PathLike[str], what: str = "results stream") -> dict[str, np.ndarray]:
    """Column name -> samples (float64) of a journal file."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != MAGIC or len(data) < 12:
        raise ValueError(f"invalid `path` = {os.fspath(path)!r}: expected a {what} file")
    ncol = int.from_bytes(data[8:12], "little")
    pos, names = 12, []
    for _ in range(ncol):
        n = int.from_bytes(data[pos : pos + 4], "little")
        names.append(data[pos + 4 : pos + 4 + n].decode())
        pos += 4 + n
    rows = (len(data) - pos) // (8 * ncol) if ncol else 0
    table = np.frombuffer(data, dtype="<f8", count=rows * ncol, offset=pos).reshape(rows, ncol)
    return {name: table[:, i].copy() for i, name in enumerate(names)}
