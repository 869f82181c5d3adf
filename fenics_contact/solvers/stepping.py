"""Load stepping with step cut-back.

The load factor goes from 0 to 1 in equal increments. Before each
increment the problem commits its last converged state (``problem.commit()``:
the start of the slip increment for friction, a no-op without), so the step's
diagnostics and outputs still see the increment just solved. A failed increment is
undone (displacement and multiplier restored) and retried with half the
increment, up to ``max_cutbacks`` times in a row, and never below the step's
increment / 2**max_cutbacks (a limit the load cannot pass, such as inverted
elements at a fixed load, would otherwise halve it forever); past that the path stops
with the failing status, and the steps already converged are kept (the
``on_step`` callback has written them).

A converged solve is accepted only when det F > 0 at every quadrature point
of the body (:meth:`ContactProblem.min_det_F`); otherwise the attempt counts
as failed with status ``inverted`` and is cut back like any other failure.
A path that ends ``inverted`` names the worst cell in ``StepRecord.message``.
A converged solve in which the weak springs of a stabilised body carry more
than 1e-2 of the load (:func:`~fenics_contact.model.springs.spring_held`) is
no answer either: status ``held_by_springs``, cut back the same way.
"""

from __future__ import annotations

import math
import numbers
import re
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field

from fenics_contact.model.springs import spring_held
from fenics_contact.model.state import combined_state
from fenics_contact.solvers.base import SolveResult, Strategy
from fenics_contact.solvers.diagnostics import ROUNDOFF_STALL, Status, admissibility, roundoff_stall


@dataclass
class StepRecord:
    """What one load step cost and where it ended.

    A failed step's record holds the state the run stopped in: the last
    converged one, at ``load_factor`` (its forces, counts, det F and
    reactions), part of the way through the step when a halved increment
    converged before the last attempt failed; ``message`` names the load
    factor it failed at (det F is the failed attempt's when it turned
    elements inside out).

    Attributes:
        step: 1-based step number.
        load_factor: load factor reached (1 at the end of the path).
        status: converged, or the status of the last failed attempt.
        iterations: Newton iterations, all attempts and sub-increments included.
        updates: multiplier updates (Uzawa).
        linear_solves: linear systems solved.
        residuals: residual history of each solve, in order.
        cutbacks: how many times the increment was halved.
        active_count: nodes in contact at the end of the step.
        max_penetration: largest nodal penetration (length).
        contact_force: total normal contact force, -int lam dA over every contact
            (force, per thickness in 2D); on tilted normals a little more than the
            resultant along the load (see ``reactions``).
        wall_s: wall-clock time of the step (seconds).
        min_det_F: smallest det F over the body at the end of the step (1
            undeformed; <= 0 means inverted elements).
        worst_cell: reference midpoint of the cell holding ``min_det_F``.
        message: why the step failed (empty when it converged).
        failed_at: the load factor of a failed step's last attempt (None when
            it converged); ``load_factor`` is then the state it stopped in.
        tangential_force: magnitude of the total tangential contact force
            (force, per thickness in 2D; 0 without friction).
        stick_count: contact nodes that stick (0 without friction).
        slip_count: contact nodes that slip (0 without friction).
        contacts: each contact's numbers by name (normal_force, active_count,
            max_penetration, tangential_force, stick_count, slip_count); the
            fields above are their sums (the largest penetration).
        reactions: the force each support (prescribed displacement, by its
            scene tag) exerts on the bodies at the end of the step, per
            component (force, per thickness in 2D); filled by the scene
            runner for every finished step, empty for a failed one.
        reaction_total: the force all supports together exert, each held
            component of a node counted once (``reactions`` counts a component
            two supports share, as a fixed base meeting a symmetry plane, in
            both); it balances the contact forces and the tractions.
    """

    step: int
    load_factor: float
    status: str
    iterations: int = 0
    updates: int = 0
    linear_solves: int = 0
    residuals: list[list[float]] = field(default_factory=list)
    cutbacks: int = 0
    active_count: int = 0
    max_penetration: float = 0.0
    contact_force: float = 0.0
    wall_s: float = 0.0
    min_det_F: float = 1.0
    worst_cell: tuple[float, float, float] = (0.0, 0.0, 0.0)
    message: str = ""
    tangential_force: float = 0.0
    stick_count: int = 0
    slip_count: int = 0
    contacts: dict[str, dict] = field(default_factory=dict)
    reactions: dict[str, list[float]] = field(default_factory=dict)
    reaction_total: list[float] = field(default_factory=list)
    failed_at: float | None = None

    def to_dict(self) -> dict:
        """Plain-data view for JSON."""
        return asdict(self)


class _StepTotal:
    """A read-only :class:`RunRecord` total: one :class:`StepRecord` count over the steps.

    The attribute's name is the count's name (``iterations = _StepTotal(...)``
    sums ``step.iterations``).
    """

    def __init__(self, doc: str) -> None:
        self.__doc__ = doc
        self.name = ""

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    def __get__(self, record: RunRecord | None, owner: type | None = None) -> int:
        if record is None:
            return self  # type: ignore[return-value]  # the class attribute: this descriptor
        return sum(getattr(s, self.name) for s in record.steps)

    def __set__(self, record: RunRecord, value: object) -> None:
        raise AttributeError(f"{self.name} is the sum over the steps; change the steps.")


@dataclass
class RunRecord:
    """One run of a problem along its load path: the record every driver writes from.

    The CLI's summary.json, the studies' tables and CSV files and the
    benchmarks all read this record; a study that needs more columns
    subclasses it (see :mod:`fenics_contact.sweeps`).

    Attributes:
        status: converged, the failing status of the last step, or ``error``
            (an exception; ``message`` says which).
        steps: one record per load step attempted.
        method: strategy name.
        r_absolute: r in stress per length.
        r_relative: r divided by E/h.
        displacement_dofs: global displacement unknowns.
        multiplier_dofs: global multiplier unknowns (normal, and tangential with friction).
        processes: MPI ranks.
        wall_s: wall-clock time of the load path (seconds).
        error: relative L2 displacement error against a reference (NaN when none).
        switches: decisions an adaptive strategy took, in order, each with its load
            step ("rescale r (step 3): ...").
        message: what went wrong: the exception when status is ``error``, the failed
            load step's message (``load step K: ...``) when a step failed.
    """

    status: str
    steps: list[StepRecord] = field(default_factory=list)
    method: str = ""
    r_absolute: float = math.nan
    r_relative: float = math.nan
    displacement_dofs: int = 0
    multiplier_dofs: int = 0
    processes: int = 1
    wall_s: float = 0.0
    error: float = math.nan
    switches: list[str] = field(default_factory=list)
    message: str = ""

    @property
    def r(self) -> float:
        """R in stress per length (the paper's tables)."""
        return self.r_absolute

    iterations = _StepTotal("Newton iterations over the whole path.")
    updates = _StepTotal("Multiplier updates over the whole path.")
    linear_solves = _StepTotal("Linear solves over the whole path.")
    cutbacks = _StepTotal("Increment halvings over the whole path.")

    @property
    def steps_completed(self) -> int:
        """Load steps that converged."""
        return sum(s.status == Status.CONVERGED for s in self.steps)

    @property
    def max_penetration(self) -> float:
        """Largest nodal penetration at the last step attempted (length)."""
        return self.steps[-1].max_penetration if self.steps else 0.0

    @property
    def contact_force(self) -> float:
        """Normal contact force at the last step attempted (force)."""
        return self.steps[-1].contact_force if self.steps else 0.0

    @property
    def residuals(self) -> list[list[float]]:
        """Residual history of every solve, in order."""
        return [h for s in self.steps for h in s.residuals]

    @property
    def converged(self) -> bool:
        """True when every step converged."""
        return self.status == Status.CONVERGED

    _DERIVED = (
        "r",
        "iterations", "updates", "linear_solves", "cutbacks", "steps_completed",
        "max_penetration", "contact_force",
    )

    def row(self) -> dict[str, object]:
        """Flat row for CSV and tables: fields, totals and r, no histories."""
        d = {k: v for k, v in asdict(self).items() if k not in ("steps", "switches")}
        d.update({k: getattr(self, k) for k in self._DERIVED})
        if math.isnan(self.error):
            d["error"] = None  # not measured (no reference)
        d["switches"] = "; ".join(dict.fromkeys(
            re.sub(r" \(step \d+\)$", "", s.split(":")[0]) for s in self.switches))
        return d

    def to_dict(self) -> dict[str, object]:
        """Everything, per-step records included, for JSON."""
        d = self.row()
        d["switches"] = list(self.switches)
        d["steps"] = [s.to_dict() for s in self.steps]
        return d


#: The load-path result before the record gained its run context.
PathResult = RunRecord


def _at_step(switch: str, step: int) -> str:
    """'rescale r: ...' -> 'rescale r (step 3): ...' (the kind first, as :meth:`row` reads it)."""
    kind, colon, rest = switch.partition(":")
    return f"{kind} (step {step}){colon}{rest}"


def _absorb(record: StepRecord, result: SolveResult, run: RunRecord) -> None:
    run.switches.extend(_at_step(s, record.step) for s in result.switches)
    record.iterations += result.iterations
    record.updates += result.updates
    record.linear_solves += result.linear_solves
    record.residuals.append(result.residuals)


def _attempts(record: StepRecord) -> str:
    """How often the failed step was tried, in words: '5 attempts, the increment halved 4 times'."""
    halved = record.cutbacks
    if halved == 0:
        return "1 attempt, no cut-back"
    times = "once" if halved == 1 else f"{halved} times"
    return f"{halved + 1} attempts, the increment halved {times}"


def refusal(strategy: Strategy, result: SolveResult) -> str | None:
    """Why a failed solve whose residual met its tolerance was not accepted, or None.

    The strategy's admissibility test (prescribed displacements, Signorini,
    Coulomb) read on the last iterate: the reason the solve kept iterating
    although its residual had converged.
    """
    settings = strategy.settings
    if not result.residuals:
        return None
    tolerance = max(settings.atol, settings.rtol * result.residuals[0])
    if not result.residuals[-1] <= tolerance:  # above it, or NaN (a diverged iterate)
        return None
    check = admissibility(strategy.problem, settings,
                          exact_constraint=getattr(strategy, "exact_constraint", True))
    return None if check is None else check()


def _settle(strategy: Strategy, t: float) -> None:
    """Put the problem at the state a failed step stops in: the last converged u, at its load.

    The failed attempt left its load factor set and the solver's last
    residual (whose Dirichlet rows are the supports' reactions) at the failed
    iterate; the record and the reactions read at ``t`` must be those of the
    restored, converged state.
    """
    strategy.problem.set_load(t)
    kernel = getattr(strategy, "kernel", None)
    if kernel is not None:
        kernel.assemble_residual()


#: The stall note's advice; a front end names its own tolerance setting after it
#: (:func:`name_tolerance`).
RAISE_TOLERANCE = "raise the absolute tolerance to about"


def stall_note(strategy: Strategy, residuals: list[float]) -> str | None:
    """Why the residual of a failed attempt stopped falling, when it is round-off (collective).

    The residual's round-off floor (FLOOR_FACTOR eps r g ||A||, see
    :meth:`~fenics_contact.model.problem.ContactProblem.residual_roundoff`)
    bounds what any tolerance may demand: a
    residual that sits below it over :data:`STALL_WINDOW` iterations without
    falling is round-off, and only a larger atol ends the step. The note
    does not say where the tolerance is set: each front end says it
    (:func:`name_tolerance`).
    """
    floor, size, atol = strategy.problem.residual_roundoff()
    level = roundoff_stall(residuals, floor) if floor > 0.0 else None
    if level is None or level <= strategy.settings.atol:  # a strategy's own tighter target
        return None
    return (f"the residual stalls at {level:.2g}, {ROUNDOFF_STALL} {size:.3g} (r g ||A||), "
            f"above atol = {strategy.settings.atol:g}; {RAISE_TOLERANCE} {atol:.1g}")


def name_tolerance(record: RunRecord, setting: str) -> None:
    """Name ``setting`` (where the tolerance is set) after the stall note's advice in ``record``.

    ``setting``: e.g. "study's --tol". The run's and its steps' messages are
    amended (once: a second call changes nothing).
    """
    advice = re.compile(rf"({re.escape(RAISE_TOLERANCE)} [-+.0-9e]+)(?![-+.0-9e]| \()")

    def named(text: str) -> str:
        return advice.sub(lambda m: f"{m.group(1)} ({setting})", text)

    record.message = named(record.message)
    for step in record.steps:
        step.message = named(step.message)


def _failure_message(record: StepRecord, t_try: float, refused: str | None = None,
                     earlier: tuple[int, str] | None = None, springs: str | None = None,
                     stalled: str | None = None) -> str:
    """Why a step failed, in words.

    ``refused``: the last attempt's refusal; ``earlier``: (attempt number,
    reason) of an earlier attempt's, named when the last one was not refused;
    ``springs``: why the last attempt's converged state was no answer
    (:func:`~fenics_contact.model.springs.spring_held`); ``stalled``:
    :func:`stall_note` of the last attempt, said first.
    """
    if record.status == Status.HELD_BY_SPRINGS:
        return f"{springs} (at load factor {t_try:.4g} after {_attempts(record)})"
    if record.status == Status.INVERTED:
        x = ", ".join(f"{c:.4g}" for c in record.worst_cell)
        return (
            f"inverted: elements turned inside out (det F = {record.min_det_F:.3g} <= 0) "
            f"near ({x}) at load "
            f"factor {t_try:.4g} after {_attempts(record)}; "
            "reduce the load, its initial penetration or r, or refine the mesh there"
        )
    message = f"{record.status} at load factor {t_try:.4g} after {_attempts(record)}"
    if stalled:
        message += f"; {stalled}"
    firsts = [r[0] for r in record.residuals if r]
    if firsts and not any(math.isfinite(r) for r in firsts):
        message += ("; the residual was NaN or infinite at its first evaluation in every attempt "
                    "(no Newton step could be taken): a form gave a non-number at the step's "
                    "start state")
    elif (record.status == Status.DIVERGED and firsts
          and all(len(r) == 1 and math.isfinite(r[0]) for r in record.residuals)):
        message += ("; in every attempt the linear solve of the first Newton step failed: "
                    "the Jacobian is singular at the step's start state (a node with more "
                    "contact conditions than free components, or a constraint with no "
                    "derivative there), which smaller steps do not change")
    if refused:
        message += f"; the residual met its tolerance but the iterate was refused: {refused}"
    elif earlier is not None:
        message += (f"; in attempt {earlier[0]} the residual met its tolerance but the "
                    f"iterate was refused: {earlier[1]}")
    return message


def start_record(strategy: Strategy) -> RunRecord:
    """An empty record (status ``running``) carrying the strategy's and problem's context."""
    problem = strategy.problem
    V = problem.V
    return RunRecord(
        status="running",
        method=strategy.name,
        r_absolute=problem.r_absolute,
        r_relative=problem.r_relative,
        displacement_dofs=V.dofmap.index_map.size_global * V.dofmap.index_map_bs,
        multiplier_dofs=problem.multiplier_dofs,
        processes=problem.comm.size,
    )


def solve_load_path(
    strategy: Strategy,
    n_steps: int,
    *,
    max_cutbacks: int = 4,
    on_step: Callable[[StepRecord], None] | None = None,
    on_iteration: Callable[[StepRecord, SolveResult], None] | None = None,
    record: RunRecord | None = None,
    first_step: int = 1,
    last_step: int | None = None,
) -> RunRecord:
    """Drive the load factor 0 -> 1 in ``n_steps`` increments with cut-back.

    ``on_step`` is called after each converged step (write results there);
    ``on_iteration`` after each solve attempt (progress display). The steps
    go into ``record`` as they finish (a fresh :func:`start_record` when
    None), so a caller holding it sees the run grow; it is returned with its
    final status and wall time. A resumed path starts at ``first_step`` from
    the problem's current load factor and fields (those of step
    ``first_step - 1``); the record holds the steps solved here.
    ``last_step`` ends the path after that step (a partial path: status
    "partial" when it converged up to there).
    """
    if not hasattr(strategy, "problem") or not hasattr(strategy, "solve"):
        raise TypeError(f"solve_load_path needs a strategy (make_strategy(method, problem, "
                        f"settings)), got {type(strategy).__name__}.")
    if isinstance(n_steps, bool) or not isinstance(n_steps, numbers.Integral):
        raise TypeError(f"n_steps = {n_steps!r}: give a whole number of load steps >= 1.")
    if n_steps < 1:
        raise ValueError(f"The number of load steps must be >= 1, got {n_steps}.")
    problem = strategy.problem
    if record is None and problem.load_factor >= 1.0 - 1e-14:
        raise ValueError(
            "Nothing to solve: the problem is at load factor 1, the end of its path (solved "
            "before?). Build a new problem for a new run, or set_load(t) and strategy.solve() "
            "for one more load."
        )
    run = start_record(strategy) if record is None else record
    run_start = time.perf_counter()
    t = problem.load_factor
    end = n_steps if last_step is None else min(last_step, n_steps)
    for k in range(first_step, end + 1):
        target = k / n_steps
        if target <= t + 1e-14:
            continue  # reached before (a resumed path)
        step = StepRecord(step=k, load_factor=target, status=Status.CONVERGED.value)
        start = time.perf_counter()
        increment = target - t
        halvings = attempts = 0
        earlier: tuple[int, str] | None = None  # the last refusal of an attempt of this step
        smallest = increment / 2**max_cutbacks
        while t < target - 1e-14:
            t_try = min(t + increment, target)
            # history-dependent terms (friction) take the last converged state as
            # the start of the increment; idempotent after a restore
            problem.commit()
            saved = problem.snapshot()
            problem.set_load(t_try)
            result = strategy.solve()
            attempts += 1
            _absorb(step, result, run)
            if on_iteration is not None:
                on_iteration(step, result)
            status = result.status
            springs: str | None = None  # why a converged attempt is no answer
            if result.converged:
                det = problem.min_det_F()
                step.min_det_F, step.worst_cell = det.value, det.where
                springs = spring_held(problem) if det.value > 0.0 else None
                if det.value > 0.0 and springs is None:
                    t = t_try
                    halvings = 0
                    continue
                status = Status.INVERTED if springs is None else Status.HELD_BY_SPRINGS
            refused = refusal(strategy, result) if not result.converged else None
            if refused is not None:
                earlier = (attempts, refused)
            problem.restore(saved)
            if status is not Status.INVERTED:  # the record holds the state the run stops in
                det = problem.min_det_F()
                step.min_det_F, step.worst_cell = det.value, det.where
            halvings += 1
            if halvings > max_cutbacks or increment / 2 < smallest * (1 - 1e-12):
                step.status = status.value
                step.load_factor = t
                step.failed_at = t_try
                stalled = (stall_note(strategy, result.residuals) if refused is None
                           and status in (Status.MAX_ITERATIONS, Status.CYCLING) else None)
                step.message = _failure_message(step, t_try, refused, earlier, springs, stalled)
                _settle(strategy, t)
                break
            increment /= 2
            step.cutbacks += 1
        step.wall_s = time.perf_counter() - start
        states = problem.contact_states()
        state = combined_state(list(states.values()))
        step.contacts = {name: s.summary() for name, s in states.items()}
        step.active_count = state.active_count
        step.max_penetration = state.max_penetration
        step.contact_force = state.contact_force
        step.tangential_force = state.tangential_force
        step.stick_count, step.slip_count = state.stick_count, state.slip_count
        run.steps.append(step)
        run.wall_s += time.perf_counter() - run_start
        run_start = time.perf_counter()
        if step.status != Status.CONVERGED:
            run.status = step.status
            run.message = f"load step {step.step}: {step.message}"
            return run
        if on_step is not None:
            on_step(step)
    run.status = Status.CONVERGED.value if end == n_steps else "partial"
    run.wall_s += time.perf_counter() - run_start
    return run
