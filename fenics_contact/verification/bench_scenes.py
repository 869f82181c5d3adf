"""Parametrised scenes for the trade-off and stability sweeps.

Each scene is a frozen dataclass with ``steps``, ``label`` and
``build(settings, comm) -> ContactProblem``; every knob a sweep turns
(material, mesh, initial gap, candidate facets) is a field.

- :class:`BarScene`: the Example 2 analog
  (:class:`~fenics_contact.verification.bar.BarOnCradle`, the same class)
  with free E, nu, law, mesh (nx, ny) and end gap (negative: initial
  penetration; 0: grazing; large: no contact).
- :class:`HertzScene`: the Hertz half-cylinder
  (:class:`~fenics_contact.verification.hertz_problem.HertzCylinder`) on a
  coarser default mesh (h_contact = 0.01).
- :class:`BlockScene`: a block pressed flat onto a rigid plane: every
  bottom node in contact (full contact), gap exactly 0 at the start.

Candidate facets (``candidates``, see
:func:`~fenics_contact.model.candidates.choose_candidates`): ``"tag"`` the
scene's own choice, ``"detected"`` along the obstacle's path, ``"boundary"``
every exterior facet. Loads are prescribed displacements, so all forces
scale with E.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from dolfinx import mesh

from mpi4py import MPI

from fenics_contact.model.candidates import CandidateMode, choose_candidates
from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.materials import material
from fenics_contact.model.obstacles import RigidPlane
from fenics_contact.model.problem import (
    ContactProblem,
    PrescribedDisplacement,
    one_body_problem,
)
from fenics_contact.verification.bar import BarOnCradle
from fenics_contact.verification.hertz_problem import HertzCylinder
from fenics_contact.verification.paper import PAPER_E, PAPER_NU

#: The Example 2 bar with every knob a sweep turns.
BarScene = BarOnCradle


@dataclass(frozen=True)
class HertzScene(HertzCylinder):
    """The Hertz half-cylinder of the sweeps: HertzCylinder on a coarser mesh."""

    h_contact: float = 0.01


@dataclass(frozen=True)
class BlockScene:
    """A unit block pressed flat on the rigid plane y = 0: full, grazing contact.

    The lower face rests on the plane (gap exactly 0 at the start); the top
    face is moved down by ``delta`` and the left face held horizontally.
    Every lower node ends in contact with a uniform pressure ~ E' delta.
    """

    n: int = 4
    delta: float = 0.05
    E: float = PAPER_E
    nu: float = PAPER_NU
    law: str = "svk"
    steps: int = 2
    candidates: CandidateMode = "tag"

    @property
    def label(self) -> str:
        """Mesh label for tables."""
        return f"{self.n}x{self.n}"

    def build(self, settings: ContactSettings, comm: MPI.Comm = MPI.COMM_WORLD) -> ContactProblem:
        """Mesh, plane and problem."""
        domain = mesh.create_unit_square(comm, self.n, self.n, mesh.CellType.quadrilateral)
        fdim = domain.topology.dim - 1

        def side(axis: int, value: float) -> np.ndarray:
            return mesh.locate_entities_boundary(domain, fdim, lambda x: np.isclose(x[axis], value))

        plane = RigidPlane(domain, [0.0, 0.0], [0.0, 1.0])
        facets = choose_candidates(domain, plane, side(1, 0.0), self.candidates, self.delta)
        return one_body_problem(
            domain, material(self.law, self.E, self.nu), plane, facets, settings,
            prescribed=[
                PrescribedDisplacement(side(1, 1.0), (None, -self.delta)),
                PrescribedDisplacement(side(0, 0.0), (0.0, None)),
            ],
        )
