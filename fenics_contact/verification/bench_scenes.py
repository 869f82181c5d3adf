"""Parametrised scenes for the trade-off and stability sweeps.

Each scene is a frozen dataclass with ``steps``, ``label`` and
``build(settings, comm) -> ContactProblem``; every knob a sweep turns
(material, mesh, initial gap, candidate facets) is a field.

- :class:`BarScene`: the Example 2 analog
  (:class:`~fenics_contact.verification.examples.BarOnCradle`)
  with free E, nu, law, mesh (nx, ny) and end gap (negative: initial
  penetration; 0: grazing; large: no contact).
- :class:`HertzScene`: the Hertz half-cylinder
  (:class:`~fenics_contact.verification.hertz_problem.HertzCylinder`) with free E, nu and
  mesh sizes.
- :class:`BlockScene`: a block pressed flat onto a rigid plane: every
  bottom node in contact (full contact), gap exactly 0 at the start.

Candidate facets (``candidates``): ``"tag"`` the scene's own choice (the
bar's lower face, the Hertz contact band, the block's lower face);
``"detected"`` :func:`~fenics_contact.model.candidates.detect_candidate_facets`
with a margin that includes the body's largest prescribed displacement;
``"boundary"`` every exterior facet. Loads are prescribed displacements, so
all forces scale with E.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from dolfinx import mesh

from mpi4py import MPI

from fenics_contact.model.candidates import boundary_facets, detect_candidate_facets
from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.materials import material
from fenics_contact.model.obstacles import RigidBall, RigidObstacle, RigidPlane
from fenics_contact.model.problem import ContactProblem, PrescribedDisplacement
from fenics_contact.scene.meshing import CONTACT_TAG, TOP_TAG, hertz_half_disk
from fenics_contact.verification.examples import PAPER_E, PAPER_NU
from fenics_contact.verification.hertz_problem import HertzCylinder, measure_hertz

Candidates = Literal["tag", "detected", "boundary"]


def _choose(
    domain: mesh.Mesh,
    obstacle: RigidObstacle,
    tagged: np.ndarray,
    mode: Candidates,
    reach: float,
) -> np.ndarray:
    """Candidate facets by mode; ``reach`` is the body's displacement bound (length)."""
    if mode == "tag":
        return tagged
    if mode == "boundary":
        return boundary_facets(domain)
    if mode == "detected":
        return detect_candidate_facets(domain, obstacle, None, 0.0, displacement_bound=reach)
    raise ValueError(f"Unknown candidate mode {mode!r}; use 'tag', 'detected' or 'boundary'.")


@dataclass(frozen=True)
class BarScene:
    """A plane-strain bar pushed into a rigid cradle (Example 2 analog, see BarOnCradle).

    Attributes:
        nx, ny: quadrilaterals along and across the bar.
        end_gap: initial gap at the bar's lower corners (length); < 0 starts
            penetrated, 0 grazing.
        push: downward displacement of the middle third of the top face (length).
        E, nu, law: material (stress units; 'svk', 'neo-hookean', 'linear').
        steps: load steps.
        candidates: 'tag' (lower face), 'detected' or 'boundary'.
    """

    nx: int = 6
    ny: int = 2
    end_gap: float = 0.02
    push: float = 0.8
    E: float = PAPER_E
    nu: float = PAPER_NU
    law: str = "svk"
    steps: int = 10
    candidates: Candidates = "tag"
    length: float = 6.0
    height: float = 1.0
    radius: float = 10.0

    @property
    def label(self) -> str:
        """Mesh label for tables."""
        return f"{self.nx}x{self.ny}"

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
        centre = (0.0, -self.end_gap + float(np.sqrt(self.radius**2 - half**2)))
        cradle = RigidBall(domain, centre, self.radius, inside=True)
        facets = _choose(domain, cradle, bottom, self.candidates, self.push)
        return ContactProblem(
            domain, material(self.law, self.E, self.nu), cradle, facets, settings,
            prescribed=[PrescribedDisplacement(punch, (0.0, -self.push))],
        )


@dataclass(frozen=True)
class HertzScene:
    """The Hertz half-cylinder on a rigid plane (see HertzCylinder), small strain.

    Attributes:
        h_contact, h_far: element sizes near and far from the contact (length).
        E, nu: material; push: top-face displacement at load 1 (length).
        steps: load steps; candidates: 'tag' (contact band), 'detected', 'boundary'.
    """

    h_contact: float = 0.01
    h_far: float = 0.1
    E: float = 200.0
    nu: float = 0.3
    push: float = 0.01
    steps: int = 4
    candidates: Candidates = "tag"

    @property
    def label(self) -> str:
        """Mesh label for tables."""
        return f"h={self.h_contact:g}"

    def cylinder(self) -> HertzCylinder:
        """The equivalent HertzCylinder (for the analytic comparison)."""
        return HertzCylinder(
            E=self.E, nu=self.nu, push=self.push, h_contact=self.h_contact, h_far=self.h_far
        )

    def build(self, settings: ContactSettings, comm: MPI.Comm = MPI.COMM_WORLD) -> ContactProblem:
        """Graded half-disk mesh and problem."""
        cyl = self.cylinder()
        if self.candidates == "tag":
            return cyl.build(settings, comm)
        data = hertz_half_disk(
            comm, radius=cyl.radius, h_contact=cyl.h_contact, h_far=cyl.h_far,
            fine_radius=cyl.fine_radius, coarse_radius=cyl.coarse_radius,
        )
        domain = data.mesh
        plane = RigidPlane(domain, point=(0.0, 0.0), normal=(0.0, 1.0))
        arc = data.facet_tags.find(CONTACT_TAG)
        facets = _choose(domain, plane, arc, self.candidates, self.push)
        return ContactProblem(
            domain, cyl.material(), plane, facets, settings,
            prescribed=[PrescribedDisplacement(data.facet_tags.find(TOP_TAG), (0.0, -self.push))],
        )

    def peak_pressure_error(self, problem: ContactProblem) -> float:
        """Relative error of the fitted peak pressure against Hertz (NaN if not measurable)."""
        try:
            return float(measure_hertz(problem, self.cylinder()).p0_error)
        except ValueError:
            return float("nan")


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
    candidates: Candidates = "tag"

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
        facets = _choose(domain, plane, side(1, 0.0), self.candidates, self.delta)
        return ContactProblem(
            domain, material(self.law, self.E, self.nu), plane, facets, settings,
            prescribed=[
                PrescribedDisplacement(side(1, 1.0), (None, -self.delta)),
                PrescribedDisplacement(side(0, 0.0), (0.0, None)),
            ],
        )
