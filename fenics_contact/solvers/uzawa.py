"""What the two Uzawa strategies share: the primal kernel and the residual measure.

Both hold lam fixed during Newton steps in u on the augmented Lagrangian and
update it by lam <- min(lam + r g, 0) (paper eq. 10). Their residual is the
same as GNRM's: the norm of (equilibrium with the current lam,
complementarity lam - min(lam + r g, 0)).
"""

from __future__ import annotations

import math
from typing import Any

from dolfinx import fem

from mpi4py import MPI

from fenics_contact.model.contact import assemble_local
from fenics_contact.model.problem import ContactProblem, VariationalSystem
from fenics_contact.solvers.base import NewtonStrategy
from fenics_contact.solvers.diagnostics import SolverSettings


class UzawaBase(NewtonStrategy):
    """Primal Newton kernel plus the complementarity residual."""

    name = "uzawa"

    def __init__(self, problem: ContactProblem, settings: SolverSettings, **options: Any) -> None:
        super().__init__(problem, settings, **options)
        residual = problem.complementarity_residual()
        # a frictional problem gives the normal and the tangential residual
        self._complementarity = [
            fem.form(form, entity_maps=problem.entity_maps)
            for form in (residual if isinstance(residual, list) else [residual])
        ]
        self.primal_norm = math.inf
        self.complementarity_norm = math.inf

    def build_system(self, problem: ContactProblem) -> VariationalSystem:
        """Equilibrium in u with lam held fixed."""
        return problem.primal_system()

    def residual_norm(self) -> float:
        """Assemble both residuals; return the norm of the pair."""
        self.primal_norm = self.kernel.assemble_residual()
        squares = 0.0
        for form in self._complementarity:
            local = assemble_local(form)
            squares += float(local @ local)
        comm = self.problem.comm
        self.complementarity_norm = math.sqrt(comm.allreduce(squares, op=MPI.SUM))
        return math.hypot(self.primal_norm, self.complementarity_norm)
