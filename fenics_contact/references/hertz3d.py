"""Hertz point contact: an elastic sphere on a rigid plane (3D).

For a sphere of radius R (length), Young's modulus E and Poisson's ratio nu
(stress) pressed on a rigid frictionless plane by a total force P (force),
with E* = E / (1 - nu^2):

- contact radius   a  = (3 P R / (4 E*))^(1/3)      (length);
- peak pressure    p0 = 3 P / (2 pi a^2)            (stress);
- approach         delta = a^2 / R                  (length);
- pressure         p(r) = p0 sqrt(1 - r^2 / a^2), r <= a.

Pressures are magnitudes (>= 0). The fit of nodal pressures to
p^2 = p0^2 (1 - r^2/a^2) is :func:`fenics_contact.references.hertz.fit_contact_profile`
with the radial distance r as coordinate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fenics_contact.references.hertz import plane_strain_modulus


@dataclass(frozen=True)
class HertzPointContact:
    """Hertz sphere-on-plane contact at one load.

    Attributes:
        P: total normal force (force).
        a: contact radius (length).
        p0: peak pressure (stress).
        delta: approach of distant points (length).
        E_star: E / (1 - nu^2) (stress).
    """

    P: float
    a: float
    p0: float
    delta: float
    E_star: float


def hertz_point_contact(P: float, R: float, E: float, nu: float) -> HertzPointContact:
    """Contact radius, peak pressure and approach of a sphere (R, E, nu) under force P."""
    if not (np.isfinite(P) and P > 0 and R > 0):
        raise ValueError(f"Force and radius must be > 0, got P = {P}, R = {R}.")
    e_star = plane_strain_modulus(E, nu)
    a = float((3.0 * P * R / (4.0 * e_star)) ** (1.0 / 3.0))
    return HertzPointContact(
        P=float(P), a=a, p0=float(3.0 * P / (2.0 * np.pi * a**2)), delta=a**2 / R,
        E_star=e_star,
    )


def force_for_radius(a: float, R: float, E: float, nu: float) -> float:
    """The force P = 4 E* a^3 / (3 R) that gives contact radius ``a`` (force units)."""
    return float(4.0 * plane_strain_modulus(E, nu) * a**3 / (3.0 * R))
