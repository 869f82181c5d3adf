"""The 3D Hertz validation problem: one eighth of a sphere pressed on a rigid plane.

:class:`HertzSphere` builds the contact problem on the graded octant of
:func:`fenics_contact.scene.meshing.hertz_sphere_octant` with symmetry conditions
on x = 0 and y = 0; :func:`measure_hertz_sphere` compares its converged state
with :mod:`fenics_contact.verification.hertz3d` at the force it transmits (four times the
octant's, the model being a quarter of the lower hemisphere).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from dolfinx import mesh

from mpi4py import MPI

from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.materials import Elastic, material
from fenics_contact.model.obstacles import RigidPlane
from fenics_contact.model.problem import (
    ContactProblem,
    PrescribedDisplacement,
    one_body_problem,
)
from fenics_contact.scene.meshing import (
    CONTACT_TAG,
    SYMMETRY_X_TAG,
    SYMMETRY_Y_TAG,
    TOP_TAG,
    hertz_sphere_octant,
)
from fenics_contact.verification.hertz import fit_contact_profile
from fenics_contact.verification.hertz3d import hertz_point_contact
from fenics_contact.verification.hertz_problem import HertzComparison

#: Symmetry copies of the octant in the full lower hemisphere.
COPIES = 4


@dataclass(frozen=True)
class HertzSphere:
    """A sphere octant whose flat top z = R is pushed down onto the plane z = 0.

    The top face moves down by ``push`` (its in-plane motion is free); the
    faces x = 0 and y = 0 carry symmetry conditions. Candidate contact
    facets are spherical facets with midpoints below ``contact_band * R``.

    Attributes:
        radius: sphere radius R (length).
        E: Young's modulus (stress).
        nu: Poisson's ratio.
        law: 'linear' (small strain) or 'neo-hookean' (finite strain).
        push: downward displacement of the top face at load factor 1 (length).
        h_contact: element size at the contact point (length).
        h_far: element size away from it (length).
        fine_radius: distance from the contact point meshed at ``h_contact``.
        coarse_radius: distance beyond which the size is ``h_far``.
        contact_band: candidate facets have midpoints with z < contact_band R.
    """

    radius: float = 1.0
    E: float = 200.0
    nu: float = 0.3
    law: str = "linear"
    push: float = 0.01
    h_contact: float = 0.02
    h_far: float = 0.25
    fine_radius: float = 0.15
    coarse_radius: float = 0.6
    contact_band: float = 0.03

    def material(self) -> Elastic:
        """The body's law."""
        return material(self.law, self.E, self.nu)

    def build(self, settings: ContactSettings, comm: MPI.Comm = MPI.COMM_WORLD) -> ContactProblem:
        """Mesh the octant and create the contact problem (load factor 1 = ``push``)."""
        data = hertz_sphere_octant(
            comm, radius=self.radius, h_contact=self.h_contact, h_far=self.h_far,
            fine_radius=self.fine_radius, coarse_radius=self.coarse_radius,
        )
        domain, tags = data.mesh, data.facet_tags
        fdim = domain.topology.dim - 1
        sphere = tags.find(CONTACT_TAG)
        midpoints = mesh.compute_midpoints(domain, fdim, sphere)
        candidates = sphere[midpoints[:, 2] < self.contact_band * self.radius]
        plane = RigidPlane(domain, point=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0))
        prescribed = [
            PrescribedDisplacement(tags.find(TOP_TAG), (None, None, -self.push)),
            PrescribedDisplacement(tags.find(SYMMETRY_X_TAG), (0.0, None, None)),
            PrescribedDisplacement(tags.find(SYMMETRY_Y_TAG), (None, 0.0, None)),
        ]
        return one_body_problem(
            domain, self.material(), plane, candidates, settings, prescribed=prescribed
        )


#: The 3D comparison has the fields of the 2D one (contact radius for half-width).
SphereComparison = HertzComparison


def measure_hertz_sphere(problem: ContactProblem, sphere: HertzSphere) -> SphereComparison:
    """Compare the converged contact state with Hertz theory for its own force.

    The fit of p^2 against r^2 (r the distance from the z axis) uses the
    nodes in contact on every rank.
    """
    state = problem.contact_state()
    xy = problem.nodal_coordinates()[:, :2]
    r = np.concatenate(problem.comm.allgather(np.linalg.norm(xy, axis=1)))
    p = np.concatenate(problem.comm.allgather(state.pressure))
    fit = fit_contact_profile(r, p)
    force = COPIES * state.contact_force
    hertz = hertz_point_contact(force, sphere.radius, sphere.E, sphere.nu)
    return HertzComparison.of(force, hertz, fit, state.max_penetration)
