"""Sparse direct solves of the symmetric FE systems, and their low-rank updates.

factorize_symmetric  SuperLU with a symmetric ordering (SPD FE matrices)
DirichletSolver      a factorized system with prescribed dofs eliminated
LowRankUpdate        solves of (A₀ + U W Uᵀ) x = b by Woodbury, with A₀ factorized once
                     per key and kept in the object's own bounded cache
"""

from __future__ import annotations

from collections.abc import Callable, Hashable

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import condense


def factorize_symmetric(A: sp.csc_matrix) -> spla.SuperLU:
    """SuperLU of a symmetric positive-definite FE matrix.

    Minimum-degree ordering on Aᵀ+A with diagonal pivots keeps the symmetric structure:
    about half the fill and time of SuperLU's default (COLAMD, partial pivoting) here.
    """
    return spla.splu(
        A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True}
    )


class DirichletSolver:
    """A symmetric system A x = b, factorized once, with x[dofs] = values prescribed.

    scikit-fem's `condense` eliminates the prescribed dofs once; the factorization of
    A[free, free] and the lift −A[free, dofs]·values are kept, so each right-hand side
    costs one back-substitution (condense + solve would slice and factorize every time).
    """

    def __init__(self, A: sp.csr_matrix, dofs: np.ndarray, values: np.ndarray) -> None:
        n = A.shape[0]
        if dofs.size:
            x = np.zeros(n)
            x[dofs] = values
            # with b = 0, condense's right-hand side b_I − A_ID x_D is the lift −A_ID x_D
            A_free, self.lift, self.x, self.free = condense(A, np.zeros(n), x=x, D=dofs)
        else:
            self.free = None
            A_free = A
        # A is symmetric: its CSR arrays read as CSC describe the same matrix
        A_csc = sp.csc_matrix((A_free.data, A_free.indices, A_free.indptr), shape=A_free.shape)
        self.lu = factorize_symmetric(A_csc)

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        if self.free is None:
            return self.lu.solve(rhs)
        x = self.x.copy()
        x[self.free] = self.lu.solve(rhs[self.free] + self.lift)
        return x


class _Base:
    """A₀ factorized and its response to the update columns: Z = A₀⁻¹ U, Uᵀ Z."""

    def __init__(self, solver: DirichletSolver, U: sp.csc_matrix) -> None:
        self.solver = solver
        self.Ut = U.T  # once: building it at every time step was a tenth of the solve time
        self.Z = solver.lu.solve(U.toarray()) if U.shape[1] else np.zeros((U.shape[0], 0))
        self.UtZ = self.Ut @ self.Z


class WoodburySolver:
    """Solves (A₀ + U W Uᵀ) x = b with A₀ factorized:

        x = y − Z (I + W Uᵀ Z)⁻¹ W Uᵀ y,   y = A₀⁻¹ b,  Z = A₀⁻¹ U.
    """

    def __init__(self, base: _Base, W: np.ndarray) -> None:
        self._base, self._W = base, W
        self._lu = sla.lu_factor(np.eye(W.shape[0]) + W @ base.UtZ)

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        y = self._base.solver.solve(rhs)
        base = self._base
        return y - base.Z @ sla.lu_solve(self._lu, self._W @ (base.Ut @ y))


def kept(cache: dict, key: Hashable, make: Callable[[], object], max_items: int) -> object:
    """`cache[key]`, made by `make()` on a miss; at most `max_items` are kept, the oldest
    dropped first (bounded memory for values a loop asks for again and again)."""
    value = cache.get(key)
    if value is None:
        if len(cache) >= max_items:
            cache.pop(next(iter(cache)))
        value = cache[key] = make()
    return value


class LowRankUpdate:
    """Solvers of A₀ + U W Uᵀ for fixed update columns U (n × m, m small).

    The factorized A₀ of each key is cached (at most `max_bases`, the oldest dropped), so
    a new W (m × m) costs one small dense factorization and no sparse one.  A₀ must not
    depend on W: then results never depend on which W came first.
    """

    def __init__(self, U: sp.csc_matrix, max_bases: int = 8) -> None:
        self.U = sp.csc_matrix(U)
        self.max_bases = max_bases
        self._bases: dict[Hashable, _Base] = {}

    def copy(self) -> LowRankUpdate:
        """The same U and the factorizations held so far, in a cache of its own: what the
        copy factorizes later (keyed by names that may mean other sets to its owner) is not
        kept here."""
        other = LowRankUpdate(self.U, self.max_bases)
        other._bases = dict(self._bases)
        return other

    def __len__(self) -> int:
        """Number of factorized A₀ held."""
        return len(self._bases)

    def solver(
        self, key: Hashable, base: Callable[[], DirichletSolver], W: np.ndarray
    ) -> WoodburySolver:
        """The solver of A₀(key) + U W Uᵀ; `base()` factorizes A₀ on a cache miss."""
        cached = kept(self._bases, key, lambda: _Base(base(), self.U), self.max_bases)
        return WoodburySolver(cached, W)
