"""Strain energy densities written in UFL.

Every law maps the displacement ``u`` to a strain energy per unit reference
volume (stress units, e.g. the paper's E = 210). In 2D the body is in plane
strain: the out-of-plane stretch is one. Stresses and tangents are never
written by hand: the residual is ``ufl.derivative`` of the stored energy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import ufl

#: (mu, lmbda), the Lame moduli as numbers or UFL expressions (stress units).
Moduli = tuple[float | ufl.core.expr.Expr, float | ufl.core.expr.Expr]


#: Poisson's ratio from which the linear (P1) elements lock noticeably: scenes warn from it.
LOCKING_NU = 0.48
#: What locking does to contact pressures and what to do, measured on 2D Hertz: a soft
#: neo-Hookean half-disk (R = 1, E = 10) pressed on a stiff block (E = 1000), mortar pair,
#: h = 0.02 / 0.01 (/ 0.005). The peak against Hertz: -0.4 / -0.3 / -0.07 % at nu = 0.3,
#: +1.0 / +1.7 % at 0.45, +2.4 / +3.0 % at 0.47, +3.9 / +4.5 % at 0.48, +8.3 / +8.8 / +5.6 %
#: at 0.49, +54 / +40 % at 0.499, +206 / +107 % at 0.4999. The largest node-to-node second
#: difference of the pressure inside the zone, of the peak: 5.9 / 4.1 % at 0.3, 9.6 / 17 %
#: at 0.48, 18 / 30 / 20 % at 0.49: it does not shrink with h. The contact force moves
#: with it (0.4999 against 0.3: +88 / +76 %, where E* rises by 21 %).
LOCKING_NOTE = (
    "the linear elements lock as nu nears 0.5: the contact pressure comes out too high "
    "and jumps from node to node, and refining the mesh does not cure it (2D Hertz, a soft "
    "half-disk on a stiff block: peak pressure +1 to +2 % at nu = 0.45, +4 % at 0.48, +6 to "
    "+9 % at 0.49 with neighbouring nodes up to 30 % of the peak apart, +40 to +54 % at "
    "0.499, +107 to +206 % at 0.4999). No mixed or locking-free formulation is offered: "
    "where contact pressures matter use nu <= 0.45 (a slightly compressible stand-in for "
    "the material)"
)


def elastic_constants_problem(E: float, nu: float) -> tuple[str, str] | None:
    """Why (E, nu) are not valid isotropic constants: (name, what is wrong), or None.

    The one definition of the rule; materials, scenes and the analytic
    references all ask it.
    """
    if not (math.isfinite(E) and E > 0):
        return "E", "must be finite and > 0."
    if not nu < 0.5:
        return "nu", (
            f"must be < 0.5 (exact incompressibility is not supported); {LOCKING_NOTE}."
        )
    if not nu > -1.0:
        return "nu", "must be > -1."
    return None


def check_elastic_constants(E: float, nu: float) -> None:
    """Raise ValueError naming the bad constant, its value and the fix."""
    problem = elastic_constants_problem(E, nu)
    if problem is not None:
        name, message = problem
        value = E if name == "E" else nu
        raise ValueError(f"{name} = {value}: {message}")


@dataclass(frozen=True)
class Elastic:
    """Isotropic elastic constants shared by every law.

    Attributes:
        E: Young's modulus (stress units).
        nu: Poisson's ratio, -1 < nu < 0.5.
    """

    E: float
    nu: float

    def __post_init__(self) -> None:
        check_elastic_constants(self.E, self.nu)

    @property
    def mu(self) -> float:
        """Shear modulus."""
        return self.E / (2.0 * (1.0 + self.nu))

    @property
    def lmbda(self) -> float:
        """First Lame parameter (3D value; plane strain uses it as it is)."""
        return self.E * self.nu / ((1.0 + self.nu) * (1.0 - 2.0 * self.nu))

    @property
    def plane_strain_modulus(self) -> float:
        """E* = E / (1 - nu^2), the modulus of Hertz theory against a rigid body."""
        return self.E / (1.0 - self.nu**2)

    #: Whether the law is geometrically nonlinear (finite strain).
    finite_strain: bool = True

    def energy(self, H: ufl.core.expr.Expr, moduli: Moduli | None = None) -> ufl.core.expr.Expr:
        """Stored energy density as a function of the displacement gradient H (d x d).

        With d = 2 the body is in plane strain (out-of-plane stretch one).
        ``moduli``: (mu, lmbda) as UFL expressions (e.g. constants, so that the
        compiled forms do not depend on their values); default the law's own.
        """
        raise NotImplementedError

    def moduli(self, moduli: Moduli | None = None) -> Moduli:
        """(mu, lmbda): the ones given, else the law's own values."""
        return (self.mu, self.lmbda) if moduli is None else moduli

    def strain_energy(self, u: ufl.core.expr.Expr,
                      moduli: Moduli | None = None) -> ufl.core.expr.Expr:
        """Stored energy density psi(u) per unit reference volume."""
        return self.energy(ufl.grad(u), moduli)

    def cauchy_stress(self, u: ufl.core.expr.Expr,
                      moduli: Moduli | None = None) -> ufl.core.expr.Expr:
        """Cauchy stress (3 x 3, out-of-plane component included in plane strain).

        Obtained as sigma = (1/J) P F^T with P = d psi / d H; the small-strain
        law returns P itself.
        """
        H = ufl.variable(_embed_3d(ufl.grad(u)))
        P = ufl.diff(self.energy(H, moduli), H)
        if not self.finite_strain:
            return P
        F = ufl.Identity(3) + H
        return P * F.T / ufl.det(F)


def _embed_3d(H: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
    """A 2 x 2 plane-strain displacement gradient as a 3 x 3 one (3D: unchanged)."""
    if H.ufl_shape == (3, 3):
        return H
    return ufl.as_matrix([[H[0, 0], H[0, 1], 0], [H[1, 0], H[1, 1], 0], [0, 0, 0]])


def von_mises(sigma: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
    """Von Mises equivalent stress sqrt(3/2 s:s) of a 3 x 3 stress."""
    s = ufl.dev(sigma)
    return ufl.sqrt(1.5 * ufl.inner(s, s))


@dataclass(frozen=True)
class SaintVenantKirchhoff(Elastic):
    """psi = lmbda/2 (tr E)^2 + mu E:E with the Green-Lagrange strain E (the paper's law)."""

    def energy(self, H: ufl.core.expr.Expr, moduli: Moduli | None = None) -> ufl.core.expr.Expr:
        """Stored energy density."""
        mu, lmbda = self.moduli(moduli)
        d = H.ufl_shape[0]
        F = ufl.Identity(d) + H
        Egl = 0.5 * (F.T * F - ufl.Identity(d))
        return 0.5 * lmbda * ufl.tr(Egl) ** 2 + mu * ufl.inner(Egl, Egl)


@dataclass(frozen=True)
class NeoHookean(Elastic):
    """Compressible neo-Hookean: psi = mu/2 (I1 - 3) - mu ln J + lmbda/2 (ln J)^2.

    In plane strain I1 = tr(C) + 1 (the out-of-plane stretch is one).
    """

    def energy(self, H: ufl.core.expr.Expr, moduli: Moduli | None = None) -> ufl.core.expr.Expr:
        """Stored energy density."""
        mu, lmbda = self.moduli(moduli)
        d = H.ufl_shape[0]
        F = ufl.Identity(d) + H
        lnJ = ufl.ln(ufl.det(F))
        I1 = ufl.tr(F.T * F) + (3 - d)
        return 0.5 * mu * (I1 - 3) - mu * lnJ + 0.5 * lmbda * lnJ**2


@dataclass(frozen=True)
class LinearElastic(Elastic):
    """Small-strain linear elasticity: psi = lmbda/2 (tr eps)^2 + mu eps:eps.

    Used for validation against Hertz theory. The contact gap is still
    evaluated at x = X + u (exact for the small loads of those checks).
    """

    finite_strain: bool = False

    def energy(self, H: ufl.core.expr.Expr, moduli: Moduli | None = None) -> ufl.core.expr.Expr:
        """Stored energy density."""
        mu, lmbda = self.moduli(moduli)
        eps = ufl.sym(H)
        return 0.5 * lmbda * ufl.tr(eps) ** 2 + mu * ufl.inner(eps, eps)


MATERIALS: dict[str, type[Elastic]] = {
    "svk": SaintVenantKirchhoff,
    "saint-venant-kirchhoff": SaintVenantKirchhoff,
    "neo-hookean": NeoHookean,
    "neohookean": NeoHookean,
    "linear": LinearElastic,
}


def material(name: str, E: float, nu: float) -> Elastic:
    """Build a law by name ('svk', 'neo-hookean' or 'linear'; any case).

    E: Young's modulus (stress, any consistent units); nu: Poisson's ratio
    (-1 < nu < 0.5). In 2D the laws are plane strain.
    """
    try:
        cls = MATERIALS[name.lower()]
    except KeyError:
        raise ValueError(
            f"Unknown material law {name!r}; choose one of 'svk', 'neo-hookean', 'linear'."
        ) from None
    return cls(E=E, nu=nu)
