"""F_t / (mu N) of a load step over its frictional contacts.

With several contacts the step's totals mix frictionless contacts (a wall,
a floor) into N and several coefficients into mu: the ratio is taken over
the frictional contacts only, each with its own mu,

    sum_c F_t,c / sum_c mu_c N_c,

which is 1 when every frictional contact slips (Coulomb's limit reached
everywhere) and below 1 while some node sticks. F_t,c is int |t| dA, each
node's traction in its own frame (``tangential_magnitude``), not the
magnitude of the vector sum: on a curved contact that slips everywhere the
vector sum is less than mu N (a half-disk dragged over a block: 0.99468),
which read as a friction error of 0.5 % at an exact answer.
"""

from __future__ import annotations

import math

from fenics_contact.solvers.stepping import StepRecord


def coulomb_terms(step: StepRecord, mus: dict[str, float]) -> tuple[float, float]:
    """(sum_c F_t,c, sum_c mu_c N_c) over the contacts named in ``mus`` (name -> mu)."""
    named = [name for name in mus if name in step.contacts]
    tangential = sum(step.contacts[name].get("tangential_magnitude",
                                             step.contacts[name]["tangential_force"])
                     for name in named)
    limit = sum(mus[name] * step.contacts[name]["normal_force"] for name in named)
    return tangential, limit


def coulomb_ratio(step: StepRecord, mus: dict[str, float]) -> float:
    """F_t / (mu N) over the contacts named in ``mus`` (name -> mu); NaN without a load."""
    tangential, limit = coulomb_terms(step, mus)
    return tangential / limit if limit > 0.0 else math.nan


__all__ = ["coulomb_ratio", "coulomb_terms"]
