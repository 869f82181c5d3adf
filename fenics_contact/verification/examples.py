"""The paper's examples (and the wedge analog) that the ``study`` command knows.

The paper's Figures 1 and 2 are not available. Example 1's geometry is
reconstructed from the paper's own numbers (:class:`StrikerOnFacet`, see
``benchmarks/paper_ex1_geometry.py`` and ``docs/paper_ex1.md``); the earlier
rigid-wedge analog stays as :class:`WedgeOnCorner`. Example 2 is an analog
whose geometry is chosen here and documented in its docstring.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from dolfinx import fem, mesh

from mpi4py import MPI

from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.materials import SaintVenantKirchhoff
from fenics_contact.model.obstacles import RigidPlane
from fenics_contact.model.problem import (
    ContactProblem,
    PrescribedDisplacement,
    one_body_problem,
)
from fenics_contact.verification.bar import BarOnCradle
from fenics_contact.verification.paper import PAPER_E, PAPER_NU, PAPER_TABLE_1
from fenics_contact.verification.striker import StrikerOnFacetProblem
from fenics_contact.verification.two_body_examples import BlockOnBlock, TwoCylinders


def _one_free_corner(domain: mesh.Mesh) -> list[PrescribedDisplacement]:
    """Unit square clamped on its left and bottom faces, right face vertical only.

    Leaves one free unknown: the vertical displacement of the corner (1, 1).
    """
    fdim = domain.topology.dim - 1

    def side(axis: int, value: float) -> np.ndarray:
        return mesh.locate_entities_boundary(domain, fdim, lambda x: np.isclose(x[axis], value))

    return [
        PrescribedDisplacement(side(0, 0.0), (0.0, 0.0)),
        PrescribedDisplacement(side(1, 0.0), (0.0, 0.0)),
        PrescribedDisplacement(side(0, 1.0), (0.0, None)),
    ]


def _corner_displacement(V: fem.FunctionSpace, u: fem.Function) -> float:
    """Vertical displacement of the corner (1, 1), gathered from the rank that owns it."""
    coords = V.tabulate_dof_coordinates()
    corner = np.flatnonzero(np.isclose(coords[:, 0], 1.0) & np.isclose(coords[:, 1], 1.0))
    values = u.x.array.reshape(-1, 2)[corner, 1]
    found = V.mesh.comm.allgather(values.tolist())
    return float(next(v for vs in found for v in vs))


def _corner_dofs(V: fem.FunctionSpace, value: float) -> np.ndarray:
    """Dof values of a displacement that moves only the corner (1, 1), vertically by value."""
    coords = V.tabulate_dof_coordinates()
    exact = np.zeros((coords.shape[0], 2))
    exact[np.isclose(coords[:, 0], 1.0) & np.isclose(coords[:, 1], 1.0), 1] = value
    return exact.ravel()


class _OneElement:
    """What the one-element examples share: the unit square, its corner, the study's probe.

    A subclass defines ``exact_u``, the exact vertical displacement of the corner (1, 1).
    """

    exact_u: float

    #: Paper's Table 1, for the study's side-by-side print.
    published_table = PAPER_TABLE_1

    @staticmethod
    def _unit_square(comm: MPI.Comm) -> tuple[mesh.Mesh, np.ndarray]:
        """One quadrilateral [0, 1]^2 and its top facet (local indices)."""
        domain = mesh.create_unit_square(comm, 1, 1, mesh.CellType.quadrilateral)
        top = mesh.locate_entities_boundary(domain, 1, lambda x: np.isclose(x[1], 1.0))
        return domain, top

    def corner_displacement(self, problem: ContactProblem | StrikerOnFacetProblem) -> float:
        """Vertical displacement of the corner (1, 1) (the single unknown)."""
        return _corner_displacement(problem.V, problem.u)

    def probe(self, problem: ContactProblem | StrikerOnFacetProblem) -> float:
        """What a study reports per run: the corner displacement u."""
        return self.corner_displacement(problem)

    def exact_dofs(self, problem: ContactProblem | StrikerOnFacetProblem) -> np.ndarray:
        """Dof values of the exact displacement: only the corner moves."""
        return _corner_dofs(problem.V, self.exact_u)


@dataclass(frozen=True)
class StrikerOnFacet(_OneElement):
    """The paper's Example 1: a striker node pushes the top facet of one SVK quadrilateral.

    Reconstructed geometry (the paper's Figure 1 is not available; see
    ``benchmarks/paper_ex1_geometry.py``): the unit square [0, 1]^2 in plane
    strain, clamped on its left and bottom faces, its right face free to
    move vertically only, so the one unknown is the vertical displacement
    u of the corner b = (1, 1). The target facet is the top face a -> b,
    a = (0, 1) fixed. The striker node starts on the facet at its midpoint
    (0.5, 1) and moves straight down by h = -0.25. The node-to-segment gap is

        g(u) = (h - u/2) / sqrt(1 + u^2),

    nonlinear in u through the rotation of the facet about a. The striker
    stops the facet's midpoint at 1 + h, so the corner stops at

        u = 2 h = -0.5,

    from geometry alone, as the paper says. With the strain energy
    integrated by 2 x 2 Gauss points, the penalty method gives u = -0.098750
    at r = 100 and -0.38727 at r = 1000: the paper's -0.0988 and -0.387 to
    every printed digit. Units: E = 210 (stress), lengths as given; r is a
    point stiffness (force per length, per unit thickness), absolute as in
    the paper.
    """

    h: float = -0.25
    striker_at: float = 0.5
    steps: int = 1
    energy_quadrature_degree: int = 2

    @property
    def exact_u(self) -> float:
        """The exact corner displacement h / striker_at (2 h at the midpoint)."""
        return self.h / self.striker_at

    def build(
        self,
        settings: ContactSettings,
        comm: MPI.Comm = MPI.COMM_WORLD,
    ) -> StrikerOnFacetProblem:
        """Create the one-element mesh and the node-to-segment problem."""
        domain, top = self._unit_square(comm)
        return StrikerOnFacetProblem(
            domain,
            SaintVenantKirchhoff(E=PAPER_E, nu=PAPER_NU),
            top,
            striker_start=(self.striker_at, 1.0),
            striker_motion=(0.0, self.h),
            settings=settings,
            prescribed=_one_free_corner(domain),
            energy_quadrature_degree=self.energy_quadrature_degree,
        )

@dataclass(frozen=True)
class WedgeOnCorner(_OneElement):
    """The former Example 1 analog (``paper-ex1-wedge``): a rigid wedge instead of a striker.

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
        domain, top = self._unit_square(comm)
        wedge = RigidPlane(domain, [1.0, 1.0], [-self.slope, -1.0])
        return one_body_problem(
            domain,
            SaintVenantKirchhoff(E=PAPER_E, nu=PAPER_NU),
            wedge,
            top,
            settings,
            prescribed=_one_free_corner(domain),
            obstacle_motion=[self.h, 0.0],
        )

#: Examples the ``study`` command knows, by name.
EXAMPLES: dict[str, type] = {
    "paper-ex1": StrikerOnFacet,
    "paper-ex1-wedge": WedgeOnCorner,
    "paper-ex2": BarOnCradle,
    "two-cylinders": TwoCylinders,
    "block-on-block": BlockOnBlock,
}
