"""The two common contact problems, built from their parts.

A body against a rigid obstacle (:func:`one_body_problem`) and bodies of
one mesh in one node-to-segment pair (:func:`two_body_problem`); any other
composition is a :class:`~.body.Solid` and a list of contacts given to
:class:`~.problem.ContactProblem` directly. :mod:`.problem` re-exports both
functions, so they import :class:`~.problem.ContactProblem` when called.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from dolfinx import mesh

from fenics_contact.model.body import Body, PrescribedDisplacement, Solid, SurfaceTraction
from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.friction import FrictionSettings
from fenics_contact.model.materials import Elastic
from fenics_contact.model.obstacle_contact import ObstacleContact
from fenics_contact.model.obstacles import RigidObstacle

if TYPE_CHECKING:
    from fenics_contact.model.problem import ContactProblem


def one_body_problem(
    domain: mesh.Mesh,
    material: Elastic,
    obstacle: RigidObstacle,
    contact_facets: np.ndarray,
    settings: ContactSettings,
    *,
    prescribed: Sequence[PrescribedDisplacement] = (),
    tractions: Sequence[SurfaceTraction] = (),
    obstacle_motion: Sequence[float] | None = None,
    obstacle_schedule: Sequence[Sequence[float]] | None = None,
    degree: int = 1,
    friction: FrictionSettings | None = None,
) -> ContactProblem:
    """One deformable body (every cell) against one rigid obstacle."""
    from fenics_contact.model.problem import ContactProblem

    solid = Solid(domain, [Body("body", None, material)], prescribed=prescribed,
                  tractions=tractions, degree=degree)
    contact = ObstacleContact(obstacle, contact_facets, settings, motion=obstacle_motion,
                              schedule=obstacle_schedule, friction=friction)
    return ContactProblem(solid, [contact])


def two_body_problem(
    domain: mesh.Mesh,
    cell_tags: mesh.MeshTags,
    bodies: Sequence[Body],
    striker_facets: np.ndarray,
    target_facets: np.ndarray,
    settings: ContactSettings,
    *,
    striker: str | None = None,
    target: str | None = None,
    prescribed: Sequence[PrescribedDisplacement] = (),
    tractions: Sequence[SurfaceTraction] = (),
    degree: int = 1,
    friction: FrictionSettings | None = None,
    name: str = "pair",
) -> ContactProblem:
    """Bodies of one mesh with one node-to-segment pair (striker against target)."""
    from fenics_contact.model.pairs import NodeToSegmentContact
    from fenics_contact.model.problem import ContactProblem

    solid = Solid(domain, bodies, cell_tags, prescribed=prescribed, tractions=tractions,
                  degree=degree)
    contact = NodeToSegmentContact(striker_facets, target_facets, settings, striker=striker,
                                   target=target, friction=friction, name=name)
    return ContactProblem(solid, [contact])


__all__ = ["one_body_problem", "two_body_problem"]
