"""A converged contact state against Hertz theory at its own load (2D line, 3D point contact).

The measured total contact force sets the Hertz reference; the half-width
(contact radius) and the peak come from a fit of the nodal pressures
(:func:`~fenics_contact.references.hertz.fit_contact_profile`), and the
largest nodal pressure is compared too. Pressures are <= 0 (the
multiplier's sign); lengths and stresses in the scene's units.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fenics_contact.model.problem import ContactProblem
from fenics_contact.references.hertz import (
    ContactProfileFit,
    HertzSolution,
    PlainData,
    fit_contact_profile,
    hertz_line_contact,
    relative_error,
)
from fenics_contact.references.hertz3d import HertzPointContact, hertz_point_contact


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
class HertzComparison(PlainData):
    """The finite element contact state against Hertz theory at the same load.

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


def measure_hertz(problem: ContactProblem, radius: float, E: float, nu: float) -> HertzComparison:
    """A cylinder (radius R, E, nu; plane strain) on a rigid plane against Hertz at its load.

    Raises:
        ValueError: when the outermost candidate nodes are in contact (the
            contact zone may be cut off by the candidate facets).
    """
    state = problem.contact_state()
    x, p = contact_profile(problem)
    if p[0] < 0.0 or p[-1] < 0.0:
        raise ValueError(
            "The contact zone reaches the end of the candidate facets: widen the candidate "
            "facets (the contact tag's bounds) or lower the push."
        )
    fit = fit_contact_profile(x, p)
    hertz = hertz_line_contact(state.contact_force, radius, E, nu)
    return HertzComparison.of(state.contact_force, hertz, fit, state.max_penetration)


def measure_hertz_sphere(
    problem: ContactProblem, radius: float, E: float, nu: float, copies: int = 4
) -> HertzComparison:
    """A sphere (R, E, nu) modelled by a symmetric part on a rigid plane z = 0, against Hertz.

    ``copies``: how many such parts make the whole contact (4 for an octant
    with symmetry on x = 0 and y = 0). The fit of p^2 against r^2 (r the
    distance from the z axis) uses the nodes in contact on every rank.
    """
    state = problem.contact_state()
    xy = problem.nodal_coordinates()[:, :2]
    r = np.concatenate(problem.comm.allgather(np.linalg.norm(xy, axis=1)))
    p = np.concatenate(problem.comm.allgather(state.pressure))
    fit = fit_contact_profile(r, p)
    force = copies * state.contact_force
    hertz = hertz_point_contact(force, radius, E, nu)
    return HertzComparison.of(force, hertz, fit, state.max_penetration)
