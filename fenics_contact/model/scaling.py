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


def force_scale(problem: ContactProblem) -> float:
    """E h^(d-1): the force unit of the residual (force; per unit thickness in 2D)."""
    dim = problem.domain.geometry.dim
    return float(problem.material.E * problem.surface.h ** (dim - 1))


def gap_scale(problem: ContactProblem) -> float:
    """Size of the numbers the gap is computed from (length).

    The largest distance between a multiplier node (reference position plus
    displacement bound given by the current state) and the obstacle's
    reference point; at least the mean contact facet size.
    """
    coords = problem.nodal_coordinates()[:, : problem.domain.geometry.dim]
    gdim = problem.domain.geometry.dim
    # Two-body problems (no obstacle): the gap is a difference of coordinates.
    obstacle = getattr(problem, "obstacle", None)
    point = np.zeros(gdim) if obstacle is None else np.asarray(obstacle.point.value, float)
    local = float(np.max(np.linalg.norm(coords - point, axis=1), initial=0.0))
    u_max = float(np.max(np.abs(problem.u.x.array), initial=0.0))
    scale = problem.comm.allreduce(local, op=MPI.MAX) + problem.comm.allreduce(u_max, op=MPI.MAX)
    return max(scale, problem.surface.h)


def area_norm(problem: ContactProblem) -> float:
    """Euclidean norm of the lumped nodal areas of the contact surface (area)."""
    local = float(problem.surface.lumped_area @ problem.surface.lumped_area)
    return math.sqrt(problem.comm.allreduce(local, op=MPI.SUM))


def residual_floor(problem: ContactProblem, r: float | None = None) -> float:
    """Round-off floor of the static residual at ``r`` (absolute; default: current r).

    Returns ``FLOOR_FACTOR * eps * r * g_scale * ||A||`` (force units).
    """
    r_abs = problem.r_absolute if r is None else float(r)
    eps = float(np.finfo(float).eps)
    return FLOOR_FACTOR * eps * r_abs * gap_scale(problem) * area_norm(problem)


def scaled_atol(problem: ContactProblem, force_rtol: float = DEFAULT_FORCE_RTOL) -> float:
    """Absolute tolerance ``force_rtol * E h^(d-1)``, raised to the round-off floor at r."""
    return max(force_rtol * force_scale(problem), residual_floor(problem))
