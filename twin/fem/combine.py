"""Linear combinations of sparse matrices that share one sparsity pattern.

K(θ) = Σ θ_i K_i is the heart of the performance design: the unit operators of every
region, boundary and interface are stored as data vectors aligned to one CSR pattern, so
forming K(θ) is a single dense mat-vec over the non-zeros (no sparse additions, no
re-assembly, no re-allocation of the pattern).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp


class PatternCombination:
    """A fixed CSR pattern and named data vectors on it."""

    def __init__(self, pattern: sp.spmatrix) -> None:
        pat = sp.csr_matrix(pattern, copy=True)
        pat.sum_duplicates()
        pat.sort_indices()
        self.shape = pat.shape
        self.indptr = pat.indptr
        self.indices = pat.indices
        rows = np.repeat(np.arange(pat.shape[0], dtype=np.int64), np.diff(pat.indptr))
        self._keys = rows * pat.shape[1] + pat.indices.astype(np.int64)
        self._terms: dict[str, np.ndarray] = {}

    def copy(self) -> PatternCombination:
        """The same pattern and terms (the same arrays) with a registry of its own: terms
        added to the copy are not added here."""
        other = object.__new__(PatternCombination)
        other.__dict__.update(self.__dict__)
        other._terms = dict(self._terms)
        return other

    @property
    def nnz(self) -> int:
        return self._keys.size

    def __contains__(self, name: str) -> bool:
        return name in self._terms

    def add(self, name: str, matrix: sp.spmatrix) -> None:
        """Store `matrix` (whose pattern must lie inside this pattern) under `name`."""
        coo = sp.coo_matrix(matrix)
        keys = coo.row.astype(np.int64) * self.shape[1] + coo.col.astype(np.int64)
        pos = np.searchsorted(self._keys, keys)
        pos = np.clip(pos, 0, self.nnz - 1)
        if keys.size and not np.array_equal(self._keys[pos], keys):
            raise ValueError(f"operator {name!r} has entries outside the assembled pattern")
        data = np.zeros(self.nnz)
        np.add.at(data, pos, coo.data)
        self._terms[name] = data

    def data(self, coefficients: dict[str, float]) -> np.ndarray:
        """Σ c_i · data_i for the named terms."""
        out = np.zeros(self.nnz)
        for name, c in coefficients.items():
            if c != 0.0:
                out += c * self._terms[name]
        return out

    def csr(self, data: np.ndarray) -> sp.csr_matrix:
        return sp.csr_matrix((data, self.indices, self.indptr), shape=self.shape)

    def matrix(self, coefficients: dict[str, float]) -> sp.csr_matrix:
        return self.csr(self.data(coefficients))
