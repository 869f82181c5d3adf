"""The paper's Example 1 (a prescribed striker node on one element) and its corner probe.

The one problem of the project that no scene states: a striker node moved
along a prescribed path onto the top facet of one SVK quadrilateral
(:class:`StrikerOnFacet`, built on :mod:`benchmarks.research.striker`).
Its rigid-wedge analog is a scene (:func:`benchmarks.cases.wedge_on_corner`).
Both have one free unknown, the vertical displacement u of the corner
(1, 1), read by :func:`corner_displacement`; their exact answer is u = 2 h.
"""

from __future__ import annotations

from dataclasses import dataclass

import fenics_contact  # noqa: F401  (the DOLFINx wheel before dolfinx)

# isort: split
import numpy as np
from dolfinx import fem, mesh

from mpi4py import MPI

from benchmarks.cases import PAPER_E, PAPER_NU
from benchmarks.research.striker import StrikerOnFacetProblem
from fenics_contact import ContactSettings, PrescribedDisplacement
from fenics_contact.model.materials import SaintVenantKirchhoff


def corner_displacement(problem) -> float:
    """Vertical displacement of the corner (1, 1), gathered from the rank that owns it."""
    V, u = problem.V, problem.u
    coords = V.tabulate_dof_coordinates()
    corner = np.flatnonzero(np.isclose(coords[:, 0], 1.0) & np.isclose(coords[:, 1], 1.0))
    values = u.x.array.reshape(-1, 2)[corner, 1]
    found = V.mesh.comm.allgather(values.tolist())
    return float(next(v for vs in found for v in vs))


def corner_dofs(V: fem.FunctionSpace, value: float) -> np.ndarray:
    """Dof values of a displacement that moves only the corner (1, 1), vertically by value."""
    coords = V.tabulate_dof_coordinates()
    exact = np.zeros((coords.shape[0], 2))
    exact[np.isclose(coords[:, 0], 1.0) & np.isclose(coords[:, 1], 1.0), 1] = value
    return exact.ravel()


def exact_corner(value: float):
    """The exact dofs (only the corner moves, by ``value``) as a function of a problem."""
    return lambda problem: corner_dofs(problem.V, value)


def _one_free_corner(domain: mesh.Mesh) -> list[PrescribedDisplacement]:
    """Unit square clamped on its left and bottom faces, right face vertical only."""
    fdim = domain.topology.dim - 1

    def side(axis: int, value: float) -> np.ndarray:
        return mesh.locate_entities_boundary(domain, fdim, lambda x: np.isclose(x[axis], value))

    return [
        PrescribedDisplacement(side(0, 0.0), (0.0, 0.0)),
        PrescribedDisplacement(side(1, 0.0), (0.0, 0.0)),
        PrescribedDisplacement(side(0, 1.0), (0.0, None)),
    ]


@dataclass(frozen=True)
class StrikerOnFacet:
    """The paper's Example 1: a striker node pushes the top facet of one SVK quadrilateral.

    Reconstructed geometry (the paper's Figure 1 is not available; see
    ``benchmarks/research/paper_ex1_geometry.py`` and ``docs/paper_ex1.md``):
    the unit square [0, 1]^2 in plane strain, clamped on its left and bottom
    faces, its right face free to move vertically only, so the one unknown
    is the vertical displacement u of the corner b = (1, 1). The target
    facet is the top face a -> b, a = (0, 1) fixed. The striker node starts
    on the facet at (``striker_at``, 1) and moves straight down by h. The
    node-to-segment gap is g(u) = (h - u/2) / sqrt(1 + u^2) at the midpoint,
    nonlinear in u through the rotation of the facet about a; the striker
    stops the corner at u = h / striker_at (2 h = -0.5 at the midpoint). With
    the strain energy integrated by 2 x 2 Gauss points, the penalty method
    gives u = -0.098750 at r = 100 and -0.38727 at r = 1000: the paper's
    -0.0988 and -0.387 to every printed digit. Units: E = 210, lengths as
    given; r is a point stiffness (force per length, per unit thickness),
    absolute as in the paper.
    """

    h: float = -0.25
    striker_at: float = 0.5
    steps: int = 1
    energy_quadrature_degree: int = 2

    @property
    def exact_u(self) -> float:
        """The exact corner displacement h / striker_at."""
        return self.h / self.striker_at

    def build(
        self, settings: ContactSettings, comm: MPI.Comm = MPI.COMM_WORLD
    ) -> StrikerOnFacetProblem:
        """Create the one-element mesh and the node-to-segment problem."""
        domain = mesh.create_unit_square(comm, 1, 1, mesh.CellType.quadrilateral)
        top = mesh.locate_entities_boundary(domain, 1, lambda x: np.isclose(x[1], 1.0))
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
