"""The paper's Example 2 analog: a bar pushed into a rigid cylindrical cradle.

Defined once here; the study (``paper-ex2``), the main demo, the trade-off
and stability sweeps (as ``BarScene``) and ``scenes/paper_ex2.toml`` all
describe this problem.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from dolfinx import mesh

from mpi4py import MPI

from fenics_contact.model.candidates import CandidateMode, choose_candidates
from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.materials import material
from fenics_contact.model.obstacles import RigidBall
from fenics_contact.model.problem import (
    ContactProblem,
    PrescribedDisplacement,
    one_body_problem,
)
from fenics_contact.verification.paper import PAPER_E, PAPER_NU, PAPER_TABLE_2


@dataclass(frozen=True)
class BarOnCradle:
    """Example 2 analog: a plane-strain bar pushed into a rigid cylindrical cradle.

    A bar [-L/2, L/2] x [0, H] of ``nx`` x ``ny`` bilinear quadrilaterals
    (6 x 2: 12 elements, 7 contact nodes on its lower face) hangs a distance
    ``end_gap`` above a rigid cradle: the inside of a circle of radius
    ``radius`` whose lowest point is below the bar's centre. The middle third
    of the top face is driven down by ``push`` (and held horizontally) in
    equal increments.

    What happens (SVK, E = 210, nu = 0.3, r = 100; 10 steps): the bar's end
    corners touch the cradle first; the bar bends and the gaps close toward
    the centre until the whole lower face is in contact; as the centre is
    pressed further the ends lift off again: gaps open near the extremities
    while the centre stays closed, the pattern the paper describes.

    Attributes:
        nx, ny: quadrilaterals along and across the bar.
        end_gap: initial gap at the bar's lower corners (length); < 0 starts
            penetrated, 0 grazing.
        push: downward displacement of the middle third of the top face (length).
        E, nu, law: material (stress units; 'svk', 'neo-hookean', 'linear').
        steps: load steps.
        candidates: 'tag' (lower face), 'detected' or 'boundary'.
        length, height: bar size; radius: cradle radius (length).
    """

    nx: int = 6
    ny: int = 2
    end_gap: float = 0.02
    push: float = 0.8
    E: float = PAPER_E
    nu: float = PAPER_NU
    law: str = "svk"
    steps: int = 10
    candidates: CandidateMode = "tag"
    length: float = 6.0
    height: float = 1.0
    radius: float = 10.0

    #: The paper's Table 2, for the study's side-by-side print.
    published_table = PAPER_TABLE_2

    @property
    def label(self) -> str:
        """Mesh label for tables."""
        return f"{self.nx}x{self.ny}"

    def cradle_centre(self) -> tuple[float, float]:
        """Centre of the cradle circle: its arc passes end_gap below the bar's corners."""
        half = self.length / 2
        return 0.0, -self.end_gap + float(np.sqrt(self.radius**2 - half**2))

    def build(self, settings: ContactSettings, comm: MPI.Comm = MPI.COMM_WORLD) -> ContactProblem:
        """Mesh, cradle and problem."""
        half = self.length / 2
        domain = mesh.create_rectangle(
            comm, [np.array([-half, 0.0]), np.array([half, self.height])],
            [self.nx, self.ny], mesh.CellType.quadrilateral,
        )
        fdim = domain.topology.dim - 1
        bottom = mesh.locate_entities_boundary(domain, fdim, lambda x: np.isclose(x[1], 0.0))
        punch = mesh.locate_entities_boundary(
            domain, fdim,
            lambda x: np.isclose(x[1], self.height) & (np.abs(x[0]) <= half / 3 + 1e-9),
        )
        cradle = RigidBall(domain, self.cradle_centre(), self.radius, inside=True)
        facets = choose_candidates(domain, cradle, bottom, self.candidates, self.push)
        return one_body_problem(
            domain, material(self.law, self.E, self.nu), cradle, facets, settings,
            prescribed=[PrescribedDisplacement(punch, (0.0, -self.push))],
        )
