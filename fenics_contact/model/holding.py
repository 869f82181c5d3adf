"""Which rigid motions of a problem's bodies its supports and closed contacts hold, in a state.

The analysis is :class:`~.rigid.AssemblyModes` (the rigid modes the
Dirichlet conditions leave free, then the contacts' rates of change along
them); the scene checks ask it before the run, with the gaps closed at the
start holding the motions that would close them
(:func:`~fenics_contact.scene.checks.free_motion_of_contacts`). The contacts
that hold a body change during the run: this module hands it a problem's
contacts in a converged state (:meth:`ContactHold.in_state`, every accepted
iterate). A contact node that is closed there, active (pressure < 0; the
penalty method: penetrating) or touching (gap at most ``gap_tol`` h),
holds its gap both ways, as the active set of the Newton step does; a
sticking node of a frictional contact also holds its slip (both tangential
components). A body whose rigid motion nothing closed holds has a singular
stiffness there, and the iterate is one member of a family of rigid
positions (a Uzawa strategy at small r that lost every contact threw a
stack clean through the ball pressing it).

The contacts' measures are evaluated for rigid motions of the bodies by
setting u (a difference quotient); u is put back afterwards and the
searches refreshed. Collective.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from mpi4py import MPI

from fenics_contact.model.friction import STICK
from fenics_contact.model.rigid import AssemblyModes

if TYPE_CHECKING:
    from fenics_contact.model.problem import ContactProblem


def problem_bodies(problem: ContactProblem) -> list[tuple[str, np.ndarray]]:
    """(name, local cell indices) of each body of the problem's solid."""
    solid = problem.solid
    tdim = problem.domain.topology.dim
    every = np.arange(problem.domain.topology.index_map(tdim).size_local, dtype=np.int32)
    return [(b.name, every if b.tag is None else solid.cell_tags.find(b.tag))
            for b in solid.bodies if b.stabilise <= 0.0]  # springs hold a stabilised body


class ContactHold:
    """A problem's rigid modes, its supports and its contacts, for the check of a state.

    Built once per problem (the bodies' nodes, the prescribed components,
    the displacement dof of each geometry node).

    Args:
        problem: the problem (its u is set and put back by the check).
    """

    def __init__(self, problem: ContactProblem) -> None:
        self.problem = problem
        self.modes = AssemblyModes(problem.domain, problem_bodies(problem),
                                   [(p.facets, p.at(1.0)) for p in problem.solid.prescribed])
        domain, V = problem.domain, problem.V
        nodes = domain.geometry.dofmaps[0]
        block = np.full(domain.geometry.x.shape[0], -1, dtype=np.int64)
        block[nodes[:, : V.dofmap.list.shape[1]].reshape(-1)] = V.dofmap.list.reshape(-1)
        #: the displacement block of each geometry node (-1: none)
        self.block = block
        self.mapped = block >= 0
        self._sizes: list[int] = []  # each contact's owned nodes, as the last measures had them

    def in_state(self, gap_tol: float) -> list[tuple[str, str]]:
        """A rigid motion that the conditions and the contacts closed in this state leave free.

        (body name, its part of the motion) per moving body; [] when held,
        at once and without touching u when the supports alone hold every
        body. Closed: active, or with a gap at most ``gap_tol`` h (the
        contact's own h); closed nodes hold both ways, sticking nodes their
        slip too. Collective.
        """
        gdim = self.problem.gdim
        state = self.problem.u.x.array.reshape(-1, gdim)
        displacement = np.zeros((self.block.size, gdim))
        displacement[self.mapped] = state[self.block[self.mapped]]
        x = self.problem.domain.geometry.x[:, :gdim] + displacement
        if self.modes.free_modes(x)[0].shape[1] == 0:
            return []  # the supports alone hold every body: u is neither set nor saved

        def holding(base: np.ndarray) -> np.ndarray:
            self._set(displacement)
            return self._closed(base, gap_tol)

        u = self.problem.u
        saved = u.x.array.copy()
        try:
            return self.modes.free_motion(self._measures, displacement, holding)
        finally:
            changed = not np.array_equal(u.x.array, saved)
            if self.problem.comm.allreduce(changed, op=MPI.LOR):  # the searches are collective
                u.x.array[:] = saved
                self.problem.refresh_search()

    def _set(self, displacement: np.ndarray) -> None:
        """Set u at the geometry nodes' dofs to ``displacement`` (nodes, gdim)."""
        u = self.problem.u.x.array.reshape(-1, self.problem.gdim)
        u[self.block[self.mapped]] = displacement[self.mapped]

    def _measures(self, displacement: np.ndarray) -> np.ndarray:
        """The joined owned nodal gaps, and slips of frictional contacts, for a displacement."""
        self._set(displacement)
        out = []
        self._sizes = []
        for c in self.problem.contacts:
            out.append(c.nodal_gap())
            self._sizes.append(out[-1].size)
            if c.friction is not None:
                out.append(c.friction.nodal_slip().ravel())
        return np.concatenate(out)

    def _closed(self, base: np.ndarray, gap_tol: float) -> np.ndarray:
        """Which of the measures ``base`` (of :meth:`_measures`, in this state) hold: a mask.

        A gap holds where its node is active (pressure < 0) or touching (at
        most ``gap_tol`` h); a slip where its node sticks.
        """
        out = []
        at = 0
        for c, n in zip(self.problem.contacts, self._sizes, strict=True):  # n: owned nodes
            active = c.nodal_pressure(c.lam.x.array[:n].copy()) < 0.0
            out.append(active | (base[at: at + n] <= gap_tol * float(c.surface.h)))
            at += n
            if c.friction is not None:
                stick = active & (c.friction.node_states() == STICK)
                out.append(np.repeat(stick, self.problem.gdim - 1))
                at += n * (self.problem.gdim - 1)
        return np.concatenate(out) if out else np.zeros(0, dtype=bool)


__all__ = ["ContactHold", "problem_bodies"]
