"""SUA: simultaneous Uzawa, a multiplier update after every Newton iteration."""

from __future__ import annotations

from fenics_contact.solvers.base import SolveResult, newton_loop, timed
from fenics_contact.solvers.diagnostics import ConvergenceMonitor, signorini_admissibility
from fenics_contact.solvers.uzawa import UzawaBase


class SimultaneousUzawa(UzawaBase):
    """Newton in u with lam fixed; lam <- min(lam + r g, 0) after each iteration."""

    name = "sua"

    def solve(self) -> SolveResult:
        """Iterate until the coupled residual passes the stopping test."""
        return timed(self._solve)

    def _solve(self) -> SolveResult:
        monitor = ConvergenceMonitor(
            self.settings, observer=self.observer,
            admissible=signorini_admissibility(self.problem, self.settings),
        )
        before = self.kernel.linear_solves
        status, steps = newton_loop(
            self.kernel,
            monitor,
            self.residual_norm,
            self.problem.active_signature,
            after_step=self.problem.update_multiplier,
        )
        return SolveResult(
            status, steps, steps, self.kernel.linear_solves - before, monitor.residuals
        )
