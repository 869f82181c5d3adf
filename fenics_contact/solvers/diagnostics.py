"""Convergence statuses, iteration histories and the Signorini (KKT) check.

Statuses, with their defined tests (checked in this order each iteration):

- ``diverged``: the residual is NaN/inf, a linear solve failed, or the
  residual exceeds ``divergence_factor`` times the first residual of the solve
  (at least atol). Both are compared as forces: the Dirichlet rows (x - x_D,
  a length) are weighted by a stiffness E h^(d-2)
  (:meth:`~fenics_contact.solvers.newton.NewtonKernel.force_norm`). Unweighted,
  a displacement-driven step starts from a length and continues with forces
  that scale with E: steel in Pa went 0.017 -> 2e6 in one Newton step of a
  linear problem and was "diverged", the same scene at E = 200 converged.
- ``converged``: the residual norm is at most ``max(atol, rtol * first)`` and,
  for strategies that impose the constraint exactly, the Signorini
  conditions hold in their own units (:func:`signorini_admissibility`): no
  nodal penetration beyond ``gap_tol`` times the contact facet size and no
  multiplier tension beyond ``tension_tol`` times E. A small residual alone
  does not suffice: at tiny r the force-scaled complementarity residual
  r g hides a gap. With friction the Coulomb conditions are tested too
  (:func:`coulomb_admissibility`): no slip beyond ``gap_tol`` h at
  sticking nodes, tangential complementarity and Coulomb excess within
  ``tension_tol`` E. For every strategy, penalty included, the prescribed
  displacements must hold to ``gap_tol`` h (:func:`prescribed_admissibility`):
  the Dirichlet rows of the residual hold x - x_D in length units, so at a
  large r, whose round-off floor raises the tolerance, the residual before
  the first Newton step of a displacement-driven step could pass the test
  with the load not applied. Finally every body must be held
  (:func:`hold_admissibility`): a rigid motion that no support holds and
  that moves no contact node closed in the iterate (active, or touching
  within ``gap_tol`` h) leaves the stiffness singular, and the "solution"
  is an arbitrary rigid motion (SUA at r = 1e-3 threw a stack 6 lengths
  clean through the ball pressing it, every contact open, and converged).
- ``cycling``: the residual zigzags between two levels that barely move
  over the last ``cycle_window`` iterations (a 2-cycle whose lower level
  drifts down by a per cent a cycle), or over that window it never
  fell below the smallest value seen before the window, and the active set
  (or, without one, the rounded residual) returned to a state it had left
  within the window (a pattern A -> B -> A).
- ``max_iterations``: the iteration limit was reached (the paper's "> 500").

Load stepping adds two statuses of its own: ``inverted`` (the solve
converged but det F <= 0 somewhere in the body, so the step is refused) and
``error`` (an exception ended the run; studies record it with its message).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Hashable, Sequence
from dataclasses import dataclass, field
from enum import StrEnum

import numpy as np


class Status(StrEnum):
    """Outcome of one nonlinear solve.

    ``converged``: the residual met the tolerance and the answer was admissible
    (prescribed displacements, Signorini, Coulomb); ``cycling``: the contact set
    (or stick/slip pattern) repeats without the residual falling; ``diverged``:
    the residual grew beyond recovery or is not finite; ``max_iterations``: the
    iteration limit was reached; ``inverted``: converged with elements turned
    inside out (det F <= 0); ``held_by_springs``: converged with the weak springs
    of a stabilised body holding more than 1e-2 of the load (the contact that
    should hold it carries nothing); ``error``: an exception (a run record's message says
    which).
    """

    CONVERGED = "converged"
    CYCLING = "cycling"
    DIVERGED = "diverged"
    MAX_ITERATIONS = "max_iterations"
    INVERTED = "inverted"
    HELD_BY_SPRINGS = "held_by_springs"
    ERROR = "error"


#: Every status a run, a step or a study record can carry.
STATUSES = tuple(s.value for s in Status)


@dataclass(frozen=True)
class SolverSettings:
    """Stopping rules shared by every strategy.

    Attributes:
        atol: absolute tolerance on the L2 norm of the static residual (force).
        rtol: tolerance relative to the first residual of the solve (0 disables).
        max_iterations: Newton iterations allowed in one solve (one load step).
        divergence_factor: growth of the residual's force norm over the first
            one (at least atol) that means divergence.
        cycle_window: iterations inspected by the cycling test.
        gap_tol: largest nodal penetration accepted at convergence, relative
            to the contact facet size h (multiplier strategies only).
        tension_tol: largest nodal multiplier tension (lam > 0) accepted at
            convergence, relative to Young's modulus E.
        surface_tol: two deformable bodies: largest depth of a striker node
            inside the actual target surface (closest point over every target
            facet), relative to h. Looser than ``gap_tol``, which holds for the
            constraint the discretisation imposes (the gap to the assigned
            facet's plane): node-to-segment pins a node to one facet, so at a
            concave kink of the deformed target it may sit inside the next
            facet by a discretisation-size amount (measured on the two
            cylinders: 1.8e-6 h); a node visibly inside is refused. The
            assignment's hysteresis (:data:`~..model.search.KEEP` = 0.05 of
            a facet) lets a node at a concave vertex of kink theta lie up to
            0.05 sin(theta) facet sizes inside the next facet: 1e-3 h at 1.1
            degrees (a hole of radius 1 meshed at h = 0.02 was refused), 1e-2 h
            at 11.5 degrees, so 1e-2 h accepts the curved concave targets of
            real meshes and still refuses a node pushed through. The
            end-of-run overlap check warns from the same depth.
    """

    atol: float = 1e-8
    rtol: float = 0.0
    max_iterations: int = 50
    divergence_factor: float = 1e6
    cycle_window: int = 12
    gap_tol: float = 1e-6
    tension_tol: float = 1e-6
    surface_tol: float = 1e-2

    def __post_init__(self) -> None:
        if not (self.atol >= 0 and self.rtol >= 0 and (self.atol > 0 or self.rtol > 0)):
            raise ValueError(
                f"Tolerances must be >= 0 and not both zero (atol={self.atol}, rtol={self.rtol})."
            )
        if self.max_iterations < 1:
            raise ValueError(f"max_iterations must be >= 1, got {self.max_iterations}.")
        if not (self.gap_tol > 0 and self.tension_tol > 0 and self.surface_tol > 0):
            raise ValueError(
                f"gap_tol and tension_tol must be > 0 (gap_tol={self.gap_tol}, "
                f"tension_tol={self.tension_tol})."
            )


@dataclass
class ConvergenceMonitor:
    """Records residuals and active sets of one solve and decides its status."""

    settings: SolverSettings
    #: Called with (Newton iterations so far, residual) at every check (progress display).
    observer: Callable[[int, float], None] | None = None
    #: Called when the residual passes its test: None when the iterate is an
    #: acceptable solution, else the reason it is not (the solve goes on).
    admissible: Callable[[], str | None] | None = None
    #: The last reason ``admissible`` gave for refusing convergence.
    refused: str | None = None
    #: The force norm of a recorded residual (Dirichlet rows weighted by a stiffness,
    #: :meth:`~fenics_contact.solvers.newton.NewtonKernel.force_norm`) for the
    #: divergence test; None: the residual itself.
    force: Callable[[float], float] | None = None
    residuals: list[float] = field(default_factory=list)
    #: The force norm of every recorded residual (force).
    forces: list[float] = field(default_factory=list)
    states: list[Hashable] = field(default_factory=list)
    status: Status | None = None

    iterations: int = 0

    def tolerance(self) -> float:
        """The residual level that counts as converged."""
        first = self.residuals[0] if self.residuals else math.inf
        return max(self.settings.atol, self.settings.rtol * first)

    def check(
        self, residual: float, state: Hashable | None = None, iterations: int | None = None
    ) -> Status | None:
        """Record one residual and active-set state; return a final status or None.

        ``iterations`` is the number of Newton steps taken so far (by default
        the number of residuals recorded before this one).
        """
        self.iterations = len(self.residuals) if iterations is None else iterations
        self.residuals.append(float(residual))
        if self.observer is not None:
            self.observer(self.iterations, float(residual))
        self.states.append(state if state is not None else round(math.log10(residual + 1e-300), 3)
                           if math.isfinite(residual) else None)
        s = self.settings
        finite = math.isfinite(residual)
        self.forces.append(self.force(float(residual)) if finite and self.force is not None
                           else float(residual))
        if not finite:
            self.status = Status.DIVERGED
        elif residual <= self.tolerance() and self._accepted():
            self.status = Status.CONVERGED
        elif self.forces[-1] > s.divergence_factor * max(self.forces[0], s.atol):
            self.status = Status.DIVERGED
        elif self._cycling():
            self.status = Status.CYCLING
        elif self.iterations >= s.max_iterations:
            self.status = Status.MAX_ITERATIONS
        return self.status

    def _accepted(self) -> bool:
        if self.admissible is None:
            return True
        self.refused = self.admissible()
        return self.refused is None

    def fail(self) -> Status:
        """Mark the solve diverged (a linear solve failed)."""
        self.status = Status.DIVERGED
        return self.status

    def _cycling(self) -> bool:
        """No progress over the window and a state that comes back after another.

        The state is the active pattern, and also the pattern with the
        residual (3 digits of its log): the iterates of a pure 2-cycle may
        share one pattern (every node in the same state and slip direction)
        and differ only in where they are, which the residual tells apart.
        """
        w = self.settings.cycle_window
        if len(self.residuals) <= w + 1:
            return False
        before = min(self.residuals[:-w])
        window = self.residuals[-w:]
        if _drifting_two_cycle(window):
            return True
        if min(window) < before:
            return False
        states = self.states[-w:]
        marked = [(state, round(math.log10(r + 1e-300), 3) if math.isfinite(r) else None)
                  for state, r in zip(states, window, strict=True)]
        return _returns(states) or _returns(marked)


#: A zigzag whose two levels differ by more than this factor at every iteration ...
ZIGZAG = 1.5
#: ... and each of which falls by less than this share over the window is a 2-cycle.
DRIFT = 0.3


def _drifting_two_cycle(window: Sequence[float]) -> bool:
    """A residual that alternates between two levels that barely move: a 2-cycle.

    Newton's iterates jump between two states; the lower level may drift down
    by a per cent a cycle, so a new minimum keeps appearing and "no new
    minimum over the window" never fires (a 3D frictional mortar pair at
    r = 10 E/h alternated 1.24e-2 / 1.40e-3 for 48 iterations before it
    escaped by itself). Every residual of the window must sit more than
    ZIGZAG times above both neighbours or below both, and each level must
    fall by less than DRIFT from its first to its last value.
    """
    r = list(window)
    if len(r) < 6 or not all(math.isfinite(v) and v > 0.0 for v in r):
        return False
    for k in range(1, len(r) - 1):
        high = r[k] > ZIGZAG * max(r[k - 1], r[k + 1])
        low = ZIGZAG * r[k] < min(r[k - 1], r[k + 1])
        if not (high or low):
            return False
    return all(level[-1] > (1.0 - DRIFT) * level[0] for level in (r[0::2], r[1::2]))


def _returns(states: Sequence[Hashable]) -> bool:
    """Whether some state comes back after a different one."""
    for i in range(len(states) - 2):
        for j in range(i + 2, len(states)):
            if states[j] == states[i] and any(states[k] != states[i] for k in range(i + 1, j)):
                return True
    return False


#: Iterations over which a residual that neither falls nor leaves the round-off band stalls.
STALL_WINDOW = 8

#: Said of a failure whose residual stalled at the round-off of its forces (the CLI
#: then suggests only a larger atol).
ROUNDOFF_STALL = "the round-off of forces of size"


def roundoff_stall(residuals: Sequence[float], roundoff: float,
                   window: int = STALL_WINDOW) -> float | None:
    """The level the residual stalled at round-off, or None (force units).

    Stalled: over the last ``window`` residuals none is above ``roundoff``
    (the residual floor, force units) and none is below half the smallest
    residual before them (it stopped falling). Measured: a three-body
    sandwich at atol = 1e-10 and E = 2e6 sat at 3-6e-10 (0.03-0.05 of its
    floor) for 50 iterations. Returns the median of the window.
    """
    if roundoff <= 0.0 or len(residuals) <= window:
        return None
    last = list(residuals[-window:])
    if not all(math.isfinite(r) for r in last) or max(last) > roundoff:
        return None
    if min(last) < 0.5 * min(residuals[:-window]):
        return None
    return float(np.median(last))


def convergence_order(residuals: Sequence[float], floor: float = 0.0) -> float:
    """Estimated order of convergence from the last three residuals above ``floor``.

    q = log(r_k / r_(k-1)) / log(r_(k-1) / r_(k-2)): 1 for linear, 2 for
    quadratic convergence, > 1 superlinear. Residuals at or below ``floor``
    (the round-off level, force units) are left out; NaN when fewer than
    three remain or they do not decrease.
    """
    usable = [r for r in residuals if r > floor and math.isfinite(r)]
    if len(usable) < 3:
        return math.nan
    r0, r1, r2 = usable[-3:]
    if not r0 > r1 > r2:
        return math.nan
    return math.log(r2 / r1) / math.log(r1 / r0)


@dataclass(frozen=True)
class SignoriniReport:
    """Worst violations of the nodal Signorini conditions.

    Attributes:
        min_gap: most negative nodal gap (penetration), length.
        max_pressure: largest nodal pressure (should be <= 0), stress.
        max_complementarity: max |lam g| (stress * length).
    """

    min_gap: float
    max_pressure: float
    max_complementarity: float


def signorini_report(gap: np.ndarray, pressure: np.ndarray, comm) -> SignoriniReport:
    """Global worst violations of g >= 0, lam <= 0, lam g = 0 at the nodes."""
    from mpi4py import MPI

    return SignoriniReport(
        min_gap=comm.allreduce(float(np.min(gap, initial=np.inf)), op=MPI.MIN),
        max_pressure=comm.allreduce(float(np.max(pressure, initial=-np.inf)), op=MPI.MAX),
        max_complementarity=comm.allreduce(
            float(np.max(np.abs(gap * pressure), initial=0.0)), op=MPI.MAX
        ),
    )


#: Said in a failure that no solver setting can mend (the CLI then suggests none).
NO_SOLVER_MENDS = "which no solver can undo"


def _first_violation(
    settings: SolverSettings,
    h: float,
    E: float,
    lengths: Sequence[tuple[str, float]],
    stresses: Sequence[tuple[str, float]],
) -> str | None:
    """The first named length beyond gap_tol h or stress beyond tension_tol E, as a sentence."""
    for name, value in lengths:
        if value > settings.gap_tol * h:
            return f"{name} {value:.3g} > gap_tol * h = {settings.gap_tol:g} * {h:.3g}"
    for name, value in stresses:
        if value > settings.tension_tol * E:
            return f"{name} {value:.3g} > tension_tol * E = {settings.tension_tol:g} * {E:g}"
    return None


def signorini_admissibility(
    problem, settings: SolverSettings
) -> Callable[[], str | None] | None:
    """The Signorini test of a converged iterate in its own units.

    Returns a callable giving None when the largest nodal penetration is at
    most ``settings.gap_tol * h`` (h: contact facet size) and the largest
    multiplier tension at most ``settings.tension_tol * E``, else a sentence
    naming the violation. Independent of r, unlike the residual. Only the
    nodal rule enforces the conditions at the nodes; with the Gauss rule
    (an integral constraint whose answer depends on r) there is no such
    test and None is returned.
    """
    if not problem.nodal_rule:
        return None
    E = float(problem.material.E)
    contacts = problem.contacts

    def check() -> str | None:
        for contact in contacts:
            violation = _signorini_violation(contact, settings, E)
            if violation is not None:
                prefix = f"{contact.name}: " if len(contacts) > 1 else ""
                return prefix + violation
        return None

    return check


def _signorini_violation(contact, settings: SolverSettings, E: float) -> str | None:
    """The first Signorini violation of one contact (its own h), or None."""
    from mpi4py import MPI

    h = float(contact.surface.h)
    state = contact.contact_state()
    tension = contact.comm.allreduce(float(np.max(state.multiplier, initial=0.0)), op=MPI.MAX)
    inside = state.max_penetration
    constraint = inside if state.constraint_penetration is None else (
        state.constraint_penetration
    )
    violation = _first_violation(
        settings, h, E, [("penetration", constraint)], [("tension", tension)]
    )
    if violation is not None and violation.startswith("penetration") \
            and _deepest_is_held(contact, state.gap):
        violation += (" at a node whose gap a [[dirichlet]] condition fixes: the prescribed "
                      f"displacement drives it into the partner, {NO_SOLVER_MENDS} (end that "
                      "support's path before the contact, or leave the component along the "
                      "contact normal free)")
    two_body = state.constraint_penetration is not None
    if violation is None and two_body and inside > settings.surface_tol * h:
        violation = (f"penetration into the target surface {inside:.3g} > surface_tol * h = "
                     f"{settings.surface_tol:g} * {h:.3g} "
                     f"({_inside_target_cause(contact, settings.surface_tol * h, inside)})")
    return violation


def _deepest_is_held(contact, gap: np.ndarray) -> bool:
    """Whether the most penetrating node is one a prescribed displacement holds (collective)."""
    from mpi4py import MPI

    mask = contact.normal_mask
    deepest = int(np.argmin(gap)) if gap.size else -1
    local = float(-gap[deepest]) if gap.size else -np.inf
    depth, rank = contact.comm.allreduce((local, contact.comm.rank), op=MPI.MAXLOC)
    held = bool(mask is not None and deepest >= 0 and mask.x.array[deepest] < 0.5)
    return bool(contact.comm.bcast(held, root=rank)) and depth > 0.0


def _inside_target_cause(contact, depth: float, inside: float | None = None) -> str:
    """Why a striker node of a converged iterate can lie inside the target, per discretisation.

    ``depth``: the depth that counts (length); ``inside``: the node's depth, when
    known (length). Collective.
    """
    from fenics_contact.model.mortar import MortarContact

    pair = getattr(contact, "pair", None)
    inside_own = getattr(pair, "inside_own_neighbourhood", None)
    if inside_own is not None and inside_own(depth):
        what = (f"a striker node inside target facets of its own neighbourhood "
                f"({pair.neighbourhood:g} facet sizes along the surface), which the "
                "self-contact search never pairs it with, so smaller steps or another method "
                "cannot help: ")
        if pair.neighbourhood > 1.0:
            return what + ("lower [[pair]] neighbourhood (e.g. 1), or pair the two "
                           'surfaces with discretisation = "mortar"')
        return what + ("the surface folds onto itself within about one facet size, which "
                       "no neighbourhood excludes less; refine the mesh where it folds, or "
                       "tag the surface on either side of the fold apart and pair the two "
                       'tags (self_contact = true, discretisation = "mortar")')

    if isinstance(contact, MortarContact):
        reach = contact.mortar.reach
        if inside is not None and inside < reach:
            return (f"a striker node of the mortar pair {inside / reach:.2g} of its search "
                    "reach inside the target finds no target facet it may pair with: facets "
                    "at more than about 78 degrees to its own are not paired, nor, where the "
                    "striker and target share a vertex (the fold of a surface closing on "
                    "itself), the facets that hold the node or its neighbours; refine the "
                    "mesh where the surfaces fold, or end the striker and target tags away "
                    "from the fold")
        return ("a striker node of the mortar pair has passed through the target deeper than "
                "its segment search reaches (2 facet sizes): its weighted gap finds no target "
                "facet and reads open; pushed through by too large a step, or the bodies "
                "started inside each other")
    return ("a striker node inside the target: held on the extension of a facet it has "
            "passed, at a concave vertex of a node-to-segment target, which a mortar pair, "
            "discretisation = \"mortar\", avoids; or pushed through it by too large a step")


def coulomb_admissibility(
    problem, settings: SolverSettings
) -> Callable[[], str | None] | None:
    """The Coulomb test of a converged iterate in its own units (friction, vertex rule).

    Beside the Signorini test: the raised stopping tolerance at large r (the
    round-off floor of the normal residual) covers the whole residual norm,
    so a small norm does not bound the tangential part. Returns a callable
    giving None when, at the nodes, the slip increment of sticking nodes is
    at most ``settings.gap_tol * h``, |tau - lam_t| (the tangential
    complementarity, stress) and the excess |lam_t| - mu |p_n| over the
    Coulomb disc at most ``settings.tension_tol * E``; else a sentence naming
    the violation. None (no test) without friction or with the Gauss rule.
    """
    if not problem.frictional or not problem.nodal_rule:
        return None
    h = float(problem.h)
    E = float(problem.material.E)

    def check() -> str | None:
        slip, mismatch, excess = problem.coulomb_violations()
        return _first_violation(
            settings, h, E, [("slip at sticking nodes", slip)],
            [("|tau - lam_t|", mismatch), ("|lam_t| - mu |p_n|", excess)],
        )

    return check


def prescribed_admissibility(
    problem, settings: SolverSettings
) -> Callable[[], str | None] | None:
    """The prescribed displacements of a converged iterate: |u - u_D| <= gap_tol h.

    None when the problem prescribes no displacement.
    """
    if not problem.bcs:
        return None
    h = float(problem.h)

    def check() -> str | None:
        return _first_violation(
            settings, h, 0.0, [("prescribed displacement mismatch", problem.prescribed_mismatch())],
            [],
        )

    return check


def hold_admissibility(problem, settings: SolverSettings) -> Callable[[], str | None]:
    """Every body of a converged iterate is held by its supports or its closed contacts.

    Returns a callable giving None when each rigid motion of each body is
    held by a prescribed component or moves some contact node closed in the
    iterate (active, or with a gap at most ``settings.gap_tol * h``; see
    :meth:`~fenics_contact.model.problem.ContactProblem.unheld_motion`),
    else a sentence naming the bodies and the motion. Cheap when the
    supports alone hold every body (no contact is evaluated).
    """

    def check() -> str | None:
        moving = problem.unheld_motion(settings.gap_tol)
        if not moving:
            return None
        what = "; ".join(f"body {name!r}: {motion}" for name, motion in moving)
        return (f"a rigid motion is held by nothing ({what}): no support holds it and no "
                "contact is closed against it in this state, so the stiffness is singular "
                "and the iterate is one of a family of rigid positions")

    return check


def passage_admissibility(problem) -> Callable[[], str | None]:
    """No rigid ball of a converged iterate has its centre inside the body.

    A ball's gap is positive on both sides of it: a step that carries a
    body across a small ball ends with every gap open (see
    :meth:`~fenics_contact.model.problem.ContactProblem.balls_passed_through`).
    """

    def check() -> str | None:
        names = problem.balls_passed_through()
        if not names:
            return None
        return (f"the body has passed through rigid obstacle(s) {', '.join(map(repr, names))}: "
                "the ball's centre lies inside the deformed body, its gaps read open on the "
                "far side; the step carried the surface across it (smaller load steps)")

    return check


Check = Callable[[], str | None]


def all_of(*checks: Check | None) -> Check | None:
    """One check from several, in order: the first refusal (None when no check is given)."""
    given = [c for c in checks if c is not None]
    if not given:
        return None

    def check() -> str | None:
        for c in given:
            reason = c()
            if reason is not None:
                return reason
        return None

    return check


def contact_admissibility(problem, settings: SolverSettings) -> Check | None:
    """The Signorini test, followed by the Coulomb test for frictional problems.

    None when neither applies (Gauss rule).
    """
    return all_of(signorini_admissibility(problem, settings),
                  coulomb_admissibility(problem, settings))


def admissibility(
    problem, settings: SolverSettings, *, exact_constraint: bool = True
) -> Check | None:
    """What a converged iterate must satisfy beside the residual test.

    The prescribed displacements, then (when the strategy enforces the
    constraint exactly, i.e. not penalty) the Signorini and Coulomb tests,
    then (every strategy) that supports or closed contacts hold every body.
    """
    return all_of(
        prescribed_admissibility(problem, settings),
        contact_admissibility(problem, settings) if exact_constraint else None,
        passage_admissibility(problem),
        hold_admissibility(problem, settings),
    )
