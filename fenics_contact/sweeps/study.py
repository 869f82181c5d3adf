"""Sweeps of method x r on one scene, with the paper's table layout.

Each run starts from (u, lam) = (0, 0), follows the scene's load steps
without cut-back (as in the paper) and records status, Newton iterations,
multiplier updates, linear solves, wall time, residual histories, the final
penetration and the displacement error against a tight GNRM reference. The
stopping rules are the study's (``settings``, default atol 1e-8 and 500
iterations as in the paper), the same for every method and r.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import ufl
from dolfinx import fem

from mpi4py import MPI

from fenics_contact.model.contact import Quadrature
from fenics_contact.model.problem import ContactProblem
from fenics_contact.solvers import PAPER_NAMES, make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings, Status
from fenics_contact.solvers.stepping import RunRecord, solve_load_path, start_record
from fenics_contact.sweeps.cases import Case, Probe, build_case, case_steps


@dataclass(frozen=True)
class Subject:
    """What a study runs and prints: a case with its label, probe and published table.

    Attributes:
        label: name in tables.
        case: a scene (or the paper's Example 1, a custom problem).
        probe: a scalar read off each solved problem (e.g. a corner
            displacement, length), printed for the penalty runs.
        exact: the exact displacement dofs of the problem (replaces the GNRM
            reference of the error column).
        published: a published table (method -> {r: cell}) printed beside.
    """

    label: str
    case: Case
    probe: Probe | None = None
    exact: Callable[[ContactProblem], np.ndarray] | None = None
    published: Mapping[str, Mapping[float, str]] | None = None


@dataclass
class StudyRecord(RunRecord):
    """One (method, r) run of a study: the run record plus the example's probe.

    ``probe``: the scalar the example reports through ``probe(problem)``
    (Example 1: the corner displacement u, length); NaN when it has none or
    the run failed.
    """

    probe: float = math.nan


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
    case: Case,
    quadrature: Quadrature = "nodal",
    comm: MPI.Comm = MPI.COMM_WORLD,
    exact: Callable[[ContactProblem], np.ndarray] | None = None,
) -> np.ndarray:
    """The exact displacement dofs (``exact`` of the problem) or a tight GNRM solve.

    The GNRM reference uses r = 1 relative and tolerance 1e-11.
    """
    problem = build_case(case, 1.0, True, quadrature, comm)
    if exact is not None:
        return np.asarray(exact(problem))
    strategy = make_strategy("gnrm", problem, SolverSettings(atol=1e-11, rtol=1e-14))
    result = solve_load_path(strategy, case_steps(case))
    if not result.converged:
        raise RuntimeError(f"The GNRM reference did not converge: {result.status}.")
    return problem.u.x.array.copy()


def run_one(
    case: Case,
    method: str,
    r: float,
    *,
    relative: bool,
    settings: SolverSettings,
    quadrature: Quadrature | None = None,
    reference: np.ndarray | None = None,
    max_cutbacks: int = 0,
    probe: Probe | None = None,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> tuple[StudyRecord, ContactProblem]:
    """Solve the case once with one method and one r (``probe``: a scalar of the answer)."""
    problem = build_case(case, r, relative, quadrature, comm)
    strategy = make_strategy(method, problem, settings)
    record = StudyRecord(**vars(start_record(strategy)))
    solve_load_path(strategy, case_steps(case), max_cutbacks=max_cutbacks, record=record)
    if reference is not None and record.converged:
        record.error = relative_l2_error(problem.u, reference)
    if probe is not None and record.converged:
        record.probe = float(probe(problem))
    return record, problem


def run_study(
    case: Case,
    methods: Sequence[str],
    r_values: Sequence[float],
    *,
    relative: bool = False,
    settings: SolverSettings | None = None,
    quadrature: Quadrature | None = None,
    progress: Callable[[RunRecord], None] | None = None,
    probe: Probe | None = None,
    exact: Callable[[ContactProblem], np.ndarray] | None = None,
) -> list[RunRecord]:
    """Run every method for every r on one case; return the records.

    ``quadrature`` None keeps each contact's own; ``probe`` and ``exact``
    (the exact dofs, replacing the GNRM reference) are functions of the
    solved problem.
    """
    settings = settings or SolverSettings(atol=1e-8, max_iterations=500)
    reference = reference_solution(case, quadrature or "nodal", exact=exact)
    records = []
    for method in methods:
        for r in r_values:
            record, _ = run_one(
                case, method, r, relative=relative, settings=settings,
                quadrature=quadrature, reference=reference, probe=probe,
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
    Status.HELD_BY_SPRINGS.value: "held by springs",
    Status.ERROR.value: "error",
}


def cell(record: RunRecord, limit: int) -> str:
    """Table entry: the iteration count, or the paper's word for the failure."""
    if record.status == Status.CONVERGED.value:
        return str(record.iterations)
    return STATUS_WORDS[record.status].format(limit=limit)


def r_key(record: RunRecord, relative: bool = False) -> float:
    """The r a table shows for a record: absolute, or relative to E/h (6 digits, as asked)."""
    return float(f"{record.r_relative if relative else record.r:.6g}")


def _r_header(r: float, relative: bool) -> str:
    """A table's column head: r, relative to E/h when ``relative``."""
    return f"r = {r:g}" + (" E/h" if relative else "")


def paper_table(records: Sequence[RunRecord], limit: int = 500, relative: bool = False) -> str:
    """Markdown table in the paper's layout: methods x r, updates on a second row for NUA.

    ``relative``: the columns are r relative to E/h (each record's own h).
    """
    rs = sorted({r_key(rec, relative) for rec in records})
    methods = list(dict.fromkeys(rec.method for rec in records))
    by_key = {(rec.method, r_key(rec, relative)): rec for rec in records}
    header = "| Method | " + " | ".join(_r_header(r, relative) for r in rs) + " |"
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


#: A table source: study records, or a published table (method -> {r: cell}, and
#: "nua updates" -> the second NUA row).
Source = Sequence[RunRecord] | Mapping[str, Mapping[float, str]]


def _cells(source: Source, method: str, rs: Sequence[float], limit: int,
           relative: bool = False) -> tuple[list, list]:
    """Iteration cells and NUA update cells of one method from one source."""
    if isinstance(source, Mapping):
        its, ups = source.get(method, {}), source.get(f"{method} updates", {})
        return [its.get(r, "") for r in rs], [ups.get(r, "") for r in rs]
    by_key = {(rec.method, r_key(rec, relative)): rec for rec in source}
    recs = [by_key.get((method, float(f"{r:.6g}"))) for r in rs]
    its = [cell(rec, limit) if rec is not None else "" for rec in recs]
    ups = [
        f"{rec.updates} updates"
        if rec is not None and rec.status == Status.CONVERGED.value
        else ""
        for rec in recs
    ]
    return its, ups


def comparison_table(
    sources: Sequence[tuple[str, Source]],
    r_values: Sequence[float],
    methods: Sequence[str],
    limit: int = 500,
    relative: bool = False,
) -> str:
    """Markdown table with one row per method and source (ours, the paper, an analog...).

    ``relative``: ``r_values`` are relative to E/h (each source's own h).
    """
    header = ("| Method | source | " + " | ".join(_r_header(r, relative) for r in r_values)
              + " |")
    lines = [header, "|---" * (len(r_values) + 2) + "|"]
    for m in methods:
        for label, source in sources:
            its, ups = _cells(source, m, r_values, limit, relative)
            if not any(its):
                continue
            lines.append(f"| {PAPER_NAMES.get(m, m)} | {label} | " + " | ".join(its) + " |")
            if m == "nua" and any(ups):
                lines.append(f"| | {label} | " + " | ".join(ups) + " |")
    return "\n".join(lines)


def probe_line(records: Sequence[StudyRecord], method: str = "penalty") -> str:
    """The probed value of one method at every r, e.g. the penalty displacement."""
    values = [(rec.r, rec.probe, rec.status) for rec in records if rec.method == method]
    return ", ".join(
        f"{v:.6g} (r = {r:g})" if math.isfinite(v) else f"{status} (r = {r:g})"
        for r, v, status in values
    )
