"""Sweeps of method x r on one example, with the paper's table layout.

Each run starts from (u, lam) = (0, 0), follows the example's load steps
without cut-back (as in the paper) and records status, Newton iterations,
multiplier updates, linear solves, wall time, residual histories, the final
penetration and the displacement error against a tight GNRM reference.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
import ufl
from dolfinx import fem

from mpi4py import MPI

from fenics_contact.model.contact import ContactSettings, Quadrature
from fenics_contact.model.problem import ContactProblem
from fenics_contact.solvers import PAPER_NAMES, make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings, Status
from fenics_contact.solvers.stepping import PathResult, solve_load_path


class Example:
    """What a study needs of an example: a builder and its load steps."""

    steps: int

    def build(self, settings: ContactSettings, comm: MPI.Comm = MPI.COMM_WORLD) -> ContactProblem:
        """Create the problem."""
        raise NotImplementedError


@dataclass
class RunRecord:
    """One (method, r) run of a study."""

    method: str
    r: float
    r_relative: float
    status: str
    iterations: int
    updates: int
    linear_solves: int
    wall_s: float
    max_penetration: float
    error: float
    contact_force: float
    steps_completed: int
    residuals: list[list[float]] = field(default_factory=list)

    def row(self) -> dict[str, object]:
        """Flat row for CSV (no histories)."""
        d = dict(self.__dict__)
        d.pop("residuals")
        return d


def relative_l2_error(u: fem.Function, reference: np.ndarray) -> float:
    """||u - u_ref||_L2 / ||u_ref||_L2 with u_ref given by its dof values."""
    ref = fem.Function(u.function_space)
    ref.x.array[:] = reference
    comm = u.function_space.mesh.comm
    diff = fem.form(ufl.inner(u - ref, u - ref) * ufl.dx)
    norm = fem.form(ufl.inner(ref, ref) * ufl.dx)
    num = comm.allreduce(fem.assemble_scalar(diff), op=MPI.SUM)
    den = comm.allreduce(fem.assemble_scalar(norm), op=MPI.SUM)
    return math.sqrt(num / den) if den > 0 else math.sqrt(num)


def reference_solution(
    example: Example, quadrature: Quadrature = "nodal", comm: MPI.Comm = MPI.COMM_WORLD
) -> np.ndarray:
    """The exact displacement dofs when the example knows them, else a tight GNRM solve.

    The GNRM reference uses r = 1 relative and tolerance 1e-11.
    """
    problem = example.build(ContactSettings(r=1.0, relative=True, quadrature=quadrature), comm)
    exact = getattr(example, "exact_dofs", None)
    if exact is not None:
        return np.asarray(exact(problem))
    strategy = make_strategy("gnrm", problem, SolverSettings(atol=1e-11, rtol=1e-14))
    result = solve_load_path(strategy, example.steps)
    if not result.converged:
        raise RuntimeError(f"The GNRM reference did not converge: {result.status}.")
    return problem.u.x.array.copy()


def run_one(
    example: Example,
    method: str,
    r: float,
    *,
    relative: bool,
    settings: SolverSettings,
    quadrature: Quadrature = "nodal",
    reference: np.ndarray | None = None,
    max_cutbacks: int = 0,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> tuple[RunRecord, ContactProblem, PathResult]:
    """Solve the example once with one method and one r."""
    problem = example.build(ContactSettings(r=r, relative=relative, quadrature=quadrature), comm)
    strategy = make_strategy(method, problem, settings)
    start = time.perf_counter()
    path = solve_load_path(strategy, example.steps, max_cutbacks=max_cutbacks)
    wall = time.perf_counter() - start
    last = path.steps[-1]
    done = sum(s.status == Status.CONVERGED for s in path.steps)
    error = (
        relative_l2_error(problem.u, reference)
        if reference is not None and path.converged
        else math.nan
    )
    record = RunRecord(
        method=method,
        r=problem.r_absolute,
        r_relative=problem.r_relative,
        status=path.status,
        iterations=path.iterations,
        updates=path.updates,
        linear_solves=path.linear_solves,
        wall_s=wall,
        max_penetration=last.max_penetration,
        error=error,
        contact_force=last.contact_force,
        steps_completed=done,
        residuals=[h for s in path.steps for h in s.residuals],
    )
    return record, problem, path


def run_study(
    example: Example,
    methods: Sequence[str],
    r_values: Sequence[float],
    *,
    relative: bool = False,
    settings: SolverSettings | None = None,
    quadrature: Quadrature = "nodal",
    progress: Callable[[RunRecord], None] | None = None,
) -> list[RunRecord]:
    """Run every method for every r; return the records."""
    settings = settings or SolverSettings(atol=1e-8, max_iterations=500)
    reference = reference_solution(example, quadrature)
    records = []
    for method in methods:
        for r in r_values:
            record, _, _ = run_one(
                example, method, r, relative=relative, settings=settings,
                quadrature=quadrature, reference=reference,
            )
            records.append(record)
            if progress is not None:
                progress(record)
    return records


#: Words the paper's tables use for failures.
STATUS_WORDS = {
    Status.CYCLING.value: "cycling",
    Status.DIVERGED.value: "divergence",
    Status.MAX_ITERATIONS.value: "> {limit}",
    Status.INVERTED.value: "inverted",
    Status.ERROR.value: "error",
}


def cell(record: RunRecord, limit: int) -> str:
    """Table entry: the iteration count, or the paper's word for the failure."""
    if record.status == Status.CONVERGED.value:
        return str(record.iterations)
    return STATUS_WORDS[record.status].format(limit=limit)


def paper_table(records: Sequence[RunRecord], limit: int = 500) -> str:
    """Markdown table in the paper's layout: methods x r, updates on a second row for NUA."""
    rs = sorted({rec.r for rec in records})
    methods = list(dict.fromkeys(rec.method for rec in records))
    by_key = {(rec.method, rec.r): rec for rec in records}
    header = "| Method | " + " | ".join(f"r = {r:g}" for r in rs) + " |"
    lines = [header, "|---" * (len(rs) + 1) + "|"]
    for m in methods:
        row = [cell(by_key[(m, r)], limit) if (m, r) in by_key else "" for r in rs]
        lines.append(f"| {PAPER_NAMES.get(m, m)} | " + " | ".join(row) + " |")
        if m == "nua":
            ups = [
                f"{by_key[(m, r)].updates} updates"
                if (m, r) in by_key and by_key[(m, r)].status == Status.CONVERGED.value
                else ""
                for r in rs
            ]
            lines.append("| | " + " | ".join(ups) + " |")
    return "\n".join(lines)
