"""A load-step predictor: extrapolate the last converged increment.

Newton starts each load step from a guess. The plain choice is the last
converged state (the default of every strategy). :class:`Extrapolated`
wraps any strategy and starts it instead from the linear extrapolation of
the last two converged states in the load factor,

    x_pred = x_n + (t - t_n) / (t_n - t_{n-1}) (x_n - x_{n-1}),

for the displacement and the multiplier alike. In contact this predicts
where the contact zone grows (nodes whose extrapolated gap closes enter
the active set at the first iteration) and the multiplier of nodes already
closed. It is only a starting guess: the converged answer is the same.

:class:`ActiveSetPredicted` starts from the same extrapolation and also
chooses the contact set of the first Newton iteration (nodal-rule,
frictionless contacts): a node open in the last two states closes when the
extrapolated state closes it and the linear extrapolation of ``g**(2/3)``
reaches zero as well (near the edge of a smooth
contact the gap grows as the distance to the edge to the power 3/2, so
``g**(2/3)`` moves linearly with the edge, while the gap itself closes
tangentially and its linear extrapolation closes nodes too early); a node in
contact stays in contact unless its extrapolated multiplier turns tensile (a
pressure that round-off leaves on an open node, below 1e-9 of the largest,
does not make it a node in contact).
At the first step, from rest, the nodes that touch (g = 0) start in
contact instead of none. The choice is imposed through the multiplier
(lam + r g just below zero for a node set in contact, at or above zero for a
node set open), so it holds for every r; it is again only a starting guess.
The penalty method, whose multiplier is not an unknown and stays zero, gets
the extrapolated displacement only.
"""

from __future__ import annotations

import numpy as np

from mpi4py import MPI

from fenics_contact.model.problem import ContactProblem
from fenics_contact.solvers.base import SolveResult, Strategy
from fenics_contact.solvers.diagnostics import SolverSettings


class Extrapolated:
    """Any strategy, started from the extrapolation of its last two converged states.

    The state the problem holds when the wrapper is created counts as the
    first converged state (at the problem's load factor): a load path starts
    from equilibrium. When the problem's fields are changed behind the
    wrapper's back (they no longer equal the last converged state), the
    history is dropped and the next solve starts from the fields as they are.
    After a cut-back the stepping restores the last converged state, so the
    extrapolation simply uses the shorter increment.

    Args:
        strategy: the strategy that does the solving (e.g. GNRM).
    """

    def __init__(self, strategy: Strategy) -> None:
        self.inner = strategy
        self.name = strategy.name
        self.problem: ContactProblem = strategy.problem
        self.settings: SolverSettings = strategy.settings
        self._history: list[tuple[float, np.ndarray, np.ndarray]] = []
        self._record()

    @property
    def kernel(self):
        """The wrapped strategy's Newton kernel."""
        return self.inner.kernel  # type: ignore[attr-defined]

    def _state(self) -> tuple[np.ndarray, np.ndarray]:
        """The u array itself and every contact's lam joined (a copy for several)."""
        multipliers = self.problem.normal_multipliers()
        if len(multipliers) == 1:
            return self.problem.u.x.array, multipliers[0].x.array
        return self.problem.u.x.array, np.concatenate([m.x.array for m in multipliers])

    def _set_multipliers(self, values: np.ndarray) -> None:
        start = 0
        for m in self.problem.normal_multipliers():
            m.x.array[:] = values[start:start + m.x.array.size]
            start += m.x.array.size

    def _record(self) -> None:
        u, lam = self._state()
        self._history = [*self._history[-1:], (self.problem.load_factor, u.copy(), lam.copy())]

    @property
    def history(self) -> list[tuple[float, np.ndarray, np.ndarray]]:
        """The converged states (load factor, u array, lam array) it extrapolates from.

        Oldest first, at most two; local arrays with ghosts. Setting it (a
        resumed run) replaces the history with copies of the given states.
        """
        return list(self._history)

    @history.setter
    def history(self, states: list[tuple[float, np.ndarray, np.ndarray]]) -> None:
        self._history = [(float(t), u.copy(), lam.copy()) for t, u, lam in states[-2:]]

    def _at_last_converged(self) -> bool:
        if not self._history:
            return False
        _, u_n, lam_n = self._history[-1]
        u, lam = self._state()
        return bool(np.array_equal(u, u_n) and np.array_equal(lam, lam_n))

    def predict(self) -> bool:
        """Overwrite the fields with the extrapolated guess; False when there is none.

        A guess that turns an element inside out (det F <= 0 somewhere) is not
        used: the solve starts from the last converged state.

        Collective: every rank predicts, or none does.
        """
        comm = self.problem.comm
        if not comm.allreduce(int(self._at_last_converged()), op=MPI.MIN):
            self._history = []
            return False
        if len(self._history) < 2 or self._history[0][0] == self._history[1][0]:
            return False
        (t0, u0, lam0), (t1, u1, lam1) = self._history
        s = (self.problem.load_factor - t1) / (t1 - t0)
        u, _ = self._state()
        u[:] = u1 + s * (u1 - u0)
        if self.problem.multiplier_is_pressure:  # the penalty method's lam stays zero
            self._set_multipliers(lam1 + s * (lam1 - lam0))
        if self.problem.min_det_F().value <= 0.0:
            # the extrapolation turns an element inside out (a fold closing): start from
            # the last converged state instead, whose elements are all admissible
            u[:] = u1
            self._set_multipliers(lam1)
            return False
        return True

    def solve(self) -> SolveResult:
        """Predict, then let the wrapped strategy solve at the current load."""
        self.predict()
        result = self.inner.solve()
        if result.converged:
            self._record()
        return result


class ActiveSetPredicted(Extrapolated):
    """:class:`Extrapolated`, and the first iteration's contact set chosen by the gaps' history.

    See the module's description. Contacts with friction, or with a
    quadrature other than the vertex rule, are only extrapolated. A history
    set from outside (a resumed run) has no gaps unless :attr:`gap_history`
    is set too: without them the first step after it decides the set by the
    sign of the extrapolated lam + r g, as :class:`Extrapolated` does.

    Args:
        strategy: the strategy that does the solving (e.g. GNRM).
    """

    #: Exponent of the gap near a contact edge against the distance to the edge (Hertz).
    edge_exponent = 1.5
    #: The margin of the imposed augmented pressure, relative to the largest |lam|.
    margin = 1e-9

    def __init__(self, strategy: Strategy) -> None:
        self._gaps: list[list[np.ndarray]] = []
        super().__init__(strategy)

    def _chosen(self) -> list:
        """The contacts whose set the predictor chooses (none under the penalty method).

        The choice is imposed through lam, which the penalty method does not
        solve for: its lam must stay zero, or lam + r g, the pressure it
        reports, would be shifted by the imposed value.
        """
        if not self.problem.multiplier_is_pressure:
            return []
        return [c for c in self.problem.contacts
                if c.friction is None and c.settings.quadrature == "nodal"]

    def _nodal_gaps(self) -> list[np.ndarray]:
        out = []
        for c in self._chosen():
            c.refresh()
            out.append(c.surface.nodal(c._gap_form))
        return out

    def _record(self) -> None:
        super()._record()
        self._gaps = [*self._gaps[-1:], self._nodal_gaps()]

    @Extrapolated.history.setter  # type: ignore[attr-defined]
    def history(self, states: list[tuple[float, np.ndarray, np.ndarray]]) -> None:
        """The converged states, as :attr:`Extrapolated.history`; the gaps' history is dropped."""
        Extrapolated.history.fset(self, states)  # type: ignore[attr-defined]
        self._gaps = []

    @property
    def gap_history(self) -> list[np.ndarray]:
        """The nodal gaps of the converged states (length), oldest first, one per state.

        Each is joined over the contacts in the layout of their owned
        multiplier values (NaN on a contact whose set is not chosen here).
        Set it after :attr:`history` (a resumed run) to continue exactly as
        the uninterrupted run; arrays of another length are ignored.
        """
        chosen = {id(c): k for k, c in enumerate(self._chosen())}
        out = []
        for gaps in self._gaps:
            parts = []
            for c in self.problem.contacts:
                n = c.lam.x.index_map.size_local
                k = chosen.get(id(c))
                parts.append(gaps[k] if k is not None else np.full(n, np.nan))
            out.append(np.concatenate(parts) if parts else np.zeros(0))
        return out

    @gap_history.setter
    def gap_history(self, joined: list[np.ndarray]) -> None:
        chosen = {id(c) for c in self._chosen()}
        sizes = [c.lam.x.index_map.size_local for c in self.problem.contacts]
        gaps = []
        for array in joined[-2:]:
            if array.size != sum(sizes):
                return
            parts, start = [], 0
            for c, n in zip(self.problem.contacts, sizes, strict=True):
                if id(c) in chosen:
                    parts.append(np.array(array[start:start + n]))
                start += n
            gaps.append(parts)
        if len(gaps) == len(self._history):
            self._gaps = gaps

    def _offsets(self) -> dict[int, int]:
        """Where each contact's lam starts in the joined multiplier array."""
        out, start = {}, 0
        for c in self.problem.contacts:
            out[id(c)] = start
            start += c.lam.x.array.size
        return out

    def predict(self) -> bool:
        """Extrapolate, then impose the predicted contact set; False when nothing was predicted."""
        if not super().predict():
            if self._history and not self._gaps[:-1] and self._history[-1][0] == 0.0:
                self._touching()  # the first step from rest
            return False
        (t0, _, lam0), (t1, _, lam1) = self._history
        s = (self.problem.load_factor - t1) / (t1 - t0)
        gaps = self._gaps if len(self._gaps) == 2 else None
        offsets = self._offsets()
        p = 1.0 / self.edge_exponent
        comm = self.problem.comm
        # the set is imposed for the r the solve works at (auto rescales a huge user r):
        # lam = -r g at the user's r = 1e16 E/h is r g's round-off, not a pressure
        at_work = self.inner.working_r() / self.problem.r_absolute
        for k, (c, g_pred) in enumerate(zip(self._chosen(), self._nodal_gaps(), strict=True)):
            n = g_pred.size
            start = offsets[id(c)]
            before, last = lam0[start:start + n], lam1[start:start + n]
            lam = c.lam.x.array[:n]
            closing = g_pred < 0.0
            if gaps is not None:
                g0, g1 = gaps[0][k], gaps[1][k]
                both = (g0 > 0.0) & (g1 > 0.0)
                h0, h1 = np.abs(g0) ** p, np.abs(g1) ** p
                # the edge rule only delays a closure the extrapolated state predicts: a gap
                # that jumped (a node that found its facet, or lost a lift) proves nothing
                closing = np.where(both, closing & (h1 + s * (h1 - h0) <= 0.0), closing)
            scale = comm.allreduce(float(np.max(np.abs(np.concatenate([last, before])),
                                                initial=0.0)), op=MPI.MAX)
            floor = self.margin * scale  # a pressure below this is round-off (an open node)
            was_active = last < -floor
            active = np.where(was_active, lam < 0.0, closing)
            r = float(c.r.value) * at_work
            tiny = self.margin * max(scale, 1e-6 * r * c.surface.h)
            augmented = lam + r * g_pred
            to_close = active & (augmented >= -tiny)
            to_open = ~active & (augmented < tiny)
            lam[to_close] = -r * g_pred[to_close] - tiny
            lam[to_open] = -r * g_pred[to_open] + tiny
            c.lam.x.scatter_forward()
        return True

    #: A contact's smallest gap at rest below this fraction of h counts as touching.
    touching_gap = 1e-2

    def _touching(self) -> None:
        """The nodes that touch at rest start in contact (lam = 0 there).

        Touching: the contact's smallest nodal gap, where it is below
        ``touching_gap`` h (g = 0 at a node-to-segment or obstacle node that
        touches; a mortar pair's weighted gap is the gap's mean over the
        node's support, 1e-3 h at the touching node of two cylinders), and
        every node within 1e-12 h of it.
        """
        comm = self.problem.comm
        at_work = self.inner.working_r() / self.problem.r_absolute
        for c, g in zip(self._chosen(), self._nodal_gaps(), strict=True):
            lam = c.lam.x.array[:g.size]
            smallest = comm.allreduce(float(np.min(g, initial=np.inf)), op=MPI.MIN)
            level = max(smallest, 0.0) if smallest <= self.touching_gap * c.surface.h else 0.0
            touch = (g <= level + 1e-12 * c.surface.h) & (lam >= 0.0)
            r = float(c.r.value) * at_work
            lam[touch] = -r * g[touch] - self.margin * 1e-6 * r * c.surface.h
            c.lam.x.scatter_forward()
