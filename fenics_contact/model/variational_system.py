"""What a solver is handed: residual blocks, their unknowns and their conditions.

A :class:`VariationalSystem` is plain data (UFL forms and DOLFINx objects);
:mod:`.residuals` builds them from a problem's energies and
:class:`~.problem.ContactProblem` names them (augmented, primal, penalty).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
import ufl
from dolfinx import fem

#: A non-potential residual term: (coefficient, test function) -> form (or None).
Work = Callable[[fem.Function, ufl.Argument], ufl.Form]


@dataclass
class VariationalSystem:
    """Residual blocks F_i(unknowns; tests) = 0 and what a solver needs to compile them.

    Systems with deformable targets add ``extras``: coefficients (the target
    vertex displacements w_k) that are a selection of ``unknowns[0]``
    (w_k = S_k u), with one more residual block each after the unknowns'
    blocks; ``transfer`` refreshes them (search) and names the selected
    blocks (``sources()``, ``version``), or, for extras that are functions
    of u rather than selections, gives their derivative (``condensation()``)
    and second-derivative term (``curvature()``). A solver condenses them away
    (solvers/condensed.py).
    """

    name: str
    residuals: list[ufl.Form]
    unknowns: list[fem.Function]
    bcs: list[fem.DirichletBC]
    entity_maps: list = field(default_factory=list)
    extras: list[fem.Function] = field(default_factory=list)
    transfer: object | None = None
    #: Options of the forms' just-in-time compilation (None: the defaults); a contact
    #: with very large kernels asks for cheaper C optimisation (see :func:`jit_options`).
    jit_options: dict | None = None
    #: Called by a condensing solver at each residual with (owned u dofs of the Dirichlet
    #: rows, the condensed residual there before the rows are set): the supports' forces
    #: on the bodies, contact at a held node included (:meth:`Solid.support_reactions`).
    supports: Callable[[np.ndarray, np.ndarray], None] | None = None


def jit_options(contacts: Sequence[object]) -> dict | None:
    """The compilation options the contacts ask for (``jit_options`` attribute), merged."""
    merged: dict = {}
    for c in contacts:
        merged.update(getattr(c, "jit_options", None) or {})
    return merged or None


class Transfers:
    """The searches of several deformable contacts seen as one (refresh, version, sources)."""

    def __init__(self, transfers: Sequence[object]) -> None:
        self.transfers = list(transfers)

    def refresh(self) -> bool:
        """Refresh every search; True when some assignment changed."""
        changed = [t.refresh() for t in self.transfers]
        return any(changed)

    @property
    def version(self) -> int:
        """Grows whenever some search changes an assignment."""
        return sum(t.version for t in self.transfers)

    def sources(self) -> list[np.ndarray]:
        """Every contact's selections, in the order of the systems' extras."""
        return [s for t in self.transfers for s in t.sources()]

    def condensation(self) -> list:
        """Every contact's extras as selections (sources) or sparse derivatives, in order."""
        out: list = []
        for t in self.transfers:
            out += list(t.condensation() if hasattr(t, "condensation") else t.sources())
        return out

    def reachable_blocks(self) -> list:
        """Per extra, the V blocks each node may come to select, or None (see pairs)."""
        out: list = []
        for t in self.transfers:
            if hasattr(t, "reachable_blocks"):
                out += list(t.reachable_blocks())
            else:
                items = t.condensation() if hasattr(t, "condensation") else t.sources()
                out += [None] * len(items)
        return out

    def acting_facets(self) -> list[tuple[tuple[int, ...], np.ndarray]]:
        """Every contact's limits of its integrals (see pairs' ``acting_facets``)."""
        return [limit for t in self.transfers if hasattr(t, "acting_facets")
                for limit in t.acting_facets()]

    def curvature(self, residual_of) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The second-derivative terms of the contacts whose extras are not linear in u."""
        parts = [t.curvature(residual_of) for t in self.transfers if hasattr(t, "curvature")]
        if not parts:
            empty = np.zeros(0, np.int64)
            return empty, empty, np.zeros(0)
        return tuple(np.concatenate(p) for p in zip(*parts, strict=True))


__all__ = ["Transfers", "VariationalSystem", "Work", "jit_options"]
