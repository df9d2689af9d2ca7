"""Global energy, internal force and tangent stiffness of a structure, one design or a batch.

Each evaluation runs the element kernels of the active kernel path
(:func:`holofold.mechanics.kernels.active`: numpy, or numba as an accelerator) into the
:class:`ElementArrays` and sums them into the storage the solver wants by the
:class:`~holofold.mechanics.sparsity.SumLists` of the cached sparsity
(:mod:`~holofold.mechanics.sparsity`); :mod:`~holofold.mechanics.linear` factorises and
:mod:`~holofold.mechanics.newton_step` runs whole Newton updates in one kernel call.

Typical use::

    asm = Assembler(structure)
    energy, f_int, K = asm.evaluate(U)                 # full system, K csr (ndof, ndof)
    energy, f_int, K_ff = asm.evaluate_reduced(U)      # K on the free DOFs (dense or csr)
    energy, f_int, solve = asm.evaluate_factorized(U)  # dU_f = solve(r[asm.free_dofs])
"""

from __future__ import annotations

from functools import cached_property
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from holofold.mechanics import kernels, linear
from holofold.mechanics.bars import ElementResponse
from holofold.mechanics.kernel_args import ModelArrays, Scatter
from holofold.mechanics.linear import DENSE_MAX_DOF, SingularSystemError, solver_path
from holofold.mechanics.sparsity import AssemblyPattern, ReducedPattern, SumLists, assembly_pattern
from holofold.mechanics.springs import arccos_shift
from holofold.mechanics.structure import Structure

__all__ = [
    "Assembler",
    "BatchAssembler",
    "AssembledSystem",
    "ElementArrays",
    "KernelInputs",
    "SingularSystemError",
    "assembly_pattern",
    "DENSE_MAX_DOF",
    "solver_path",
]


class AssembledSystem(NamedTuple):
    """Result of one evaluation (unpacks as ``energy, force, stiffness``).

    energy     float                     total strain energy, J
    force      (ndof,) float             internal force vector T(U), N
    stiffness  csr (n, n) | (n, n) array tangent stiffness (full, or free-free block), N/m
    """

    energy: float
    force: np.ndarray
    stiffness: sp.csr_matrix | np.ndarray


class ElementArrays(NamedTuple):
    """The element arrays the kernels write, in their layouts (see
    :func:`~holofold.mechanics.bars.bar_kernel`, :func:`~holofold.mechanics.springs.
    spring_kernel`): bar energy (nb,), force (3, 2, nb), tangent (3, 3, 2, 2, nb); spring
    energy (ns,), force (3, 4, ns), tangent (3, 3, 10, ns), angle (ns,)."""

    bar_energy: np.ndarray
    bar_force: np.ndarray
    bar_tangent: np.ndarray
    spring_energy: np.ndarray
    spring_force: np.ndarray
    spring_tangent: np.ndarray
    spring_angle: np.ndarray

    @classmethod
    def empty(cls, nb: int, ns: int) -> ElementArrays:
        return cls(
            np.empty(nb), np.empty((3, 2, nb)), np.empty((3, 3, 2, 2, nb)),
            np.empty(ns), np.empty((3, 4, ns)), np.empty((3, 3, 10, ns)), np.empty(ns),
        )  # fmt: skip

    def flat(self) -> ElementArrays:
        """The same memory, flat (what the sum lists index)."""
        return ElementArrays(*(a.reshape(-1) for a in self))


class KernelInputs(NamedTuple):
    """What the kernels read of a model, per design (a leading sample axis in a batch):
    reference coordinates ``X`` (nn, 3), bar end nodes ``b0``, ``b1`` (nb,), reference bar
    vectors ``D0`` (3, nb), rest lengths ``L0`` (nb,), axial rigidities ``EA`` (nb,), spring
    node quadruples ``sT`` (4, ns) and stiffnesses ``k`` (ns,)."""

    X: np.ndarray
    b0: np.ndarray
    b1: np.ndarray
    D0: np.ndarray
    L0: np.ndarray
    EA: np.ndarray
    sT: np.ndarray
    k: np.ndarray

    @classmethod
    def of(cls, structure: Structure) -> KernelInputs:
        X = np.ascontiguousarray(structure.nodes, dtype=float)
        b0 = np.ascontiguousarray(structure.bars[:, 0], dtype=np.intp)
        b1 = np.ascontiguousarray(structure.bars[:, 1], dtype=np.intp)
        XT = X.T
        return cls(
            X,
            b0,
            b1,
            np.ascontiguousarray(XT[:, b1] - XT[:, b0]),
            np.ascontiguousarray(structure.bar_length, dtype=float),
            np.ascontiguousarray(structure.bar_E * structure.bar_area, dtype=float),
            np.ascontiguousarray(structure.springs.T, dtype=np.intp),
            np.ascontiguousarray(structure.spring_k, dtype=float),
        )

    def model(self, U, theta0, k_nonneg) -> ModelArrays:
        """The kernels' model record: these arrays with displacements ``U``, rest angles
        ``theta0`` and ``k_nonneg`` (batch-shaped like the inputs)."""
        return ModelArrays(self.X, U, *self[1:], theta0, k_nonneg)

    def batch_of_one(self) -> KernelInputs:
        return KernelInputs(*(a.reshape((1, *a.shape)) for a in self))

    @classmethod
    def stack_of(cls, structures) -> KernelInputs:
        """The inputs of S structures of one size, stacked (S, ...), built as arrays."""
        X = np.stack([np.asarray(s.nodes, float) for s in structures])
        first = structures[0].bars
        if all(s.bars is first for s in structures):  # one bar array (a builder's layout)
            bars = np.asarray(first, np.intp)
            ends = np.repeat(bars.T[:, None], len(structures), axis=1)  # (2, S, nb)
            b0, b1 = ends[0], ends[1]  # C-contiguous rows
            D0 = np.ascontiguousarray((X[:, bars[:, 1]] - X[:, bars[:, 0]]).transpose(0, 2, 1))
        else:
            bars = np.stack([s.bars for s in structures]).astype(np.intp)
            b0 = np.ascontiguousarray(bars[:, :, 0])
            b1 = np.ascontiguousarray(bars[:, :, 1])
            D0 = np.take_along_axis(X, b1[..., None], 1) - np.take_along_axis(X, b0[..., None], 1)
            D0 = np.ascontiguousarray(D0.transpose(0, 2, 1))
        springs = np.stack([s.springs for s in structures]).astype(np.intp)
        return cls(
            X,
            b0,
            b1,
            D0,
            np.stack([np.asarray(s.bar_length, float) for s in structures]),
            np.stack([s.bar_E * s.bar_area for s in structures]).astype(float),
            np.ascontiguousarray(springs.transpose(0, 2, 1)),
            np.stack([np.asarray(s.spring_k, float) for s in structures]),
        )


def sum_into(lists: SumLists, bar_values, spring_values, out) -> np.ndarray:
    """``out`` (zeros) filled by the active kernel path's scatter with ``lists`` (bars,
    springs, spring mirrors) from the element arrays."""
    vb = bar_values.reshape(-1)
    vs = spring_values.reshape(-1)
    kernels.active().module.scatter(
        lists.bar_src, lists.bar_tgt, vb, lists.spring_src, lists.spring_tgt, vs,
        lists.mirror_src, lists.mirror_tgt, vs, out,
    )  # fmt: skip
    return out


class Assembler:
    """Evaluate the global energy, internal force and tangent of a :class:`Structure`.

    Parameters
    ----------
    structure : Structure
        The model (reference coordinates, element properties, supports).
    pattern : AssemblyPattern, optional
        A pattern built for the same connectivity (default: the cached one).
    dense_max : int
        Reduced systems with at most this many free DOFs are built and solved dense.

    The assembler reads the structure's arrays once; build a new one for a changed structure
    (it is cheap: the pattern comes from the cache). Not thread-safe: one per thread.
    """

    def __init__(
        self,
        structure: Structure,
        pattern: AssemblyPattern | None = None,
        *,
        dense_max: int = DENSE_MAX_DOF,
    ):
        if pattern is None:
            pattern = assembly_pattern(structure)
        elif not pattern.compatible(structure.n_dof, structure.bar_dofs, structure.spring_dofs):
            raise ValueError("pattern was built for another connectivity than this structure")
        self.structure = structure
        self.pattern = pattern
        self.dense_max = int(dense_max)
        self.X = structure.nodes
        self.bars = structure.bars
        self.springs = structure.springs
        self.theta0 = structure.spring_rest
        self.n_dof = structure.n_dof
        self.inputs = KernelInputs.of(structure)
        self.k_nonneg = bool(np.all(self.inputs.k >= 0.0))
        self.arccos = structure.profile.arccos_dihedral and len(self.springs) > 0
        self._work: ElementArrays | None = None

    @cached_property
    def reduction(self) -> ReducedPattern:
        """Free-DOF reduction for the structure's supports."""
        return self.pattern.reduced(~self.structure.supports.ravel())

    @property
    def free_dofs(self) -> np.ndarray:
        """(nf,) int: free global DOFs."""
        return self.reduction.free

    @property
    def solver(self) -> str:
        """The solver path of this structure (:func:`~holofold.mechanics.linear.solver_path`)."""
        return solver_path(self.reduction, self.dense_max)

    # ------------------------------------------------------------------ evaluation
    def rest_angles(self, U, spring_rest=None) -> np.ndarray:
        """The rest angles the kernels use at ``U`` (with the reference's arccos shift where
        the profile asks for it), C-contiguous (ns,)."""
        if spring_rest is None:
            theta0 = self.theta0
        else:
            theta0 = np.asarray(spring_rest, float)
            if theta0.shape != self.theta0.shape:
                raise ValueError(
                    f"spring_rest must have shape {self.theta0.shape}, got {theta0.shape}"
                )
        if self.arccos:  # the reference's arccos angle (compat.Profile.arccos_dihedral)
            theta0 = theta0 + arccos_shift(self.X + U, self.springs)
        return np.ascontiguousarray(theta0, dtype=float)

    def _kernels(self, U, spring_rest, tangent, out: ElementArrays) -> ElementArrays:
        """Run the bar and spring kernels into ``out``."""
        ck = kernels.active().module
        U = np.ascontiguousarray(np.asarray(U, dtype=float).reshape(-1, 3))
        if U.shape[0] != self.X.shape[0]:
            raise ValueError(f"U must have shape ({self.X.shape[0]}, 3), got {np.shape(U)}")
        theta0 = self.rest_angles(U, spring_rest)
        X, b0, b1, D0, L0, EA, sT, k = self.inputs
        ck.bar_elements(
            X, U, b0, b1, D0, L0, EA, tangent, (out.bar_energy, out.bar_force, out.bar_tangent)
        )
        ck.spring_elements(
            X, U, sT, k, theta0, self.k_nonneg, tangent,
            (out.spring_energy, out.spring_force, out.spring_tangent, out.spring_angle),
        )  # fmt: skip
        return out

    def _buffers(self) -> ElementArrays:
        if self._work is None:
            self._work = ElementArrays.empty(len(self.bars), len(self.springs))
        return self._work

    def element_response(self, U, spring_rest=None, *, tangent: bool = True):
        """Element-level bar and spring responses ``(bar, spring)`` in the kernels' layouts;
        new arrays on every call."""
        a = self._kernels(
            U, spring_rest, tangent, ElementArrays.empty(len(self.bars), len(self.springs))
        )
        return (
            ElementResponse(a.bar_energy, a.bar_force, a.bar_tangent if tangent else None),
            ElementResponse(a.spring_energy, a.spring_force, a.spring_tangent if tangent else None),
        )

    def _elements(self, U, spring_rest, tangent=True):
        a = self._kernels(U, spring_rest, tangent, self._buffers())
        energy = float(a.bar_energy.sum() + a.spring_energy.sum())
        f = sum_into(self.pattern.force_sums, a.bar_force, a.spring_force, np.zeros(self.n_dof))
        return energy, f, a

    def _tangent(self, a: ElementArrays, storage: str) -> np.ndarray:
        """The tangent in ``storage`` (flat) from the element arrays."""
        red = self.reduction
        lists = red.tangent_sums(storage)
        out = np.zeros(red.storage_size(storage))
        return sum_into(lists, a.bar_tangent, a.spring_tangent, out)

    def internal_force(self, U, spring_rest=None) -> tuple[float, np.ndarray]:
        """Energy (J) and internal force (ndof,) N, without the tangent."""
        energy, f, _ = self._elements(U, spring_rest, tangent=False)
        return energy, f

    def evaluate(self, U, spring_rest=None) -> AssembledSystem:
        """Energy, internal force (ndof,) and full tangent (csr ndof x ndof) at displacement U
        ((nn, 3) or (ndof,), m), optionally with other rest angles ``spring_rest`` (ns,)."""
        energy, f, a = self._elements(U, spring_rest)
        pat = self.pattern
        data = self._tangent(a, "csr")
        K = sp.csr_matrix((data, pat.indices, pat.indptr), shape=(self.n_dof, self.n_dof))
        return AssembledSystem(energy, f, K)

    def evaluate_reduced(self, U, spring_rest=None, *, dense: bool | None = None):
        """Energy, full internal force (ndof,) and the free-free tangent block: a dense
        ``(nf, nf)`` array when ``dense`` (default: ``nf <= dense_max``), else csr; its rows
        and columns follow :attr:`free_dofs`."""
        energy, f, a = self._elements(U, spring_rest)
        red = self.reduction
        nf = red.n_free
        if dense is None:
            dense = nf <= self.dense_max
        if dense:
            K = self._tangent(a, "dense").reshape(nf, nf)
        else:
            data = self._tangent(a, "csr")
            K = sp.csr_matrix((data[red.keep], red.indices, red.indptr), shape=(nf, nf))
        return AssembledSystem(energy, f, K)

    def evaluate_factorized(self, U, spring_rest=None):
        """Energy, full internal force (ndof,) and ``solve(rhs)`` of the free-free tangent
        (``rhs`` (nf,) or (nf, k) on :attr:`free_dofs`; one factorisation serves every call;
        :class:`SingularSystemError` for a singular tangent or a non-finite solution)."""
        energy, f, a = self._elements(U, spring_rest)
        return energy, f, self._factorize(a)

    def _factorize(self, a: ElementArrays):
        red = self.reduction
        path = self.solver
        if path == "none":
            return linear.zero_solver
        if path == "dense":
            return linear.dense_solver(
                self._tangent(a, "dense").reshape(red.n_free, -1), symmetric=True
            )
        if path == "banded":
            solve = linear.band_solver(self._tangent(a, "banded"), red)
            if solve is not None:
                return solve
            # not positive definite: LU below
        if path == "cholesky":
            solve = linear.cholesky_solver(self._tangent(a, "csr_upper"), red)
            if solve is not None:
                return solve
            # not positive definite: LU below
        return linear.lu_solver(self._tangent(a, "csr"), red)

    def dense_stepper(self, U, F, spring_rest=None, r=None):
        """A :class:`~holofold.mechanics.newton_step.DenseStepper`: ``step()`` does
        ``_, f, solve = evaluate_factorized(U); dU = solve((F - f)[free]); U[free] += dU`` in
        one kernel call (``U`` (ndof,) updated in place; ``r`` (nf,) optional, filled with the
        residual before the update), or None where this assembler does not take the dense path
        or uses the reference's arccos angle (then use :meth:`evaluate_factorized`)."""
        from holofold.mechanics.newton_step import DenseStepper

        if self.arccos or self.solver != "dense":
            return None
        return DenseStepper(self, U, F, spring_rest, r)

    def dense_newton_update(self, U, F, spring_rest=None, r=None):
        """One :meth:`dense_stepper` step: the increment ``dU`` on :attr:`free_dofs` (a buffer
        the next call overwrites), or None off the dense path."""
        step = self.dense_stepper(U, F, spring_rest, r)
        return None if step is None else step()


class BatchAssembler:
    """S structures of one size and one support mask, evaluated together.

    Every sample of an arch m or a Miura m x n sheet has the same nodes, bars and springs up to
    the orientation of some springs (the polarity rule follows the geometry), hence one of a
    few connectivities. One call of :meth:`factorized` runs the kernels for the active samples
    of each connectivity in one kernel call, then factorises each sample's tangent by the path
    :class:`Assembler` takes; :meth:`newton_step` does whole Newton updates in one call.

    Parameters
    ----------
    structures : sequence of Structure
        Same numbers of nodes, bars and springs and the same supports (``ValueError``
        otherwise).
    dense_max : int
        As for :class:`Assembler`.
    """

    def __init__(self, structures, *, dense_max: int = DENSE_MAX_DOF):
        structures = list(structures)
        if not structures:
            raise ValueError("a batch needs at least one structure")
        sizes = {(s.n_dof, len(s.bars), len(s.springs)) for s in structures}
        masks = {s.supports.tobytes() for s in structures}
        if len(sizes) > 1 or len(masks) > 1:
            raise ValueError("the structures of a batch need the same sizes and supports")
        self.structures = structures
        self.dense_max = int(dense_max)
        self.n = len(structures)
        self.n_dof = structures[0].n_dof
        self.patterns = [assembly_pattern(s) for s in structures]
        groups: dict[int, list[int]] = {}
        for i, pat in enumerate(self.patterns):
            groups.setdefault(id(pat), []).append(i)
        free = ~structures[0].supports.ravel()
        #: (pattern, reduction, samples) of each connectivity
        self.groups = [
            (self.patterns[g[0]], self.patterns[g[0]].reduced(free), np.array(g, np.intp))
            for g in groups.values()
        ]
        self.inputs = KernelInputs.stack_of(structures)
        self.theta0 = np.stack([np.asarray(s.spring_rest, float) for s in structures])
        self.k_nonneg = np.all(self.inputs.k >= 0.0, axis=1)
        self.arccos = [s.profile.arccos_dihedral and len(s.springs) > 0 for s in structures]
        self.scratch = ElementArrays.empty(len(structures[0].bars), len(structures[0].springs))

    @cached_property
    def assemblers(self) -> list[Assembler]:
        """One :class:`Assembler` per structure (built on first use: the fallbacks)."""
        return [
            Assembler(s, pat, dense_max=self.dense_max)
            for s, pat in zip(self.structures, self.patterns, strict=True)
        ]

    @property
    def free_dofs(self) -> np.ndarray:
        return self.groups[0][1].free

    def scatter(self, pat: AssemblyPattern) -> Scatter:
        """The kernels' :class:`~holofold.mechanics.kernel_args.Scatter` of connectivity
        ``pat``: its force sums and this batch's element arrays."""
        return Scatter(pat.force_sums, self.scratch, self.scratch.flat())

    def rest_angles(self, U3, active, spring_rest=None) -> np.ndarray:
        """(S, ns) rest angles the kernels use (the reference's arccos shift where asked)."""
        rest = self.theta0 if spring_rest is None else np.array(spring_rest, dtype=float)
        if rest.shape != self.theta0.shape:
            raise ValueError(f"spring_rest must have shape {self.theta0.shape}")
        if any(self.arccos):
            rest = rest.copy()
            for s in np.flatnonzero(active):
                if self.arccos[s]:
                    st = self.structures[s]
                    rest[s] = rest[s] + arccos_shift(st.nodes + U3[s], st.springs)
        return np.ascontiguousarray(rest)

    def factorized(self, U, active, spring_rest=None):
        """Internal forces and solvers of the ``active`` samples.

        Parameters
        ----------
        U : (S, nn, 3) float
            Displacements, m.
        active : (S,) bool
            Samples to evaluate (the others are left alone).
        spring_rest : (S, ns) float, optional
            Rest angles instead of the structures' own, rad.

        Returns
        -------
        force : (S, ndof) float
            Internal force of each active sample (rows of the others are zero), N.
        solves : list
            Per sample: ``solve(rhs)`` as from :meth:`Assembler.evaluate_factorized`, the
            :class:`SingularSystemError` its factorisation raised, or None (inactive).
        """
        ck = kernels.active().module
        U = np.ascontiguousarray(np.asarray(U, dtype=float).reshape(self.n, -1, 3))
        active = np.ascontiguousarray(active, dtype=bool)
        rest = self.theta0 if spring_rest is None else np.array(spring_rest, dtype=float)
        theta0 = self.rest_angles(U, active, spring_rest)
        f = np.zeros((self.n, self.n_dof))
        solves: list = [None] * self.n
        for pat, red, members in self.groups:
            idx = np.ascontiguousarray(members[active[members]], dtype=np.intp)
            if idx.size == 0:
                continue
            path = solver_path(red, self.dense_max)
            if path == "none":
                for s in idx:
                    solves[s] = linear.zero_solver
                continue
            storage = linear.storage_of(path)
            lists = red.tangent_sums(storage)
            fj = np.empty((idx.size, self.n_dof))
            kj = np.empty((idx.size, red.storage_size(storage)))
            ck.assemble_batch(
                self.inputs.model(U, theta0, self.k_nonneg), idx, self.scatter(pat), lists, fj, kj
            )
            f[idx] = fj
            for j, s in enumerate(idx):
                solves[s] = self._solver(s, path, red, kj[j], U[s], rest[s])
        return f, solves

    def newton_step(self, U, rhs_force, active):
        """One Newton update of the ``active`` samples: ``U[s, free] += dU`` with
        ``dU = K_ff^-1 (rhs_force[s] - f_int[s])[free]``
        (:func:`~holofold.mechanics.newton_step.batch_newton_step`).

        Parameters
        ----------
        U : (S, ndof) float, C-contiguous
            Displacements, updated in place, m.
        rhs_force : (S, ndof) float
            External force of each sample, N.
        active : (S,) bool

        Returns
        -------
        dU : (S, nf) float
            Row s: the increment of active sample s on :attr:`free_dofs` (rows of inactive
            or failed samples are undefined).
        errors : dict
            Sample -> the :class:`SingularSystemError` that stopped it (its U is left alone).
        """
        from holofold.mechanics.newton_step import batch_newton_step

        return batch_newton_step(self, U, rhs_force, active)

    def _solver(self, s, path, red, values, U, rest):
        """The solver of sample ``s`` from its dense block, band or CSR data ``values``
        (``rest``: its rest angles, for the LU fallback's own evaluation)."""
        if path == "dense":
            return linear.dense_solver(values.reshape(red.n_free, red.n_free), symmetric=True)
        if path in ("banded", "cholesky"):
            factor = linear.band_solver if path == "banded" else linear.cholesky_solver
            solve = factor(values, red)
            if solve is not None:
                return solve
            # not positive definite: LU on the full CSR data of this sample alone
            a = self.assemblers[s]
            values = a._tangent(a._kernels(U, rest, True, a._buffers()), "csr")
        try:
            return linear.lu_solver(values, red)
        except SingularSystemError as exc:
            return exc
