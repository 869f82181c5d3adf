"""GNRM: generalized Newton on displacement and multiplier together.

The Jacobian of the Alart-Curnier system is the UFL derivative of
``min_value``: the generalized Jacobian of the paper (Alart and Curnier).
The residual measure is the norm of (equilibrium, complementarity).

With friction, a solve whose stick/slip pattern cycles (or that reaches the
iteration limit) is restarted from its starting state with the tangential
parameter r_t halved, up to :attr:`GeneralizedNewton.tangential_halvings`
times (:func:`~fenics_contact.solvers.base.retry_lowering_r_t`); the
converged nodal answer does not depend on r_t.
"""

from __future__ import annotations

from fenics_contact.model.problem import ContactProblem, VariationalSystem
from fenics_contact.solvers.base import NewtonStrategy, SolveResult, retry_lowering_r_t
from fenics_contact.solvers.diagnostics import Status


class GeneralizedNewton(NewtonStrategy):
    """Newton on (u, lam) of the augmented Lagrangian (paper's GNRM)."""

    name = "gnrm"
    #: Halvings of r_t tried when a frictional solve cycles.
    tangential_halvings = 2

    def build_system(self, problem: ContactProblem) -> VariationalSystem:
        """The coupled Alart-Curnier system."""
        return problem.augmented_system()

    def _solve(self) -> SolveResult:
        if not self.problem.frictional:  # frictionless: plain Newton
            return super()._solve()
        saved = self.problem.snapshot()
        results = [super()._solve()]

        def again() -> Status:
            results.append(super(GeneralizedNewton, self)._solve())
            return results[-1].status

        switches: list[str] = []
        status = retry_lowering_r_t(
            self.problem, saved, results[0].status, again, self.tangential_halvings,
            switches, "gnrm",
        )
        return SolveResult(
            status, sum(r.iterations for r in results), 0,
            sum(r.linear_solves for r in results),
            [v for r in results for v in r.residuals], switches=switches,
        )
