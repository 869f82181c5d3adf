"""Solution strategies over one Newton kernel; each strategy is one module."""

from __future__ import annotations

from fenics_contact.model.problem import ContactProblem
from fenics_contact.solvers.auto import AutoStrategy
from fenics_contact.solvers.base import SolveResult, Strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.gnrm import GeneralizedNewton
from fenics_contact.solvers.nua import NestedUzawa
from fenics_contact.solvers.penalty import Penalty
from fenics_contact.solvers.sua import SimultaneousUzawa

STRATEGIES: dict[str, type] = {
    "penalty": Penalty,
    "sua": SimultaneousUzawa,
    "nua": NestedUzawa,
    "gnrm": GeneralizedNewton,
    "auto": AutoStrategy,
}

#: Names the paper uses in its tables.
PAPER_NAMES = {
    "penalty": "Penalty",
    "sua": "Simultaneous Uzawa",
    "nua": "Nested Uzawa",
    "gnrm": "GNRM",
    "auto": "Auto",
}


def make_strategy(name: str, problem: ContactProblem, settings: SolverSettings) -> Strategy:
    """Build the strategy called ``name`` for ``problem``."""
    try:
        cls = STRATEGIES[name]
    except KeyError:
        raise ValueError(
            f"Unknown method {name!r}; choose one of {', '.join(STRATEGIES)}."
        ) from None
    return cls(problem, settings)  # type: ignore[no-any-return]


__all__ = ["STRATEGIES", "SolveResult", "Strategy", "make_strategy"]
