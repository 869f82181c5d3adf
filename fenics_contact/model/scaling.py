"""Scales that make the stopping test meaningful for any E, h and r.

The static residual is a vector of nodal forces (force units; per unit
thickness in 2D): out-of-balance forces and the complementarity residual
(min(lam + r g, 0) - lam) weighted by the lumped facet area. Two scales
decide what "small" means for it:

- the force scale F = E h^(d-1): the force a unit strain puts on one
  contact facet of size h. A tolerance ``rtol * F`` means the same for
  E = 1e-3 and E = 1e12 (displacement-driven loads scale the forces with E).
- the round-off floor of the complementarity residual,
  ``FLOOR_FACTOR * eps * r * g_scale * ||A||``: the gap is computed as a
  difference of coordinates of size ``g_scale`` (|x - obstacle point|), so
  it carries an error of about eps * g_scale; r multiplies that error into
  a pressure, and the lumped areas A into forces. At r = 1e12 E/h this floor
  is of the order of the contact forces themselves; no stopping test may
  demand less.
"""

from __future__ import annotations

import math

import numpy as np

from mpi4py import MPI

from fenics_contact.model.problem import ContactProblem

#: Safety factor over eps * r * g_scale * ||A||. Measured on the Example 2
#: analog: plain GNRM stalls at 0.3-0.5 times eps * r * g_scale * ||A||
#: for r = 1e8 ... 1e12 E/h; 4 keeps the floor above every stall seen.
FLOOR_FACTOR = 4.0

#: Default stopping tolerance relative to the force scale E h^(d-1).
DEFAULT_FORCE_RTOL = 1e-10

#: A scene that leaves atol out stops at max(SCENE_ATOL, SCENE_FORCE_ATOL E h^(d-1)).
SCENE_ATOL = 1e-8
SCENE_FORCE_ATOL = 1e-12

#: An atol below this share of eps r g_scale ||A|| lies under the level the residual
#: stalls at. Measured: a three-body sandwich (r = 1 E/h, E = 2e6 and 2e9) stalled at
#: 0.1-0.2 eps r g_scale ||A|| (3-6e-10 and 3-6e-7), the Example 2 analog at 0.3-0.5;
#: a cylinder between plates reaches atol = 0.7 of it (5 iterations a step).
BELOW_ROUNDOFF = 0.1


def force_scale(problem: ContactProblem) -> float:
    """E h^(d-1): the force unit of the residual (force; per unit thickness in 2D)."""
    dim = problem.domain.geometry.dim
    return float(problem.material.E * problem.h ** (dim - 1))


def dirichlet_stiffness(problem: ContactProblem) -> float:
    """E h^(d-2): the stiffness that makes a Dirichlet row's x - x_D a force (force/length).

    The force a mismatch of one length puts on a node of facet size h; the
    divergence test weights the residual's Dirichlet rows with it
    (:meth:`~fenics_contact.solvers.newton.NewtonKernel.force_norm`).
    """
    return force_scale(problem) / float(problem.h)


def gap_scale(problem: ContactProblem) -> float:
    """Size of the numbers the gap is computed from (length).

    The largest distance between a multiplier node (reference position plus
    displacement bound given by the current state) and the point its gap is
    measured from (an obstacle's reference point; the origin for a
    deformable pair, whose gap is a difference of coordinates), over every
    contact; at least the smallest contact facet size.
    """
    gdim = problem.domain.geometry.dim
    local = max(
        float(np.max(np.linalg.norm(c.nodal_coordinates()[:, :gdim] - c.gap_origin(), axis=1),
                     initial=0.0))
        for c in problem.contacts
    )
    u_max = float(np.max(np.abs(problem.u.x.array), initial=0.0))
    scale = problem.comm.allreduce(local, op=MPI.MAX) + problem.comm.allreduce(u_max, op=MPI.MAX)
    return max(scale, problem.h)


def area_norm(problem: ContactProblem) -> float:
    """Euclidean norm of the lumped nodal areas of every contact surface (area)."""
    local = sum(float(c.surface.lumped_area @ c.surface.lumped_area) for c in problem.contacts)
    return math.sqrt(problem.comm.allreduce(local, op=MPI.SUM))


def residual_floor(problem: ContactProblem, r: float | None = None) -> float:
    """Round-off floor of the static residual at ``r`` (absolute; default: current r).

    ``r`` is the first contact's; the others keep their ratio to it and the
    largest r counts. Returns ``FLOOR_FACTOR * eps`` times the larger of
    r g_scale ||A|| (the complementarity rows) and E h^(d-1) of the stiffest
    body (the elastic rows: a patch test with a body of E = 2e6 stalled at
    1.2e-11 = 0.2 eps E h, far above the contact rows' round-off at a small
    working r) (force units).
    """
    eps = float(np.finfo(float).eps)
    return FLOOR_FACTOR * eps * max(contact_force_size(problem, r), force_scale(problem))


def contact_force_size(problem: ContactProblem, r: float | None = None) -> float:
    """The size r g_scale ||A|| of the forces whose round-off the residual carries (force).

    The complementarity rows r g A are formed from coordinates of size
    ``g_scale``; eps times this is the round-off of those rows (the residual's
    floor is :data:`FLOOR_FACTOR` times it). 0 without contacts. Collective.
    """
    if not problem.contacts:
        return 0.0
    r_abs = (problem.r_absolute if r is None else float(r)) * max(problem.r_ratios())
    return r_abs * gap_scale(problem) * area_norm(problem)


def default_atol(problem: ContactProblem) -> float:
    """The atol of a scene that leaves it out: max(1e-8, 1e-12 E h^(d-1)) (force).

    Every shipped scene (E h^(d-1) <= 1e4) keeps 1e-8; steel in Pa follows its forces.
    """
    return max(SCENE_ATOL, SCENE_FORCE_ATOL * force_scale(problem))


def suggested_atol(problem: ContactProblem) -> float:
    """An atol above the round-off of ``problem``'s residual: the default, at least the floor."""
    floor = residual_floor(problem) if problem.contacts else 0.0
    return max(default_atol(problem), floor)


def below_roundoff(problem: ContactProblem, atol: float) -> bool:
    """Whether ``atol`` lies below the level the residual stalls at (collective)."""
    eps = float(np.finfo(float).eps)
    return atol < BELOW_ROUNDOFF * eps * contact_force_size(problem)


def scaled_atol(problem: ContactProblem, force_rtol: float = DEFAULT_FORCE_RTOL) -> float:
    """Absolute tolerance ``force_rtol * E h^(d-1)``, raised to the round-off floor at r."""
    return max(force_rtol * force_scale(problem), residual_floor(problem))
