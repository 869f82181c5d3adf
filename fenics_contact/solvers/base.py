"""What a strategy returns and the shared Newton loop."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from fenics_contact.model.problem import ContactProblem, VariationalSystem
from fenics_contact.model.scaling import dirichlet_stiffness
from fenics_contact.solvers.condensed import kernel_for
from fenics_contact.solvers.diagnostics import (
    ConvergenceMonitor,
    SolverSettings,
    Status,
    admissibility,
)
from fenics_contact.solvers.linear import LinearSolverSettings
from fenics_contact.solvers.newton import NewtonKernel


@dataclass
class SolveResult:
    """Outcome of one nonlinear solve (one load increment).

    Attributes:
        status: see :class:`fenics_contact.solvers.diagnostics.Status`.
        iterations: Newton iterations (each one linear solve).
        updates: multiplier updates (Uzawa strategies; 0 otherwise).
        linear_solves: linear systems solved.
        residuals: static residual norm at every check.
        wall_s: wall-clock time of the solve (seconds).
        switches: decisions an adaptive strategy took, in order.
    """

    status: Status
    iterations: int
    updates: int
    linear_solves: int
    residuals: list[float]
    wall_s: float = 0.0
    switches: list[str] = field(default_factory=list)

    @property
    def converged(self) -> bool:
        """True when the status is converged."""
        return self.status is Status.CONVERGED


#: Progress callback: (Newton iterations so far in the solve, residual norm).
Observer = Callable[[int, float], None]


class Strategy(Protocol):
    """A solution strategy bound to one problem."""

    name: str
    problem: ContactProblem
    settings: SolverSettings

    def solve(self) -> SolveResult:
        """Solve at the problem's current load, starting from its current state."""
        ...

    def working_r(self) -> float:
        """The first contact's r the solve works at (absolute; the problem's unless rescaled)."""
        ...


def force_measure(kernel: NewtonKernel, problem: ContactProblem) -> Callable[[float], float]:
    """The force norm of ``kernel``'s last residual for the divergence test (force).

    Its Dirichlet rows weighted by E h^(d-2) of ``problem``
    (:func:`~fenics_contact.model.scaling.dirichlet_stiffness`).
    """
    stiffness = dirichlet_stiffness(problem)
    return lambda norm: kernel.force_norm(norm, stiffness)


def newton_loop(
    kernel: NewtonKernel,
    monitor: ConvergenceMonitor,
    residual_norm: Callable[[], float],
    state: Callable[[], object],
    after_step: Callable[[], None] | None = None,
) -> tuple[Status, int]:
    """Newton iterations until the monitor gives a status.

    ``residual_norm`` assembles the residual the step needs and returns the
    norm used for the stopping test; ``after_step`` runs after each step
    (the simultaneous Uzawa update). Without it a step whose residual is not
    finite is shortened (:func:`_shorten_to_finite`). Returns the status and
    the step count.
    The monitor's tolerance bounds an inexact linear solve's forcing term
    (:meth:`NewtonKernel.newton_step`).
    """
    steps = 0
    kernel.begin_solve()
    norm = residual_norm()
    while True:
        status = monitor.check(norm, state(), iterations=steps)
        if status is not None:
            return status, steps
        if not kernel.newton_step(tolerance=monitor.tolerance()):
            return monitor.fail(), steps
        steps += 1
        if after_step is not None:
            after_step()
            norm = residual_norm()
        else:
            norm = _shorten_to_finite(kernel, residual_norm)


#: Halvings of a Newton step whose residual is not finite (an element turned inside out).
SHORTENINGS = 6


def _shorten_to_finite(kernel: NewtonKernel, residual_norm: Callable[[], float]) -> float:
    """The residual after the last Newton step, halving the step while it is not finite.

    A full step that turns an element inside out (J <= 0: the neo-Hookean
    energy's log J is NaN) is taken back by halves, up to
    :data:`SHORTENINGS` times (1/64 of the step), from the same direction;
    the step lengths are the unknowns' own, so nothing else changes. An
    iterate still not finite after that is returned as it is (the monitor
    fails it).
    """
    norm = residual_norm()
    length = 1.0
    for _ in range(SHORTENINGS):
        if np.isfinite(norm):
            break
        length /= 2.0
        kernel.take_back(length)  # x0 - 2 length dx  ->  x0 - length dx
        norm = residual_norm()
    return norm


#: Failures after which a frictional solve is retried with r_t halved: the
#: stick/slip pattern cycled (or never settled within the iteration limit).
TANGENTIAL_RETRY = (Status.CYCLING, Status.MAX_ITERATIONS)


def retry_lowering_r_t(
    problem: ContactProblem,
    saved: object,
    status: Status,
    attempt: Callable[[], Status],
    halvings: int,
    switches: list[str],
    label: str,
) -> Status:
    """Retry a failed frictional solve from ``saved`` with r_t halved, up to ``halvings`` times.

    Only for problems that can lower r_t (friction) and a ``status`` in
    :data:`TANGENTIAL_RETRY`. ``attempt`` solves from the restored state and
    returns its status; each halving is appended to ``switches``. When every
    attempt fails the cap of r_t is put back (the converged nodal answer does
    not depend on r_t, so a lowered cap is kept only when it helped).
    """
    if not problem.frictional or status not in TANGENTIAL_RETRY:
        return status
    lower = problem.lower_tangential_r  # type: ignore[attr-defined]
    cap = problem.tangential_cap
    for _ in range(halvings):
        problem.restore(saved, load=False)
        r_t = lower()
        switches.append(
            f"{label} {status.value} with friction: r_t halved to {r_t:.3g} "
            f"({r_t / problem.stiffness_scale:.3g} E/h)"
        )
        status = attempt()
        if status not in TANGENTIAL_RETRY:
            break
    if status is not Status.CONVERGED:
        problem.set_tangential_cap(cap)
    return status


def timed(fn: Callable[[], SolveResult]) -> SolveResult:
    """Run a solve and store its wall time in the result."""
    start = time.perf_counter()
    result = fn()
    result.wall_s = time.perf_counter() - start
    return result


class NewtonStrategy:
    """A strategy configured once: problem, stopping rules, linear solver, observer.

    Subclasses say which system their kernel solves (:meth:`build_system`);
    plain Newton on it is :meth:`solve` (GNRM and PM). Strategies that update
    the multiplier between steps override :meth:`residual_norm` and
    :meth:`after_step` (SUA) or :meth:`solve` itself (NUA, auto).

    Args:
        problem: the problem solved; its current state is the start.
        settings: stopping rules.
        linear: linear solver of the Newton kernel (direct MUMPS when None).
        observer: called with (iterations, residual) at every residual check.
        tuning: the strategy's own knobs, an instance of :attr:`tuning_type`
            (its defaults when None; NUA's inner tolerance, auto's r window).
    """

    name = "newton"
    #: True when each step is followed by a multiplier update (counted as updates).
    updates_each_step = False
    #: The class of the strategy's own knobs (a frozen dataclass), None when it has none.
    tuning_type: type | None = None

    def __init__(
        self,
        problem: ContactProblem,
        settings: SolverSettings,
        *,
        linear: LinearSolverSettings | None = None,
        observer: Observer | None = None,
        tuning: object | None = None,
    ) -> None:
        self.problem = problem
        self.settings = settings
        self.linear = linear or LinearSolverSettings()
        self.observer = observer
        if tuning is None and self.tuning_type is not None:
            tuning = self.tuning_type()
        self.tuning = tuning
        self.kernel = kernel_for(self.build_system(problem), linear=self.linear)

    def build_system(self, problem: ContactProblem) -> VariationalSystem:
        """The residual blocks this strategy's kernel solves."""
        raise NotImplementedError

    #: Whether convergence also needs the Signorini conditions in their own
    #: units (False for the penalty method, whose penetration is its regularisation).
    exact_constraint = True

    def monitor(self, settings: SolverSettings | None = None) -> ConvergenceMonitor:
        """A fresh convergence monitor reporting to the observer.

        Converged needs the prescribed displacements to hold and, unless the
        strategy regularises the constraint (penalty), the Signorini (and
        Coulomb) conditions in their own units.
        """
        settings = settings or self.settings
        return ConvergenceMonitor(
            settings, observer=self.observer,
            admissible=admissibility(self.problem, settings,
                                     exact_constraint=self.exact_constraint),
            force=force_measure(self.kernel, self.problem),
        )

    def working_r(self) -> float:
        """The first contact's r the solve works at: the problem's (absolute)."""
        return self.problem.r_absolute

    def residual_norm(self) -> float:
        """The norm the stopping test reads (default: the kernel's residual)."""
        return self.kernel.assemble_residual()

    def after_step(self) -> None:
        """Runs after every Newton step (default: nothing)."""

    def solve(self) -> SolveResult:
        """Newton until the residual norm passes the stopping test."""
        return timed(self._solve)

    def _solve(self) -> SolveResult:
        monitor = self.monitor()
        before = self.kernel.linear_solves
        own_update = type(self).after_step is not NewtonStrategy.after_step
        status, steps = newton_loop(
            self.kernel, monitor, self.residual_norm, self.problem.active_signature,
            after_step=self.after_step if own_update else None,
        )
        updates = steps if self.updates_each_step else 0
        return SolveResult(
            status, steps, updates, self.kernel.linear_solves - before, monitor.residuals
        )

