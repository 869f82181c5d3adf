"""The plane-strain Hertz validation problem: a half-cylinder pressed on a rigid plane.

:class:`HertzCylinder` builds the contact problem on the graded half-disk of
:func:`fenics_contact.scene.meshing.hertz_half_disk`; :func:`measure_hertz`
compares its converged state with :mod:`fenics_contact.verification.hertz`.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from dolfinx import mesh

from mpi4py import MPI

from fenics_contact.model.candidates import CandidateMode, choose_candidates
from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.materials import LinearElastic
from fenics_contact.model.obstacles import RigidPlane
from fenics_contact.model.problem import (
    ContactProblem,
    PrescribedDisplacement,
    one_body_problem,
)
from fenics_contact.scene.meshing import CONTACT_TAG, TOP_TAG, hertz_half_disk
from fenics_contact.verification.hertz import (
    ContactProfileFit,
    HertzSolution,
    fit_contact_profile,
    hertz_line_contact,
    relative_error,
)
from fenics_contact.verification.hertz3d import HertzPointContact


@dataclass(frozen=True)
class HertzCylinder:
    """A small-strain elastic half-cylinder pushed onto the rigid plane y = 0.

    The body is the lower half of a disk of radius ``radius`` centred at
    (0, R) (plane strain, unit thickness), touching the plane at (0, 0).
    Its flat top face y = R is moved down by ``push`` and held horizontally
    (which removes the rigid modes); the arc meets the rigid plane
    y = 0 (normal (0, 1)). Only arc facets whose midpoint lies below
    ``contact_band * R`` are candidate contact facets, which keeps the
    multiplier space small; the band must contain the contact zone
    (a^2 / (2 R) < contact_band R).

    With the defaults (E = 200, nu = 0.3, R = 1, push = 0.01) the load is
    P = 1.064 per unit thickness and the half-width a = 0.0785 R, about 20
    contact facets of size 0.004 (41 nodes in contact across the zone); the
    mesh has about 3900 degrees of freedom (see ``demos/hertz_cylinder.py``).

    Attributes:
        radius: cylinder radius R (length).
        E: Young's modulus (stress).
        nu: Poisson's ratio.
        push: downward displacement of the top face at load factor 1 (length).
        h_contact: element size near the contact point (length).
        h_far: element size away from it (length).
        fine_radius: distance from (0, 0) meshed at ``h_contact`` (length).
        coarse_radius: distance from (0, 0) beyond which the size is
            ``h_far`` (length).
        contact_band: candidate contact facets have midpoints with
            y < contact_band * R.
        steps: load steps.
        candidates: 'tag' (the arc within the contact band), 'detected'
            (along the plane's path) or 'boundary' (every exterior facet).
    """

    radius: float = 1.0
    E: float = 200.0
    nu: float = 0.3
    push: float = 0.01
    h_contact: float = 0.004
    h_far: float = 0.1
    fine_radius: float = 0.1
    coarse_radius: float = 0.5
    contact_band: float = 0.02
    steps: int = 4
    candidates: CandidateMode = "tag"

    @property
    def label(self) -> str:
        """Mesh label for tables."""
        return f"h={self.h_contact:g}"

    def material(self) -> LinearElastic:
        """The small-strain law of the body."""
        return LinearElastic(E=self.E, nu=self.nu)

    def build(self, settings: ContactSettings, comm: MPI.Comm = MPI.COMM_WORLD) -> ContactProblem:
        """Mesh the half-disk with gmsh and create the contact problem.

        Args:
            settings: contact regularisation and quadrature (the nodal
                variant, ``ContactSettings(quadrature="nodal")``, is the one
                validated here).
            comm: communicator the mesh is distributed over.

        Returns:
            The problem; the load factor 1 corresponds to ``push``.
        """
        data = hertz_half_disk(
            comm,
            radius=self.radius,
            h_contact=self.h_contact,
            h_far=self.h_far,
            fine_radius=self.fine_radius,
            coarse_radius=self.coarse_radius,
        )
        domain = data.mesh
        tags = data.facet_tags
        fdim = domain.topology.dim - 1
        arc = tags.find(CONTACT_TAG)
        midpoints = mesh.compute_midpoints(domain, fdim, arc)
        band = arc[midpoints[:, 1] < self.contact_band * self.radius]
        top = tags.find(TOP_TAG)
        plane = RigidPlane(domain, point=(0.0, 0.0), normal=(0.0, 1.0))
        candidates = choose_candidates(domain, plane, band, self.candidates, self.push)
        return one_body_problem(
            domain,
            self.material(),
            plane,
            candidates,
            settings,
            prescribed=[PrescribedDisplacement(top, (0.0, -self.push))],
        )

    def peak_pressure_error(self, problem: ContactProblem) -> float:
        """Relative error of the fitted peak pressure against Hertz (NaN if not measurable)."""
        try:
            return float(measure_hertz(problem, self).p0_error)
        except ValueError:
            return float("nan")


def contact_profile(problem: ContactProblem) -> tuple[np.ndarray, np.ndarray]:
    """Reference x-coordinates and nodal pressures (<= 0) of all contact-surface nodes.

    Gathered from every rank and sorted by x, so each rank gets the whole
    profile.
    """
    state = problem.contact_state()
    x = problem.nodal_coordinates()[:, 0]
    xs = np.concatenate(problem.comm.allgather(x))
    ps = np.concatenate(problem.comm.allgather(state.pressure))
    order = np.argsort(xs)
    return xs[order], ps[order]


@dataclass(frozen=True)
class HertzComparison:
    """The finite element contact state against Hertz theory at the same load.

    Serves line contact (2D) and point contact (3D).

    Attributes:
        P: total contact force, measured (per unit thickness in 2D).
        hertz: the analytic solution for that P (line or point contact).
        fit: half-width and peak from the nodal pressures.
        a_error: relative error of the fitted half-width.
        p0_error: relative error of the fitted peak pressure.
        nodal_peak_error: relative error of the largest nodal pressure.
        max_penetration: largest nodal penetration (length).
    """

    P: float
    hertz: HertzSolution | HertzPointContact
    fit: ContactProfileFit
    a_error: float
    p0_error: float
    nodal_peak_error: float
    max_penetration: float

    def to_dict(self) -> dict:
        """Plain-data view for JSON."""
        return asdict(self)

    @classmethod
    def of(
        cls,
        force: float,
        hertz: HertzSolution | HertzPointContact,
        fit: ContactProfileFit,
        max_penetration: float,
    ) -> HertzComparison:
        """Relative errors of the fitted and nodal values against ``hertz``."""
        return cls(
            P=force,
            hertz=hertz,
            fit=fit,
            a_error=relative_error(fit.a, hertz.a),
            p0_error=relative_error(fit.p0, hertz.p0),
            nodal_peak_error=relative_error(fit.nodal_peak, hertz.p0),
            max_penetration=max_penetration,
        )


def measure_hertz(problem: ContactProblem, cylinder: HertzCylinder) -> HertzComparison:
    """Compare the problem's current contact state with Hertz theory for its own load.

    The measured total contact force P sets the Hertz reference; the
    half-width and peak come from :func:`fenics_contact.verification.hertz.fit_contact_profile`
    over the nodes in contact, and the largest nodal pressure is compared too.

    Raises:
        ValueError: when the outermost candidate nodes are in contact (the
            contact zone may be cut off by ``contact_band``).
    """
    state = problem.contact_state()
    x, p = contact_profile(problem)
    if p[0] < 0.0 or p[-1] < 0.0:
        raise ValueError(
            "The contact zone reaches the end of the candidate facets: raise "
            "HertzCylinder.contact_band or lower the push."
        )
    fit = fit_contact_profile(x, p)
    hertz = hertz_line_contact(state.contact_force, cylinder.radius, cylinder.E, cylinder.nu)
    return HertzComparison.of(state.contact_force, hertz, fit, state.max_penetration)
