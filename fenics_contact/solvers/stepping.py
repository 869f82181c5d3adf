"""Load stepping with step cut-back.

The load factor goes from 0 to 1 in equal increments. A failed increment is
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
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field

from fenics_contact.solvers.base import SolveResult, Strategy
from fenics_contact.solvers.diagnostics import Status


@dataclass
class StepRecord:
    """What one load step cost and where it ended.

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
        contact_force: total normal contact force (force, per thickness in 2D).
        wall_s: wall-clock time of the step (seconds).
        min_det_F: smallest det F over the body at the end of the step (1
            undeformed; <= 0 means inverted elements).
        worst_cell: reference midpoint of the cell holding ``min_det_F``.
        message: why the step failed (empty when it converged).
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

    def to_dict(self) -> dict:
        """Plain-data view for JSON."""
        return asdict(self)


@dataclass
class PathResult:
    """All load steps of one run."""

    status: str
    steps: list[StepRecord]

    @property
    def iterations(self) -> int:
        """Newton iterations over the whole path."""
        return sum(s.iterations for s in self.steps)

    @property
    def updates(self) -> int:
        """Multiplier updates over the whole path."""
        return sum(s.updates for s in self.steps)

    @property
    def linear_solves(self) -> int:
        """Linear solves over the whole path."""
        return sum(s.linear_solves for s in self.steps)

    @property
    def converged(self) -> bool:
        """True when every step converged."""
        return self.status == Status.CONVERGED


def _absorb(record: StepRecord, result: SolveResult) -> None:
    record.iterations += result.iterations
    record.updates += result.updates
    record.linear_solves += result.linear_solves
    record.residuals.append(result.residuals)


def _failure_message(record: StepRecord, t_try: float) -> str:
    if record.status == Status.INVERTED:
        x = ", ".join(f"{c:.4g}" for c in record.worst_cell)
        return (
            f"elements inverted (det F = {record.min_det_F:.3g} <= 0) near ({x}) at load "
            f"factor {t_try:.4g}, even with the increment halved {record.cutbacks - 1} times; "
            "reduce the load, its initial penetration or r, or refine the mesh there"
        )
    return (
        f"{record.status} at load factor {t_try:.4g} with the increment halved "
        f"{record.cutbacks - 1} times"
    )


def solve_load_path(
    strategy: Strategy,
    n_steps: int,
    *,
    max_cutbacks: int = 4,
    on_step: Callable[[StepRecord], None] | None = None,
    on_iteration: Callable[[StepRecord, SolveResult], None] | None = None,
) -> PathResult:
    """Drive the load factor 0 -> 1 in ``n_steps`` increments with cut-back.

    ``on_step`` is called after each converged step (write results there);
    ``on_iteration`` after each solve attempt (progress display).
    """
    if n_steps < 1:
        raise ValueError(f"The number of load steps must be >= 1, got {n_steps}.")
    problem = strategy.problem
    records: list[StepRecord] = []
    t = problem.load_factor
    for k in range(1, n_steps + 1):
        target = k / n_steps
        record = StepRecord(step=k, load_factor=target, status=Status.CONVERGED.value)
        start = time.perf_counter()
        increment = target - t
        halvings = 0
        smallest = increment / 2**max_cutbacks
        while t < target - 1e-14:
            t_try = min(t + increment, target)
            saved = (problem.u.x.array.copy(), problem.lam.x.array.copy())
            problem.set_load(t_try)
            result = strategy.solve()
            _absorb(record, result)
            if on_iteration is not None:
                on_iteration(record, result)
            status = result.status
            if result.converged:
                det = problem.min_det_F()
                record.min_det_F, record.worst_cell = det.value, det.where
                if det.value > 0.0:
                    t = t_try
                    halvings = 0
                    continue
                status = Status.INVERTED
            problem.u.x.array[:] = saved[0]
            problem.lam.x.array[:] = saved[1]
            problem.set_load(t)
            record.cutbacks += 1
            halvings += 1
            if halvings > max_cutbacks or increment / 2 < smallest * (1 - 1e-12):
                record.status = status.value
                record.load_factor = t
                record.message = _failure_message(record, t_try)
                break
            increment /= 2
        record.wall_s = time.perf_counter() - start
        state = problem.contact_state()
        record.active_count = state.active_count
        record.max_penetration = state.max_penetration
        record.contact_force = state.contact_force
        records.append(record)
        if record.status != Status.CONVERGED:
            return PathResult(record.status, records)
        if on_step is not None:
            on_step(record)
    return PathResult(Status.CONVERGED.value, records)
