"""Friction benchmark problems defined once: the sliding block of the scene file, in code.

:class:`SlidingBlock` is ``scenes/block_slide_friction.toml`` (an SVK block
on a rigid plane, top clamped, the plane pressed up then moved sideways)
with its knobs exposed for the stability grid: mu, the schedule (e.g. a load
reversal), the mesh and the number of load steps.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from dolfinx import mesh

from mpi4py import MPI

from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.friction import FrictionSettings
from fenics_contact.model.materials import material
from fenics_contact.model.obstacles import RigidPlane
from fenics_contact.model.problem import (
    ContactProblem,
    PrescribedDisplacement,
    one_body_problem,
)

#: Press up by 0.01 over t = 0 ... 0.4, then slide by 0.02 (the scene's path).
PRESS_SLIDE = ((0.0, 0.0, 0.0), (0.4, 0.0, 0.01), (1.0, 0.02, 0.01))
#: Press, slide +0.02, then back to -0.01: the friction force reverses.
REVERSAL = ((0.0, 0.0, 0.0), (0.3, 0.0, 0.01), (0.65, 0.02, 0.01), (1.0, -0.01, 0.01))
#: Press up by 0.01, then slide by 0.02 while pressing on to 0.015: every step
#: changes the normal state too, so a frictionless run has work in every step.
OBLIQUE = ((0.0, 0.0, 0.0), (0.4, 0.0, 0.01), (1.0, 0.02, 0.015))


@dataclass(frozen=True)
class SlidingBlock:
    """A width x height block (nx x ny quadrilaterals) on the plane y = 0 with friction mu.

    Attributes:
        mu: Coulomb coefficient.
        schedule: plane displacement rows (t, dx, dy).
        nx, ny: cells.
        width, height: block size (length).
        E, nu: SVK material (nu = 0: no sideways spreading when pressed).
        steps: load steps.
        tangential_r_max: cap of r_t relative to E/L, L the contact surface extent
            (None: r_t = r).
    """

    mu: float = 0.3
    schedule: tuple[tuple[float, float, float], ...] = PRESS_SLIDE
    nx: int = 20
    ny: int = 10
    width: float = 1.0
    height: float = 0.5
    E: float = 1000.0
    nu: float = 0.0
    steps: int = 20
    tangential_r_max: float | None = 2.0

    @property
    def label(self) -> str:
        """Mesh label for tables."""
        return f"{self.nx}x{self.ny}"

    def build(
        self, settings: ContactSettings, comm: MPI.Comm = MPI.COMM_WORLD
    ) -> ContactProblem:
        """Mesh, plane on its schedule and the frictional problem."""
        domain = mesh.create_rectangle(
            comm, [np.zeros(2), np.array([self.width, self.height])], [self.nx, self.ny],
            mesh.CellType.quadrilateral,
        )
        fdim = domain.topology.dim - 1
        bottom = mesh.locate_entities_boundary(domain, fdim, lambda x: np.isclose(x[1], 0.0))
        top = mesh.locate_entities_boundary(
            domain, fdim, lambda x: np.isclose(x[1], self.height)
        )
        plane = RigidPlane(domain, [0.0, 0.0], [0.0, 1.0])
        return one_body_problem(
            domain, material("svk", self.E, self.nu), plane, bottom, settings,
            prescribed=[PrescribedDisplacement(top, (0.0, 0.0))],
            obstacle_schedule=self.schedule,
            friction=FrictionSettings(self.mu, self.tangential_r_max),
        )
