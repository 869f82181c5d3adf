"""The paper's examples (analogs) that the ``study`` command knows.

The paper's Figures 1 and 2 are not available; the geometry of each analog
is chosen here and documented in its docstring.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from dolfinx import mesh

from mpi4py import MPI

from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.materials import SaintVenantKirchhoff
from fenics_contact.model.obstacles import RigidPlane
from fenics_contact.model.problem import ContactProblem, PrescribedDisplacement
from fenics_contact.verification.bar import PAPER_E, PAPER_NU, BarOnCradle


@dataclass(frozen=True)
class WedgeOnCorner:
    """Example 1 analog: one element, one degree of freedom, one contact node.

    A unit plane-strain quadrilateral [0, 1]^2 is clamped on its left and
    bottom faces; its right face can only move vertically, so the only free
    unknown is the vertical displacement ``u`` of the top-right corner. A
    rigid wedge face of slope 2, initially through that corner (normal
    -(2, 1)/sqrt(5), the body on the side it points to), slides horizontally
    by the striker motion ``h`` = -0.25. With the wedge face through
    (1 + h, 1), the corner (1, 1 + u) is clear when -(2 h + u)/sqrt(5) >= 0,
    i.e. u <= 2 h. The element resists compression, so the corner stops on
    the wedge and the answer follows from geometry alone:

        u = 2 h = -0.5,

    the paper's value. The top-left corner stays clear (its gap grows from
    2/sqrt(5)). The candidate contact facet is the top face (two multiplier
    nodes).
    """

    h: float = -0.25
    slope: float = 2.0
    steps: int = 1

    @property
    def exact_u(self) -> float:
        """The exact corner displacement, slope * h."""
        return self.slope * self.h

    def build(
        self,
        settings: ContactSettings,
        comm: MPI.Comm = MPI.COMM_WORLD,
    ) -> ContactProblem:
        """Create the one-element mesh and the contact problem."""
        domain = mesh.create_unit_square(comm, 1, 1, mesh.CellType.quadrilateral)
        fdim = domain.topology.dim - 1

        def side(axis: int, value: float) -> np.ndarray:
            return mesh.locate_entities_boundary(
                domain, fdim, lambda x: np.isclose(x[axis], value)
            )

        wedge = RigidPlane(domain, [1.0, 1.0], [-self.slope, -1.0])
        return ContactProblem(
            domain,
            SaintVenantKirchhoff(E=PAPER_E, nu=PAPER_NU),
            wedge,
            side(1, 1.0),
            settings,
            prescribed=[
                PrescribedDisplacement(side(0, 0.0), (0.0, 0.0)),
                PrescribedDisplacement(side(1, 0.0), (0.0, 0.0)),
                PrescribedDisplacement(side(0, 1.0), (0.0, None)),
            ],
            obstacle_motion=[self.h, 0.0],
        )

    def corner_displacement(self, problem: ContactProblem) -> float:
        """Vertical displacement of the top-right corner (the single unknown)."""
        coords = problem.V.tabulate_dof_coordinates()
        corner = np.flatnonzero(np.isclose(coords[:, 0], 1.0) & np.isclose(coords[:, 1], 1.0))
        values = problem.u.x.array.reshape(-1, 2)[corner, 1]
        found = problem.comm.allgather(values.tolist())
        return float(next(v for vs in found for v in vs))

    def exact_dofs(self, problem: ContactProblem) -> np.ndarray:
        """Dof values of the exact displacement: only the corner moves."""
        coords = problem.V.tabulate_dof_coordinates()
        exact = np.zeros((coords.shape[0], 2))
        corner = np.isclose(coords[:, 0], 1.0) & np.isclose(coords[:, 1], 1.0)
        exact[corner, 1] = self.exact_u
        return exact.ravel()


#: Examples the ``study`` command knows, by name.
EXAMPLES: dict[str, type] = {
    "paper-ex1": WedgeOnCorner,
    "paper-ex2": BarOnCradle,
}
