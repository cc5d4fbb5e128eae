"""Helpers around :class:`railslosh.FluidBody`."""

from __future__ import annotations

import scipy.sparse as sp

from railslosh._core import FluidBody


def mass_matrix(body: FluidBody, *, full: bool = True) -> sp.csc_matrix:
    """The constant mass matrix of a fluid body as a SciPy sparse matrix.

    With ``full=False`` the 4N x 4N scalar matrix M_s is returned; the full 12N x 12N
    matrix is M_s (x) I_3 in the coordinate layout 12 n + 3 m + i (node n, vector m of
    r, r_x, r_y, r_z, component i).
    """
    data, indices, indptr, shape = body.scalar_mass_csc()
    ms = sp.csc_matrix((data, indices, indptr), shape=shape)
    if not full:
        return ms
    return sp.kron(ms, sp.identity(3, format="csc"), format="csc")
