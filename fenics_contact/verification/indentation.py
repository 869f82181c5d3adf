"""A scalable 3D contact problem: a rigid ball indenting a block (the DOF ladder).

A quarter of a block [0, L] x [0, L] x [0, H] on a structured tetrahedral
mesh (``n`` cells per edge, 3 (n + 1)^3 displacement DOFs), symmetry
conditions on x = 0 and y = 0, the bottom z = 0 clamped. A rigid ball of
radius ``ball_radius`` touches the top face at the origin corner and moves
down by ``depth``. Candidate contact facets are the top facets within
``candidate_radius`` of the z axis. Sizes are chosen by the DOF count, so
the same physics runs from 1e4 to 1e6 DOFs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from dolfinx import mesh

from mpi4py import MPI

from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.materials import Elastic, material
from fenics_contact.model.obstacles import RigidBall
from fenics_contact.model.problem import (
    ContactProblem,
    PrescribedDisplacement,
    one_body_problem,
)


def cells_for_dofs(dofs: float) -> int:
    """Cells per edge n whose mesh has about ``dofs`` displacement DOFs (3 (n + 1)^3)."""
    return max(2, round((dofs / 3.0) ** (1.0 / 3.0)) - 1)


@dataclass(frozen=True)
class BlockIndentation:
    """The ladder problem; see the module docstring (lengths in units of L, stress of E).

    Attributes:
        n: cells per edge of the structured mesh.
        length: block side L (length).
        height: block height H (length).
        E: Young's modulus (stress).
        nu: Poisson's ratio.
        law: 'neo-hookean' (finite strain) or 'linear'.
        ball_radius: radius of the rigid ball (length).
        depth: downward motion of the ball at load factor 1 (length).
        candidate_radius: top facets closer than this to the z axis are candidates.
    """

    n: int = 20
    length: float = 1.0
    height: float = 1.0
    E: float = 200.0
    nu: float = 0.3
    law: str = "neo-hookean"
    ball_radius: float = 1.0
    depth: float = 0.02
    candidate_radius: float = 0.4

    def material(self) -> Elastic:
        """The block's law."""
        return material(self.law, self.E, self.nu)

    def build(self, settings: ContactSettings, comm: MPI.Comm = MPI.COMM_WORLD) -> ContactProblem:
        """Create the mesh and the contact problem (load factor 1 = ``depth``)."""
        L, H = self.length, self.height
        domain = mesh.create_box(
            comm, [np.zeros(3), np.array([L, L, H])], [self.n, self.n, self.n],
            mesh.CellType.tetrahedron, ghost_mode=mesh.GhostMode.none,
        )
        fdim = 2

        def plane(axis: int, value: float):
            return mesh.locate_entities_boundary(
                domain, fdim, lambda x: np.isclose(x[axis], value)
            )

        rc = self.candidate_radius
        contact = mesh.locate_entities_boundary(
            domain, fdim,
            lambda x: np.isclose(x[2], H) & (x[0] ** 2 + x[1] ** 2 <= (rc * 1.0001) ** 2),
        )
        ball = RigidBall(domain, (0.0, 0.0, H + self.ball_radius), self.ball_radius)
        prescribed = [
            PrescribedDisplacement(plane(2, 0.0), (0.0, 0.0, 0.0)),
            PrescribedDisplacement(plane(0, 0.0), (0.0, None, None)),
            PrescribedDisplacement(plane(1, 0.0), (None, 0.0, None)),
        ]
        return one_body_problem(
            domain, self.material(), ball, contact, settings, prescribed=prescribed,
            obstacle_motion=(0.0, 0.0, -self.depth),
        )
