"""What the two Uzawa strategies share: the primal kernel and the residual measure.

Both hold lam fixed during Newton steps in u on the augmented Lagrangian and
update it by lam <- min(lam + r g, 0) (paper eq. 10). Their residual is the
same as GNRM's: the norm of (equilibrium with the current lam,
complementarity lam - min(lam + r g, 0)).
"""

from __future__ import annotations

import math
from collections.abc import Callable

from dolfinx import fem

from mpi4py import MPI

from fenics_contact.model.contact import assemble_local
from fenics_contact.model.problem import ContactProblem
from fenics_contact.solvers.condensed import kernel_for
from fenics_contact.solvers.diagnostics import SolverSettings


class UzawaBase:
    """Primal Newton kernel plus the complementarity residual."""

    name = "uzawa"
    #: Optional progress callback (iterations, residual), see ConvergenceMonitor.
    observer: Callable[[int, float], None] | None = None

    def __init__(self, problem: ContactProblem, settings: SolverSettings) -> None:
        self.problem = problem
        self.settings = settings
        self.kernel = kernel_for(problem.primal_system())
        self._complementarity = fem.form(
            problem.complementarity_residual(), entity_maps=problem.surface.entity_maps
        )
        self.primal_norm = math.inf
        self.complementarity_norm = math.inf

    def residual_norm(self) -> float:
        """Assemble both residuals; return the norm of the pair."""
        self.primal_norm = self.kernel.assemble_residual()
        local = assemble_local(self._complementarity)
        comm = self.problem.comm
        self.complementarity_norm = math.sqrt(comm.allreduce(float(local @ local), op=MPI.SUM))
        return math.hypot(self.primal_norm, self.complementarity_norm)
