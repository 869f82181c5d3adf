"""PM: Newton on the penalised potential (paper eq. 7), displacement only.

The constraint is met only as r grows: the penetration scales like
pressure / r.
"""

from __future__ import annotations

from fenics_contact.model.problem import ContactProblem, VariationalSystem
from fenics_contact.solvers.base import NewtonStrategy


class Penalty(NewtonStrategy):
    """Newton on Pi + r/2 int min(g, 0)^2; the multiplier stays zero."""

    name = "penalty"
    exact_constraint = False

    def build_system(self, problem: ContactProblem) -> VariationalSystem:
        """The penalised equilibrium; zeroing lam makes diagnostics report r min(g, 0)."""
        for lam in problem.normal_multipliers():
            lam.x.array[:] = 0.0
        problem.multiplier_is_pressure = False
        return problem.penalty_system()
