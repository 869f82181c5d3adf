"""The friction of a problem's frictional contacts, seen as one.

:class:`FrictionalContacts` is a part of :class:`~.problem.ContactProblem`:
the accessors solvers and output use for friction, over every contact that
has a Coulomb coefficient. Single values (lam_t, mu, r_t) are those of the
first frictional contact; fields and forces join or sum over all of them.
"""

from __future__ import annotations

import numpy as np
from dolfinx import fem

from fenics_contact.model.contacts import Contact
from fenics_contact.model.residuals import frictions


class FrictionalContacts:
    """Friction accessors over ``self.contacts`` (a part of the contact problem)."""

    contacts: list[Contact]

    def _friction(self) -> list:
        """Every frictional contact's friction; raises when there is none."""
        frictional = frictions(self.contacts)
        if not frictional:
            raise AttributeError("The problem has no frictional contact.")
        return frictional

    @property
    def lam_t(self) -> fem.Function:
        """The first frictional contact's tangential multiplier."""
        return self._friction()[0].lam_t

    @property
    def mu(self) -> fem.Constant:
        """The first frictional contact's friction coefficient (a Constant)."""
        return self._friction()[0].mu

    @property
    def friction_coefficient(self) -> float:
        """The first frictional contact's mu (dimensionless)."""
        return float(self.mu.value)

    def friction_coefficients(self) -> dict[str, float]:
        """Each frictional contact's mu by the contact's name (empty without friction)."""
        return {c.name: float(c.friction_settings.mu) for c in self.contacts
                if c.friction is not None}

    def frictional_states(self) -> list:
        """The contact state (with stick/slip) of every frictional contact (collective)."""
        return [c.contact_state() for c in self.contacts if c.friction is not None]

    @property
    def contact_extent(self) -> float:
        """Extent L of the first frictional contact's surface (length)."""
        return self._friction()[0].contact_extent

    @property
    def symmetry_constraints(self) -> int:
        """Tangential components held at 0 by symmetry planes, over every contact."""
        return sum(f.symmetry_constraints for f in self._friction())

    def _frictions(self) -> list:
        """Every frictional contact's friction (empty when there is none)."""
        return frictions(self.contacts)

    @property
    def tangential_r(self) -> float:
        """The first frictional contact's r_t (stress per length)."""
        return self._friction()[0].tangential_r

    @property
    def tangential_cap(self) -> float:
        """The first frictional contact's cap of r_t (stress per length)."""
        return self._friction()[0].tangential_cap

    def set_tangential_cap(self, cap: float) -> None:
        """Set the cap of r_t of every frictional contact (absolute, stress per length)."""
        for f in self._friction():
            f.set_tangential_cap(cap)

    def lower_tangential_r(self, factor: float = 0.5) -> float:
        """Cap r_t at ``factor`` times its current value on every frictional contact.

        The converged nodal answer does not depend on r_t; a smaller r_t keeps
        the stick/slip guess from flipping (see :mod:`.friction`). Returns the
        first frictional contact's new r_t (stress per length).
        """
        for f in self._friction():
            f.set_tangential_cap(factor * f.tangential_r)
        return self.tangential_r

    def tangential_fields(self) -> tuple[np.ndarray, np.ndarray]:
        """Owned nodal tangential traction on the body and slip, global axes (joined)."""
        pairs = [f.tangential_fields() for f in self._friction()]
        return (np.concatenate([p[0] for p in pairs]), np.concatenate([p[1] for p in pairs]))

    def tangential_force_vector(self) -> np.ndarray:
        """Sum over the frictional contacts of int T tau dA (force): minus the friction."""
        return sum(f.tangential_force_vector() for f in self._friction())

    def node_states(self) -> np.ndarray:
        """Per owned node of the frictional contacts: 0 open, 1 stick, 2 slip."""
        return np.concatenate([f.node_states() for f in self._friction()])

    def coulomb_violations(self) -> tuple[float, float, float]:
        """Worst nodal violations of the Coulomb conditions over every frictional contact."""
        worst = [f.coulomb_violations() for f in self._friction()]
        return tuple(max(w[i] for w in worst) for i in range(3))

    def complementarity_norms(self) -> tuple[float, float]:
        """Euclidean norms of the normal and tangential complementarity residuals (force)."""
        squares = [f.complementarity_squares() for f in self._friction()]
        return (float(np.sqrt(sum(s[0] for s in squares))),
                float(np.sqrt(sum(s[1] for s in squares))))


__all__ = ["FrictionalContacts"]
