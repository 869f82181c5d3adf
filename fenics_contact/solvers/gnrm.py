"""GNRM: generalized Newton on displacement and multiplier together.

The Jacobian of the Alart-Curnier system is the UFL derivative of
``min_value``: the generalized Jacobian of the paper (Alart and Curnier).
The residual measure is the norm of (equilibrium, complementarity).
"""

from __future__ import annotations

from fenics_contact.model.problem import ContactProblem, VariationalSystem
from fenics_contact.solvers.base import NewtonStrategy


class GeneralizedNewton(NewtonStrategy):
    """Newton on (u, lam) of the augmented Lagrangian (paper's GNRM)."""

    name = "gnrm"

    def build_system(self, problem: ContactProblem) -> VariationalSystem:
        """The coupled Alart-Curnier system."""
        return problem.augmented_system()
