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
        self._set_multipliers(lam1 + s * (lam1 - lam0))
        return True

    def solve(self) -> SolveResult:
        """Predict, then let the wrapped strategy solve at the current load."""
        self.predict()
        result = self.inner.solve()
        if result.converged:
            self._record()
        return result
