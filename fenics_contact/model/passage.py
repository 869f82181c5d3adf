"""Rigid balls that a body has passed through: the ball's centre inside the deformed body.

A ball's gap |x - c| - R is positive on both sides of it: a load step that
carries a body's surface across a small ball, or the ball across a thin
body, ends with every gap open and "converges" with the ball inside the
body (a clamped block and a ball of radius 0.1 moved 0.3 into it in one
step: 0 Newton iterations, contact force 0). No admissible state has the
centre of a ball the body must stay out of inside one of its cells, so
that test is exact where it answers (a ball that passed clean through a
thin body and came out leaves no trace; the gaps then see the far side).
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from contextlib import contextmanager

import numpy as np
from dolfinx import fem, geometry, mesh

from mpi4py import MPI

from fenics_contact.model.obstacles import RigidBall


def deformed_vertices(V: fem.FunctionSpace, u: fem.Function) -> np.ndarray:
    """(nodes, gdim) current positions of the mesh's local geometry nodes (P1; length)."""
    domain = V.mesh
    gdim = domain.geometry.dim
    geo = domain.geometry.dofmaps[0]
    blocks = np.zeros(domain.geometry.x.shape[0], np.int64)
    blocks[geo.ravel()] = V.dofmap.list[:, :geo.shape[1]].ravel()  # vertex dofs first
    u.x.scatter_forward()
    return domain.geometry.x[:, :gdim] + u.x.array.reshape(-1, gdim)[blocks]


@contextmanager
def placed(domain: mesh.Mesh, x: np.ndarray) -> Iterator[None]:
    """Temporarily give the mesh geometry the positions ``x`` (restored on exit)."""
    saved = domain.geometry.x.copy()
    try:
        domain.geometry.x[:, :x.shape[1]] = x
        yield
    finally:
        domain.geometry.x[:] = saved


def points_inside(V: fem.FunctionSpace, u: fem.Function, points: np.ndarray) -> np.ndarray:
    """Whether each point (n, gdim) lies in some cell of the deformed mesh (any rank)."""
    domain = V.mesh
    gdim, tdim = domain.geometry.dim, domain.topology.dim
    x = deformed_vertices(V, u)
    found = np.zeros(points.shape[0], bool)
    lo, hi = x.min(axis=0, initial=np.inf), x.max(axis=0, initial=-np.inf)
    near = np.all((points >= lo) & (points <= hi), axis=1) if x.size else found
    if np.any(near):
        with placed(domain, x):
            tree = geometry.bb_tree(domain, tdim)
            query = np.zeros((int(near.sum()), 3))
            query[:, :gdim] = points[near]
            colliding = geometry.compute_colliding_cells(
                domain, geometry.compute_collisions_points(tree, query), query)
            found[np.flatnonzero(near)] = [len(colliding.links(i)) > 0
                                          for i in range(query.shape[0])]
    mine = found.astype(np.int32)
    every = np.empty_like(mine)
    domain.comm.Allreduce(mine, every, op=MPI.MAX)
    return every > 0


def balls_passed_through(V: fem.FunctionSpace, u: fem.Function,
                         contacts: Sequence[object]) -> list[str]:
    """Names of the contacts whose rigid ball (kept outside) has its centre in the body."""
    balls = [(c.name, c.obstacle) for c in contacts
             if isinstance(getattr(c, "obstacle", None), RigidBall) and not c.obstacle.inside]
    if not balls:
        return []
    centres = np.array([np.asarray(b.point.value, float) for _, b in balls])
    inside = points_inside(V, u, centres)
    return [name for (name, _), hit in zip(balls, inside, strict=True) if hit]


__all__ = ["balls_passed_through", "deformed_vertices", "placed", "points_inside"]
