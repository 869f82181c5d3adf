"""NUA: nested Uzawa, inner Newton in u to a loose tolerance, then one update.

The paper's setting: inner tolerance 1e-3 on the equilibrium residual, outer
1e-8. Each inner solve takes at least one Newton step after an update (an
update on an unchanged displacement would reuse a stale gap), and once the
complementarity residual is below the outer tolerance the last inner solve
runs to the outer tolerance.
"""

from __future__ import annotations

from dataclasses import dataclass

from fenics_contact.solvers.base import SolveResult, timed
from fenics_contact.solvers.diagnostics import Status
from fenics_contact.solvers.uzawa import UzawaBase


@dataclass(frozen=True)
class NestedSettings:
    """Inner-loop tolerance (absolute, on the equilibrium residual)."""

    inner_atol: float = 1e-3


class NestedUzawa(UzawaBase):
    """Uzawa with an inner Newton solve between multiplier updates."""

    name = "nua"
    tuning_type = NestedSettings
    tuning: NestedSettings

    def solve(self) -> SolveResult:
        """Outer updates until the coupled residual passes the stopping test."""
        return timed(self._solve)

    def _solve(self) -> SolveResult:
        monitor = self.monitor()
        before = self.kernel.linear_solves
        steps = updates = 0
        fresh = True  # a Newton step was taken since the last update
        status: Status | None = None
        self.kernel.begin_solve()
        while status is None:
            norm = self.residual_norm()
            status = monitor.check(norm, self.problem.active_signature(), iterations=steps)
            if status is not None:
                break
            dual_done = self.complementarity_norm <= monitor.tolerance()
            inner_tol = monitor.tolerance() if dual_done else self.tuning.inner_atol
            if self.primal_norm > inner_tol or not fresh:
                if not self.kernel.newton_step(tolerance=inner_tol):
                    status = monitor.fail()
                steps += 1
                fresh = True
            else:
                self.problem.update_multiplier()
                updates += 1
                fresh = False
        return SolveResult(
            status, steps, updates, self.kernel.linear_solves - before, monitor.residuals
        )
