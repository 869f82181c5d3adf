"""AUTO: generalized Newton that converges for any r, with its own fallbacks.

Plain GNRM fails at extreme r for two reasons, both measured on the
Example 2 analog: the complementarity residual min(lam + r g, 0) - lam
multiplies every gap error by r, so an active-set change in the first
Newton step makes the residual jump by ~r (the divergence test fires at
r >= 1e8 E/h), and the round-off floor eps * r * g_scale of that residual
exceeds any fixed tolerance (see :mod:`fenics_contact.model.scaling`).

This strategy

1. works at an internal r inside ``AutoSettings.r_window`` (relative to
   E/h): with the nodal (vertex) rule the Alart-Curnier solution is the
   nodal Signorini solution whatever r > 0, so clamping r changes the
   iterates' conditioning, not the answer. With Gauss quadrature the
   solution depends on r, so it climbs from the window to the user's r by
   continuation (factor ``continuation_factor`` a rung), warm-starting each
   rung from the last;
2. runs each rung as plain GNRM (identical iterates to ``gnrm`` when the
   user's r is inside the window); with the nodal rule, if that fails it
   restarts the rung with plain GNRM at working r lowered by
   ``continuation_factor`` (down to the window's bottom), and the r that
   converges caps the working r of the later solves (the window follows
   what was measured on the problem); if that fails too it restarts it with
   a line-searched GNRM (backtracking on the residual norm, non-monotone
   over the last three residuals), with friction retried with r_t halved
   when that cycles, and if that fails too it warm-starts
   from a penalty solution (lam = min(r g, 0)) and runs the line search
   again;
3. never demands less than the round-off floor: each rung's tolerance is
   max(atol, floor at that rung's r); with the nodal rule it finally records
   the residual at the user's r against max(atol, floor at the user's r)
   (the working-r answer is the answer at every r; Newton at a huge r would
   only amplify the gaps' round-off).

Every decision is appended to ``SolveResult.switches``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from dolfinx.fem import petsc as fem_petsc

from fenics_contact.model.problem import ContactProblem, ProblemState, VariationalSystem
from fenics_contact.model.scaling import residual_floor
from fenics_contact.solvers.base import (
    NewtonStrategy,
    Observer,
    SolveResult,
    force_measure,
    newton_loop,
    retry_lowering_r_t,
    timed,
)
from fenics_contact.solvers.condensed import kernel_for
from fenics_contact.solvers.diagnostics import (
    ConvergenceMonitor,
    SolverSettings,
    Status,
    admissibility,
)
from fenics_contact.solvers.newton import NewtonKernel


@dataclass(frozen=True)
class AutoSettings:
    """Knobs of the automatic strategy.

    Attributes:
        r_window: (low, high) range of the working r, relative to E/h (nodal
            rule). Measured on the two cylinders (node-to-segment, 10 steps):
            plain GNRM takes 30 Newton iterations at r <= 1 E/h and 89 at
            1e2 E/h (a step cycles for 38 iterations), so the top is 1 E/h.
        gauss_start: highest r (relative to E/h) at which the Gauss-rule
            continuation starts (its answer depends on r; fewer rungs from higher).
        continuation_factor: r ratio between continuation rungs (Gauss rule), and
            the factor by which the working r is lowered after a failure (nodal rule).
        min_damping: smallest line-search step length tried.
        armijo: sufficient-decrease constant of the line search.
        nonmonotone: residuals the line search compares against (their max).
        tangential_halvings: with friction, halvings of r_t tried (line-searched
            GNRM from the rung's start) when the line search cycles or reaches
            the iteration limit, before the penalty warm start.
    """

    r_window: tuple[float, float] = (1e-2, 1.0)
    gauss_start: float = 1e2
    continuation_factor: float = 100.0
    min_damping: float = 1.0 / 64.0
    armijo: float = 1e-4
    nonmonotone: int = 3
    tangential_halvings: int = 2


@dataclass
class _Tally:
    """Counters and histories accumulated over the stages of one solve."""

    iterations: int = 0
    residuals: list[float] | None = None
    switches: list[str] | None = None

    def __post_init__(self) -> None:
        self.residuals = []
        self.switches = []


class AutoStrategy(NewtonStrategy):
    """GNRM at a well-scaled internal r, with line search and penalty warm start."""

    name = "auto"
    tuning_type = AutoSettings
    tuning: AutoSettings
    #: The penalty kernel of the warm start, built the first time it is needed.
    _penalty: NewtonKernel | None = None

    def build_system(self, problem: ContactProblem) -> VariationalSystem:
        """The Alart-Curnier system, as for GNRM."""
        return problem.augmented_system()

    # -- public ------------------------------------------------------------------
    def solve(self) -> SolveResult:
        """Solve at the problem's current load; the problem's r is left unchanged."""
        return timed(self._solve)

    #: The highest working r (relative to E/h) at which plain GNRM has not failed in
    #: this problem: the window's top until a failure there lowers it (nodal rule).
    _r_cap: float | None = None

    @property
    def r_cap(self) -> float | None:
        """The top of the working r's window that this problem's failures set (E/h; None: none).

        Kept along the path; a resumed run sets it from its checkpoint so
        that its solves start at the r the uninterrupted run's would.
        """
        return self._r_cap

    @r_cap.setter
    def r_cap(self, value: float | None) -> None:
        self._r_cap = None if value is None else float(value)

    def working_r(self) -> float:
        """The user's r clamped to the window (absolute, stress per length).

        With the nodal rule the top of the window follows what was measured:
        once plain GNRM failed at a working r and succeeded at a lower one
        (:meth:`_lower_r`), later solves start at the lower one.
        """
        scale = self.problem.stiffness_scale
        low, high = (w * scale for w in self.tuning.r_window)
        if not self.problem.nodal_rule:
            high = max(high, self.tuning.gauss_start * scale)
        elif self._r_cap is not None:
            high = min(high, self._r_cap * scale)
        return min(max(self.problem.r_absolute, low), high)

    def rungs(self) -> list[float]:
        """The r values solved in turn (absolute); the last one decides the answer."""
        r_user = self.problem.r_absolute
        r_work = self.working_r()
        if self.problem.nodal_rule or r_user <= r_work:
            return [r_work]
        count = math.ceil(math.log(r_user / r_work) / math.log(self.tuning.continuation_factor))
        return [*np.geomspace(r_work, r_user, count + 1)[:-1].tolist(), r_user]

    # -- the solve -----------------------------------------------------------------
    def _solve(self) -> SolveResult:
        p = self.problem
        r_user = p.r_absolute
        tally = _Tally()
        solves_before = self._linear_solves()
        status = Status.CONVERGED
        try:
            rungs = self.rungs()
            if rungs[0] != r_user:
                kind = "rescale" if len(rungs) == 1 else "continuation from"
                tally.switches.append(
                    f"{kind} r: {r_user:.3g} -> {rungs[0]:.3g} "
                    f"({rungs[0] / p.stiffness_scale:.3g} E/h)"
                )
            for r in rungs:
                p.rescale_r(r)
                status = self._rung(tally, r_user)
                if status is not Status.CONVERGED:
                    break
            if status is Status.CONVERGED and p.r_absolute != r_user:
                self._check_user_r(r_user, tally)
        finally:
            p.rescale_r(r_user)
        return SolveResult(
            status, tally.iterations, 0, self._linear_solves() - solves_before,
            tally.residuals, switches=tally.switches,
        )

    def _rung(self, tally: _Tally, r_user: float) -> Status:
        """Solve at the current r: GNRM (at lower working r too), line search, penalty start."""
        p = self.problem
        saved = p.snapshot()
        settings = self._stage_settings(r_user)
        status = self._newton(settings, tally, line_search=False)
        if status is Status.CONVERGED:
            return status
        if p.nodal_rule:
            status = self._lower_r(saved, tally, r_user, status)
            if status is Status.CONVERGED:
                return status
            settings = self._stage_settings(r_user)
        tally.switches.append(f"gnrm {status.value} at r = {p.r_absolute:.3g}: line search")
        self._restore(saved)
        status = self._newton(settings, tally, line_search=True)
        status = retry_lowering_r_t(
            p, saved, status, lambda: self._newton(settings, tally, line_search=True),
            self.tuning.tangential_halvings, tally.switches, "line search",
        )
        if status is Status.CONVERGED:
            return status
        tally.switches.append(f"line search {status.value}: penalty warm start")
        self._restore(saved)
        if not self._penalty_start(settings, tally):
            tally.switches.append("penalty warm start failed")
            self._restore(saved)
        return self._newton(settings, tally, line_search=True)

    def _lower_r(self, saved: ProblemState, tally: _Tally, r_user: float,
                 status: Status) -> Status:
        """Nodal rule: plain GNRM again from the rung's start at a lower working r.

        r is lowered by the continuation factor, down to the window's bottom; the r
        that converges becomes the top of the window for later solves. Ends at the
        lowest r tried when none converges.
        """
        p = self.problem
        scale = p.stiffness_scale
        low = self.tuning.r_window[0] * scale
        while p.r_absolute > low * (1 + 1e-12):
            r_failed = p.r_absolute
            r_next = max(r_failed / self.tuning.continuation_factor, low)
            tally.switches.append(
                f"gnrm {status.value} at r = {r_failed:.3g}: lower the working r to "
                f"{r_next:.3g} ({r_next / scale:.3g} E/h)"
            )
            self._restore(saved)
            p.rescale_r(r_next)
            status = self._newton(self._stage_settings(r_user), tally, line_search=False)
            if status is Status.CONVERGED:
                self._r_cap = r_next / scale
                return status
        return status

    def _check_user_r(self, r_user: float, tally: _Tally) -> None:
        """Nodal rule: evaluate the residual at the user's r against its floor (a record only).

        With the vertex rule the Alart-Curnier solution is the nodal Signorini
        solution whatever r > 0, and the working-r solve already met the
        user's tolerance scaled by r_work / r_user (:meth:`_stage_settings`),
        so its answer is kept whatever this check reads. Above the floor the
        residual at a huge r is the gaps' round-off times r (a mortar weighted
        gap sums segment integrals and carries more than eps g_scale); Newton
        at that r only amplifies it: polishing there once turned a right
        step into one whose supports no longer balanced (1.42 against 1.37)
        and another into lam = 0 with 0.8 carried by the supports.
        """
        p = self.problem
        p.rescale_r(r_user)
        norm = self.kernel.assemble_residual()
        tolerance = self._stage_settings(r_user).atol
        verdict = (f"<= {tolerance:.2e}" if norm <= tolerance else
                   f"> {tolerance:.2e} (round-off times r; the working-r answer stands)")
        tally.switches.append(f"check at user r = {r_user:.3g}: residual {norm:.2e} {verdict}")

    # -- stages ----------------------------------------------------------------------
    def _stage_settings(self, r_user: float) -> SolverSettings:
        """The user's settings with atol made to pass the test at ``r_user``.

        At the user's r the tolerance is max(atol, floor(r_user)). A gap error
        e costs r e A in the residual, so at a smaller working r the same
        guarantee needs the tolerance scaled by r / r_user, but never below the
        floor at the working r.
        """
        p = self.problem
        target = max(self.settings.atol, residual_floor(p, r_user))
        ratio = min(1.0, p.r_absolute / r_user)
        return replace(self.settings, atol=max(target * ratio, residual_floor(p)))

    def _newton(self, settings: SolverSettings, tally: _Tally, *, line_search: bool) -> Status:
        """Newton on the Alart-Curnier system, plain or with backtracking."""
        monitor = ConvergenceMonitor(
            settings, observer=self._progress(tally),
            admissible=admissibility(self.problem, settings),
            force=force_measure(self.kernel, self.problem),
        )
        if line_search:
            status, steps = self._line_search_loop(self.kernel, monitor)
        else:
            status, steps = newton_loop(
                self.kernel, monitor, self.kernel.assemble_residual,
                self.problem.active_signature,
            )
        tally.iterations += steps
        tally.residuals.extend(monitor.residuals)
        return status

    def _line_search_loop(
        self, kernel: NewtonKernel, monitor: ConvergenceMonitor
    ) -> tuple[Status, int]:
        """Damped Newton: halve the step until the residual norm decreases enough."""
        a = self.tuning
        steps = 0
        kernel.begin_solve()
        norm = kernel.assemble_residual()
        while True:
            status = monitor.check(norm, self.problem.active_signature(), iterations=steps)
            if status is not None:
                return status, steps
            start = kernel.x.copy()
            step = None
            try:
                if not kernel.newton_step(tolerance=monitor.tolerance()):
                    return monitor.fail(), steps
                steps += 1
                reference = max(monitor.residuals[-a.nonmonotone :])
                damping = 1.0
                norm = kernel.assemble_residual()
                # the step actually taken: x_new - x_start (the exact contact set moves the
                # multipliers of its candidates before the step, so it is not -dx there)
                step = kernel.x.copy()
                step.axpy(-1.0, start)
                while not norm <= (1.0 - a.armijo * damping) * reference:
                    if damping <= a.min_damping:
                        break
                    damping /= 2.0
                    kernel.x.waxpy(damping, step, start)
                    self._push(kernel)
                    norm = kernel.assemble_residual()
            finally:
                start.destroy()
                if step is not None:
                    step.destroy()

    def _penalty_start(self, settings: SolverSettings, tally: _Tally) -> bool:
        """Penalty solve at the current r, then lam = min(r g, 0); True on success."""
        p = self.problem
        if self._penalty is None:
            self._penalty = kernel_for(p.penalty_system(), linear=self.linear)
        for lam in p.normal_multipliers():
            lam.x.array[:] = 0.0
        monitor = ConvergenceMonitor(
            replace(settings, rtol=max(settings.rtol, 1e-6)), observer=self._progress(tally),
            force=force_measure(self._penalty, p),
        )
        status, steps = self._line_search_loop(self._penalty, monitor)
        tally.iterations += steps
        tally.residuals.extend(monitor.residuals)
        if status is not Status.CONVERGED:
            return False
        p.update_multiplier()
        return True

    # -- helpers -----------------------------------------------------------------------
    def _progress(self, tally: _Tally) -> Observer | None:
        """The observer, told the iterations of the whole solve (all stages)."""
        if self.observer is None:
            return None
        observer, offset = self.observer, tally.iterations
        return lambda iterations, residual: observer(offset + iterations, residual)

    def _restore(self, saved: ProblemState) -> None:
        self.problem.restore(saved, load=False)

    @staticmethod
    def _push(kernel: NewtonKernel) -> None:
        """Copy the kernel's work vector into its unknowns (ghosts updated)."""
        fem_petsc.assign(kernel.x, kernel.unknowns)
        for u in kernel.unknowns:
            u.x.scatter_forward()

    def _linear_solves(self) -> int:
        extra = self._penalty.linear_solves if self._penalty is not None else 0
        return self.kernel.linear_solves + extra
