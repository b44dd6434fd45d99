"""Small-matrix linear algebra that gives the same bits on every x86-64 CPU.

numpy hands ``@``, ``np.dot``, ``np.linalg.norm`` of a vector, ``np.linalg.solve`` and ``np.linalg.lstsq`` to
OpenBLAS, which chooses its kernels when it loads, by the CPU it finds (``Haswell`` on an AVX2 machine, ``SkylakeX``
on an AVX-512 one, ...: ``threadpoolctl.threadpool_info()`` names the one in use). The kernels add their products in
different orders, so the same product differs in its last bits from one machine to the next. A tap is a contact
problem: a difference of 1e-12 rad in a servo target moves some objects by millimetres, and one last bit in an
inverse-kinematics step ends as a different interaction. Everything the simulation computes with numpy therefore
goes through these functions, which never call BLAS:

- products are ``np.einsum`` without path optimisation, whose loops numpy compiles for its baseline CPU only;
- the small linear systems are solved by Eigen (through eigenpy, which Pinocchio brings), compiled into the wheel
  for one instruction set.

Elementwise ``+``, ``-``, ``*``, ``/`` and ``np.sum`` give the same bits on every CPU. numpy's powers and
transcendental functions (``**``, ``np.arccos``, ``np.exp``, ...) do not: numpy picks their SIMD code by the CPU
(AVX2 or AVX-512), which is why a fingerprint records the CPU's features beside the versions.
"""

from __future__ import annotations

import importlib
import math
from collections.abc import Callable
from typing import Any

import eigenpy
import numpy as np

from affordance_env.exceptions import InvalidValueError


def _c_einsum() -> Callable[..., Any]:
    """What ``np.einsum`` runs when it is not asked to optimise (``optimize=False``, its default), without the
    Python layer around it: the same loops, so the same bits, for less per call (a control tick calls these)."""
    for name in ("numpy._core.multiarray", "numpy.core.multiarray"):  # numpy 2, numpy 1
        try:
            return importlib.import_module(name).c_einsum
        except (ImportError, AttributeError):
            continue
    return np.einsum  # pragma: no cover (a numpy without it)


_einsum = _c_einsum()
#: ``np.einsum(subscripts, *operands)`` (no ``optimize``): the same loops and bits, without its Python layer.
einsum = _einsum

_SUBSCRIPTS = {(1, 1): "i,i->", (1, 2): "i,ij->j", (2, 1): "...ij,j->...i", (2, 2): "...ij,jk->...ik"}
_FLOAT = np.float64
_SUCCESS = eigenpy.ComputationInfo.Success


def matmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a @ b`` for ``b`` a vector or a matrix and ``a`` a vector or a stack of matrices, in the same bits on
    every CPU."""
    a, b = np.asarray(a, dtype=_FLOAT), np.asarray(b, dtype=_FLOAT)
    subscripts = _SUBSCRIPTS.get((min(a.ndim, 2), b.ndim)) if a.ndim else None
    if subscripts is None:
        raise InvalidValueError(
            f"matmul takes a vector or (a stack of) matrices times a vector or a matrix, got shapes "
                         f"{a.shape} and {b.shape}.")
    return _einsum(subscripts, a, b)


def matmul_f64(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """:func:`matmul` of a float64 matrix (or vector) ``a`` and a float64 matrix ``b``, without the conversions and
    checks: the same einsum, so the same bits, for loops that call it many times with arrays they made."""
    return _einsum("...ij,jk->...ik" if a.ndim == 2 else "i,ij->j", a, b)


def norm_f64(v: np.ndarray) -> float:
    """:func:`norm` of a 1-D float64 array, without the conversions: the same sum and root, so the same bits."""
    return math.sqrt(_einsum("i,i->", v, v))


def dot(a: np.ndarray, b: np.ndarray) -> float:
    """The dot product of two vectors, as a float."""
    # As matmul of the two raveled: the same contiguous float64 vectors, whichever of the two conversions comes first.
    return float(_einsum("i,i->", np.asarray(a, dtype=_FLOAT).ravel(), np.asarray(b, dtype=_FLOAT).ravel()))


def norm(v: np.ndarray) -> float:
    """The Euclidean norm of a vector (``np.linalg.norm`` of a 1-D array goes through BLAS)."""
    v = np.asarray(v, dtype=_FLOAT).ravel()
    return math.sqrt(_einsum("i,i->", v, v))


def solve_spd(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``x`` with ``A x = b`` for a symmetric positive definite ``A`` (Cholesky, Eigen's ``LLT``)."""
    A = np.asarray(A, dtype=_FLOAT)
    decomposition = eigenpy.LLT(A)
    # np.isfinite(A).all(), without the method's Python layer
    if decomposition.info() != _SUCCESS or not np.logical_and.reduce(np.isfinite(A), axis=None):
        # a numerical failure inside the simulation, not a user's value: numpy's own type for it
        raise np.linalg.LinAlgError(f"solve_spd needs a finite symmetric positive definite matrix, got {A!r}.")
    return np.asarray(decomposition.solve(np.asarray(b, dtype=_FLOAT)), dtype=_FLOAT)


def lstsq(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The minimum-norm least-squares solution of ``A x = b``, as ``np.linalg.lstsq(A, b)[0]`` gives it
    (Eigen's complete orthogonal decomposition, which also handles a rank-deficient ``A``)."""
    A, b = np.asarray(A, dtype=np.float64), np.asarray(b, dtype=np.float64)
    if not (np.all(np.isfinite(A)) and np.all(np.isfinite(b))):  # as np.linalg.lstsq refuses them
        raise np.linalg.LinAlgError(f"lstsq needs finite values, got A={A!r}, b={b!r}.")
    return np.asarray(eigenpy.CompleteOrthogonalDecomposition(A).solve(b), dtype=np.float64)
