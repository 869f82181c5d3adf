"""Residual blocks from an energy and the contacts' friction work.

The energies are the potential Pi of a solid plus each contact's term:
the augmented Lagrangian (paper eq. 9) or the penalty (paper eq. 7).
:func:`energy_system` differentiates one into the blocks of a
:class:`~.variational_system.VariationalSystem`: u, every contact's lam,
every frictional contact's lam_t, then the deformable targets' extras.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import ufl
from dolfinx import fem

from fenics_contact.model.contacts import Contact
from fenics_contact.model.variational_system import Transfers, VariationalSystem, jit_options


def frictions(contacts: Sequence[Contact]) -> list:
    """The friction of every frictional contact, in the order of the contacts."""
    return [c.friction for c in contacts if c.friction is not None]


def contact_entity_maps(contacts: Sequence[Contact]) -> list:
    """The entity maps of every contact submesh (for forms on them)."""
    return [m for c in contacts for m in c.surface.entity_maps]


def lagrangian(potential: ufl.Form, contacts: Sequence[Contact]) -> ufl.Form:
    """Pi + sum over the contacts of int AL density ds (paper eq. 9)."""
    form = potential
    for c in contacts:
        form = form + c.lagrangian()
    return form


def penalty_energy(potential: ufl.Form, contacts: Sequence[Contact]) -> ufl.Form:
    """Pi + sum over the contacts of int r/2 min(g, 0)^2 ds (paper eq. 7)."""
    form = potential
    for c in contacts:
        form = form + c.penalty()
    return form


def energy_system(
    name: str,
    energy: ufl.Form,
    u: fem.Function,
    bcs: list[fem.DirichletBC],
    contacts: Sequence[Contact],
    *,
    with_lam: bool,
    tangential: Callable | None = None,
    supports: Callable | None = None,
) -> VariationalSystem:
    """Residual blocks from an energy plus the friction work.

    The residual of u (and of each extra coefficient c) is
    dE/dc[test] + sum over frictional contacts of tau . d(dg_t)/dc[test],
    tau = ``tangential(friction)``; with ``with_lam`` every contact's
    multiplier block r dE/dlam[mu] (force units) follows u, then every
    frictional contact's tangential block, before the extras' blocks.
    """
    frictional = frictions(contacts)

    def residual(c: fem.Function) -> ufl.Form:
        test = ufl.TestFunction(c.function_space)
        form = ufl.derivative(energy, c, test)
        if tangential is not None:
            for f in frictional:
                form += f.work(tangential(f), c, test)
        return form

    residuals = [residual(u)]
    unknowns = [u]
    if with_lam:
        for c in contacts:
            residuals.append(c.r * ufl.derivative(energy, c.lam, ufl.TestFunction(c.Q)))
            unknowns.append(c.lam)
        for f in frictional:
            residuals.append(f.tangential_residual())
            unknowns.append(f.lam_t)
    extras = [w for c in contacts for w in c.extras()]
    residuals += [residual(w) for w in extras]
    transfers = [c.transfer for c in contacts if c.transfer is not None]
    transfer = None
    if extras:
        transfer = transfers[0] if len(transfers) == 1 else Transfers(transfers)
    return VariationalSystem(name, residuals, unknowns, bcs, contact_entity_maps(contacts),
                             extras=extras, transfer=transfer, jit_options=jit_options(contacts),
                             supports=supports)


def complementarity_forms(contacts: Sequence[Contact]) -> list[ufl.Form]:
    """(min(lam + r g, 0) - lam) mu per contact, then the tangential ones (force units)."""
    forms = [c.complementarity_residual() for c in contacts]
    return forms + [f.tangential_residual() for f in frictions(contacts)]


__all__ = [
    "complementarity_forms", "contact_entity_maps", "energy_system", "frictions", "lagrangian",
    "penalty_energy",
]
