"""Ready-made problems: the paper's examples (analogs) and Hertz contact.

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
from fenics_contact.model.obstacles import RigidBall, RigidPlane
from fenics_contact.model.problem import ContactProblem, PrescribedDisplacement
from fenics_contact.verification.two_body_examples import BlockOnBlock, TwoCylinders

#: The paper's material for both examples.
PAPER_E = 210.0
PAPER_NU = 0.3


@dataclass(frozen=True)
class BarOnCradle:
    """Example 2 analog: a bar pushed into a rigid cylindrical cradle.

    A plane-strain bar [-L/2, L/2] x [0, H] of ``nx`` x ``ny`` bilinear
    quadrilaterals (6 x 2: 12 elements, 7 contact nodes on its lower face)
    hangs a distance ``end_gap`` above a rigid cradle: the inside of a circle
    of radius ``radius`` whose lowest point is below the bar's centre. The
    middle third of the top face is driven down by ``push`` (and held
    horizontally) in equal increments.

    What happens (SVK, E = 210, nu = 0.3, r = 100; 10 steps): the bar's end
    corners touch the cradle first; the bar bends and the gaps close toward
    the centre until the whole lower face is in contact; as the centre is
    pressed further the ends lift off again: gaps open near the
    extremities while the centre stays closed, the pattern the paper
    describes.
    """

    length: float = 6.0
    height: float = 1.0
    nx: int = 6
    ny: int = 2
    radius: float = 10.0
    end_gap: float = 0.02
    push: float = 0.8
    steps: int = 10

    def cradle_centre(self) -> tuple[float, float]:
        """Centre of the cradle circle: its arc passes end_gap below the bar's corners."""
        half = self.length / 2
        return 0.0, -self.end_gap + float(np.sqrt(self.radius**2 - half**2))

    def build(
        self,
        settings: ContactSettings,
        comm: MPI.Comm = MPI.COMM_WORLD,
    ) -> ContactProblem:
        """Create the mesh and the contact problem."""
        half = self.length / 2
        domain = mesh.create_rectangle(
            comm,
            [np.array([-half, 0.0]), np.array([half, self.height])],
            [self.nx, self.ny],
            mesh.CellType.quadrilateral,
        )
        fdim = domain.topology.dim - 1
        bottom = mesh.locate_entities_boundary(domain, fdim, lambda x: np.isclose(x[1], 0.0))
        punch = mesh.locate_entities_boundary(
            domain,
            fdim,
            lambda x: np.isclose(x[1], self.height) & (np.abs(x[0]) <= half / 3 + 1e-9),
        )
        cradle = RigidBall(domain, self.cradle_centre(), self.radius, inside=True)
        return ContactProblem(
            domain,
            SaintVenantKirchhoff(E=PAPER_E, nu=PAPER_NU),
            cradle,
            bottom,
            settings,
            prescribed=[PrescribedDisplacement(punch, (0.0, -self.push))],
        )


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
    "two-cylinders": TwoCylinders,
    "block-on-block": BlockOnBlock,
}
