"""The exact contact set of each Newton step's linear model (frictionless nodal contacts).

Semismooth Newton (GNRM) takes the contact set of a step from the sign of
lam + r g at the iterate: a node that closes or opens within the step is
found one iteration late, and every such node costs an iteration.
:class:`ExactContactSet` solves instead, at every Newton step, the linear
complementarity problem of the step's own linear model on the nodes that
may change, with the factorisation the step has anyway:

1. *candidates*: the nodes in contact at the iterate and the open nodes that
   may close within the step: gap below a quarter of the node's gap change
   over the last iteration, or below the prescribed displacement still to
   be applied; never beyond a quarter of a facet (:data:`REACH`), at most
   :data:`MAX_FORCED` (nearest first), and only where the contact says the
   Jacobian holds the open node's gap derivative (``Contact.may_close``).
   Each open candidate is set in contact for the step by its multiplier:
   the Jacobian is assembled at lam = -r g - margin, so that it takes the
   contact branch, and the step starts from lam = -r g, where the residual
   is that of the open branch with the new multiplier (the residual is
   continuous across lam + r g = 0): the node puts no force on the
   displacement rows on either side, and its own row, w (min(lam + r g, 0)
   - lam) = -w lam in the open branch, changes with lam alone. So b is
   patched on those rows, not assembled again (:meth:`ExactContactSet.settle`).
   The step holds every candidate on its target (linearised gap zero).
   That is the step dx0.
2. *release*: node j is opened in the linear model by shifting its gap row's
   right-hand side by w_j phi_j (w_j its lumped area), which gives it the
   linearised augmented gap r g_j = phi_j; the response is z_j = J^-1 e_j,
   one back-substitution with the factorisation at hand.
3. the linearised pressures of the candidates are F = F0 + G phi, with
   G_ij = delta_ij + w_j (z_j)_i (F0: the step dx0's new multipliers).
   The linear complementarity problem phi >= 0, F <= 0, phi F = 0 (G is
   minus a compliance inverse: a P-matrix, so the answer is unique and
   independent of r) is solved by principal pivoting on the released
   nodes; a candidate without a column whose pressure comes out tensile
   gets one and the problem is solved again.
4. the step is dx = dx0 - sum_j phi_j w_j z_j; released nodes leave the step
   with lam = 0 (open).

The answer of the nonlinear problem is unchanged (the residual is the same);
only the set each iteration uses is the linear model's exact one rather
than the iterate's. Frictionless contacts with the vertex rule and a direct
linear solver only; other contacts keep the sign rule.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mpi4py import MPI
from petsc4py import PETSc

#: Relative size of the margin that sets a candidate in contact with zero force.
MARGIN = 1e-9
#: An open node is a candidate when its gap is below this multiple of its gap's last change.
BAND = 0.25
#: An open node farther than this fraction of its surface's facet size is never a candidate.
REACH = 0.25
#: Open nodes set in contact at most per Newton step (those of smallest gap), so that
#: each can have its column.
MAX_FORCED = 32
#: Columns (back-substitutions) at most per Newton step.
MAX_COLUMNS = 64
#: Pivoting steps at most per complementarity solve.
MAX_PIVOTS = 200


@dataclass
class _Candidates:
    """The candidate nodes of one Newton step, in a global order every rank shares."""

    positions: np.ndarray  # local positions in the kernel's vector (this rank's candidates)
    weights: np.ndarray    # lumped areas w_j of every candidate (global order)
    owner: np.ndarray      # rank of every candidate
    local: np.ndarray      # index of every candidate among its owner's candidates
    forced: np.ndarray     # True where an open node was set in contact (global order)


class ExactContactSet:
    """The linear model's exact contact set at every Newton step of a kernel.

    Args:
        problem: the contact problem (its frictionless vertex-rule contacts are handled).
        kernel: the Newton kernel whose steps are corrected.
    """

    def __init__(self, problem, kernel) -> None:
        self.kernel = kernel
        self.comm = problem.comm
        self.contacts = [c for c in problem.contacts
                         if c.friction is None and c.settings.quadrature == "nodal"]
        offsets, start = {}, 0
        for u in kernel.unknowns:
            im = u.function_space.dofmap.index_map
            offsets[id(u)] = start
            start += im.size_local * u.function_space.dofmap.index_map_bs
        self._offsets = [offsets.get(id(c.lam)) for c in self.contacts]
        self._last_gaps: list[np.ndarray] | None = None
        #: The open candidates set in contact at this step, per contact: (positions in
        #: the kernel's vectors, lumped areas, multipliers before, -r g).
        self._settle: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []
        #: Back-substitutions taken (columns), over the kernel's life.
        self.columns = 0
        self._step: _Candidates | None = None

    @property
    def usable(self) -> bool:
        """Whether any contact is handled and the linear solver is direct."""
        return bool(self.contacts) and all(o is not None for o in self._offsets) \
            and self.kernel.linear.kind == "direct"

    def begin(self) -> None:
        """A new nonlinear solve starts: no gap change is known yet (the load's own is)."""
        self._last_gaps = None

    # -- before the Jacobian -------------------------------------------------------
    def prepare(self) -> bool:
        """Choose the candidates and set the open ones in contact; True when any was set.

        The multipliers of the ones set in contact are those the Jacobian is
        assembled at (the kernel's x must take them); :meth:`settle` then
        moves them to -r g and patches b.
        """
        self._settle = []
        if not self.usable:
            return False
        gaps = []
        for c in self.contacts:
            c.refresh()
            gaps.append(c.surface.nodal(c._gap_form))
        last = self._last_gaps
        if last is None or any(a.size != b.size for a, b in zip(gaps, last, strict=True)):
            last = gaps
        self._last_gaps = [g.copy() for g in gaps]
        prescribed = self._prescribed_increment()
        actives, nears = [], []
        for c, g, g_last in zip(self.contacts, gaps, last, strict=True):
            lam = c.lam.x.array[:g.size]
            band = np.minimum(np.maximum(BAND * np.abs(g - g_last), prescribed),
                              REACH * c.surface.h)
            active = lam + float(c.r.value) * g < 0.0
            actives.append(active)
            nears.append(~active & (g < band) & c.may_close(g))
        nears = self._closest(gaps, nears)
        positions, weights, forced = [], [], []
        changed = False
        for c, g, active, near, offset in zip(self.contacts, gaps, actives, nears,
                                              self._offsets, strict=True):
            lam = c.lam.x.array[:g.size]
            r = float(c.r.value)
            scale = self.comm.allreduce(float(np.max(np.abs(lam), initial=0.0)), op=MPI.MAX)
            if np.any(near):
                # a margin well above the round-off of r g: the contact branch for sure
                tiny = MARGIN * np.maximum(max(scale, 1e-6 * r * c.surface.h), r * np.abs(g[near]))
                nodes = np.flatnonzero(near)
                self._settle.append((offset + nodes, c.surface.lumped_area[nodes],
                                     lam[nodes].copy(), -r * g[nodes]))
                lam[near] = -r * g[near] - tiny
            changed |= bool(np.any(near))
            chosen = np.flatnonzero(active | near)
            positions.append(offset + chosen)
            weights.append(c.surface.lumped_area[chosen])
            forced.append(near[chosen])
        changed = bool(self.comm.allreduce(int(changed), op=MPI.MAX))
        if changed:
            for c in self.contacts:
                c.lam.x.scatter_forward()
        pos = np.concatenate(positions).astype(np.int64)
        counts = self.comm.allgather(pos.size)
        self._step = _Candidates(
            positions=pos,
            weights=_joined(self.comm, np.concatenate(weights)),
            owner=np.repeat(np.arange(len(counts)), counts),
            local=np.concatenate([np.arange(k) for k in counts]).astype(np.int64),
            forced=_joined(self.comm, np.concatenate(forced)),
        )
        return changed

    def settle(self) -> None:
        """After the Jacobian: the candidates set in contact start the step at lam = -r g.

        Their multiplier rows of b (w (min(lam + r g, 0) - lam): the open
        branch's -w lam, which the contact branch equals there) change by
        -w (lam_new - lam_old); no other row holds a force from them, before
        or after. b was assembled at lam_old by the loop's residual, and
        keeps its Dirichlet rows and lifting.
        """
        if not self._settle:
            return
        x = self.kernel.x.getArray()
        b = self.kernel.b.getArray()
        for positions, weights, before, after in self._settle:
            b[positions] -= weights * (after - before)
            x[positions] = after
        self._settle = []

    def _closest(self, gaps: list[np.ndarray], nears: list[np.ndarray]) -> list[np.ndarray]:
        """At most :data:`MAX_FORCED` open candidates over the ranks: those of smallest gap."""
        local = np.concatenate([g[n] for g, n in zip(gaps, nears, strict=True)])
        every = np.sort(_joined(self.comm, local))
        if every.size <= MAX_FORCED:
            return nears
        limit = every[MAX_FORCED - 1]
        return [n & (g <= limit) for g, n in zip(gaps, nears, strict=True)]

    def _prescribed_increment(self) -> float:
        """The largest |u - u_D| on the Dirichlet dofs (length): how far the load moves them."""
        u = self.kernel.unknowns[0].x.array
        target = np.zeros_like(u)
        largest = 0.0
        for bc in self.kernel.bcs:
            dofs, n = bc.dof_indices()
            bc.set(target)
            if n:
                largest = max(largest, float(np.max(np.abs(u[dofs[:n]] - target[dofs[:n]]))))
        return self.comm.allreduce(largest, op=MPI.MAX)

    # -- after the solve -----------------------------------------------------------
    def _gather(self, local: np.ndarray) -> np.ndarray:
        """Rows of a local array at every candidate (global order)."""
        return _joined(self.comm, local[self._step.positions])

    def _columns(self, wanted: list[int]) -> np.ndarray:
        """z_j = J^-1 e_j for the wanted candidates: the local rows (n_local x k).

        One solve with several right-hand sides (the factorisation at hand).
        """
        step = self._step
        A = self.kernel.A
        n_local, n_global = A.getLocalSize()[0], A.getSize()[0]
        k = len(wanted)
        B = PETSc.Mat().createDense(((n_local, n_global), (PETSc.DECIDE, k)), comm=A.comm)
        B.setUp()
        rows = B.getDenseArray()
        rows[:] = 0.0
        for col, j in enumerate(wanted):
            if step.owner[j] == self.comm.rank:
                rows[step.positions[step.local[j]], col] = 1.0
        B.assemble()
        X = B.duplicate()
        self.kernel.ksp.matSolve(B, X)
        out = np.array(X.getDenseArray(), copy=True)
        B.destroy()
        X.destroy()
        self.columns += k
        return out

    def correct(self) -> None:
        """Replace the kernel's step dx by the step of the linear model's exact contact set."""
        step = self._step
        if step is None or step.owner.size == 0:
            return
        kernel = self.kernel
        x = kernel.x.getArray(readonly=True)
        F0 = self._gather(x) - self._gather(kernel.dx.getArray(readonly=True))
        scale = max(float(np.max(np.abs(F0), initial=0.0)), 1e-300)
        tol = 1e-10 * scale
        columns: list[int] = []
        Z = np.zeros((kernel.dx.getLocalSize(), 0))
        at_candidates = np.zeros((F0.size, 0))
        phi = np.zeros(0)
        F = F0
        while True:
            tensile = np.flatnonzero(F > tol)
            tensile = tensile[np.argsort(~step.forced[tensile], kind="stable")]  # forced first
            wanted = [int(j) for j in tensile if j not in columns]
            wanted = wanted[:MAX_COLUMNS - len(columns)]
            if not wanted:
                break
            block = self._columns(wanted)
            Z = np.hstack([Z, block])
            at_candidates = np.hstack([at_candidates, self._gather(block)])
            columns += wanted
            G = at_candidates * step.weights[columns]
            G[columns, np.arange(len(columns))] += 1.0
            try:
                phi = _solve_lcp(F0[columns], G[columns], tol)
            except np.linalg.LinAlgError:  # dependent constraints (shared nodes): keep dx0
                return
            F = F0 + G @ phi
        self._step = None
        if not columns:
            return
        arr = kernel.dx.getArray()
        arr -= Z @ (phi * step.weights[columns])
        for j, value in zip(columns, phi, strict=True):
            if value > 0.0 and step.owner[j] == self.comm.rank:
                p = step.positions[step.local[j]]
                arr[p] = x[p]  # lam = x - dx = 0: the node leaves the step open


def _joined(comm: MPI.Comm, local: np.ndarray) -> np.ndarray:
    """Every rank's ``local`` rows joined in rank order (a copy; serial: without MPI)."""
    if comm.size == 1:
        return np.array(local, copy=True)
    return np.concatenate(comm.allgather(local))


def _solve_lcp(F0: np.ndarray, G: np.ndarray, tol: float) -> np.ndarray:
    """The openings phi >= 0 with F = F0 + G phi <= 0 and phi F = 0 (-G: a P-matrix).

    Block principal pivoting (all infeasible indices flip) while the count of
    infeasible indices falls, Murty's least-index rule otherwise (finite for
    P-matrices).
    """
    n = F0.size
    released = F0 > tol
    best = n + 1
    phi = np.zeros(n)
    for _ in range(MAX_PIVOTS):
        phi = np.zeros(n)
        idx = np.flatnonzero(released)
        if idx.size:
            phi[idx] = np.linalg.solve(G[np.ix_(idx, idx)], -F0[idx])
        F = F0 + G @ phi
        bad = (released & (phi < -tol)) | (~released & (F > tol))
        count = int(bad.sum())
        if count == 0:
            return np.maximum(phi, 0.0)
        if count < best:
            best = count
            released ^= bad
        else:
            k = int(np.flatnonzero(bad)[0])
            released[k] = ~released[k]
    return np.maximum(phi, 0.0)
