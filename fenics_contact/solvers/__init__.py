"""Solution strategies over one Newton kernel; each strategy is one module."""

from __future__ import annotations

from dataclasses import replace

from fenics_contact.model.problem import ContactProblem
from fenics_contact.solvers.auto import AutoStrategy
from fenics_contact.solvers.base import Observer, SolveResult, Strategy
from fenics_contact.solvers.complementarity import ExactContactSet
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.gnrm import GeneralizedNewton
from fenics_contact.solvers.linear import LinearSolverSettings
from fenics_contact.solvers.nua import NestedUzawa
from fenics_contact.solvers.penalty import Penalty
from fenics_contact.solvers.predictor import ActiveSetPredicted, Extrapolated
from fenics_contact.solvers.sua import SimultaneousUzawa

#: The solution strategies by name: penalty, simultaneous and nested Uzawa (sua, nua),
#: the generalized Newton method on both unknowns (gnrm) and auto (GNRM at a working r
#: in the measured window, with line search and fallbacks); see docs/formulation.md.
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


#: How a load step is started: from the last converged state, extrapolated, or
#: extrapolated with the first iteration's contact set chosen from the gaps' history.
PREDICTORS = ("previous", "extrapolate", "active-set")

#: How each Newton step chooses its contact set: the sign of lam + r g at the
#: iterate, or the exact set of the step's linear model.
CONTACT_SETS = ("sign", "exact")


def make_strategy(
    name: str,
    problem: ContactProblem,
    settings: SolverSettings,
    *,
    linear: LinearSolverSettings | None = None,
    observer: Observer | None = None,
    predictor: str = "previous",
    contact_set: str = "sign",
) -> Strategy:
    """Build the strategy called ``name`` for ``problem``, fully configured.

    Args:
        name: one of :data:`STRATEGIES`.
        problem: the problem it solves (its current state is the start).
        settings: stopping rules.
        linear: linear solver of every Newton kernel the strategy uses
            (direct MUMPS when None). Where contacts share nodes, null-pivot
            detection is switched on (see :class:`LinearSolverSettings`).
        observer: called with (iterations, residual) at every residual check.
        predictor: 'previous' starts each load step from the last converged
            state; 'extrapolate' from the linear extrapolation of the last two;
            'active-set' also chooses the contact set of the first iteration
            (:class:`~fenics_contact.solvers.predictor.ActiveSetPredicted`).
        contact_set: 'sign' takes each Newton step's contact set from the sign
            of lam + r g at the iterate (the paper's GNRM); 'exact' solves the
            step's linear complementarity problem with the step's
            factorisation (:class:`~fenics_contact.solvers.complementarity.ExactContactSet`;
            frictionless vertex-rule contacts of a multiplier kernel with a
            direct solver, the sign rule elsewhere). The answer is the same.
    """
    if not isinstance(settings, SolverSettings):
        raise TypeError(f"settings = {settings!r}: give a SolverSettings (stopping rules), e.g. "
                        "SolverSettings(atol=1e-10), or a scene's scene.solver.")
    try:
        cls = STRATEGIES[name]
    except KeyError:
        raise ValueError(
            f"Unknown method {name!r}; choose one of {', '.join(STRATEGIES)}."
        ) from None
    if predictor not in PREDICTORS:
        raise ValueError(f"Unknown predictor {predictor!r}; choose one of {', '.join(PREDICTORS)}.")
    if contact_set not in CONTACT_SETS:
        raise ValueError(f"Unknown contact_set {contact_set!r}; choose one of "
                         f"{', '.join(CONTACT_SETS)}.")
    if problem.shared_contact_nodes:  # contacts meet at nodes: equal rows are possible
        linear = replace(linear or LinearSolverSettings(), null_pivots=True)
    strategy: Strategy = cls(problem, settings, linear=linear, observer=observer)
    if contact_set == "exact":
        exact = ExactContactSet(problem, strategy.kernel)  # type: ignore[attr-defined]
        if exact.usable:
            strategy.kernel.complementarity = exact  # type: ignore[attr-defined]
    if predictor == "active-set":
        return ActiveSetPredicted(strategy)
    return Extrapolated(strategy) if predictor == "extrapolate" else strategy


__all__ = ["CONTACT_SETS", "PREDICTORS", "STRATEGIES", "SolveResult", "Strategy", "make_strategy"]
