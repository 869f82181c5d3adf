"""The speed-accuracy trade: methods x r x mesh on scenes, timed and scored.

A :class:`TradeoffCase` is one scene on one mesh, with its family's name and,
where a closed form exists, a function giving the peak-pressure error of a
solved problem. For every (case, method, r) the load path is solved from zero
(no cut-back, as in the paper) and we record: status, Newton iterations,
linear solves, multiplier updates, wall time (median of ``repeats`` runs;
a run that does not converge is timed once), largest penetration, the
relative L2 displacement error against a tight GNRM reference on the same
mesh, and where the case has one the peak-pressure error (Hertz).

Friction: a frictional scene (the project's sliding block, one case per
Coulomb coefficient mu) adds three measures
(:class:`FrictionMeter`): the relative error of the tangential force against
mu times the normal force over the steps where the reference slides at every
contact node, the largest slip increment at a node reported sticking, and the
largest tangential complementarity residual |P(lam_t + r_t dg_t) - lam_t|
(force; not defined for the penalty method, which has no multiplier).

Stopping test for every method: atol = max(1e-10 E h^(d-1), round-off
floor at r) (:func:`fenics_contact.model.scaling.scaled_atol`), no rtol,
written per run as ``atol``. The reference is GNRM at r = 1 E/h with
1e-13 E h^(d-1).

Picks ("fastest", "most accurate", the Pareto fronts) leave out the
reference's own run (:func:`on_reference_path`) unless only it converged;
points whose u error is at round-off (:data:`ROUNDOFF_ERROR`) tie.
"""

from __future__ import annotations

import math
import statistics
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from mpi4py import MPI

from fenics_contact.model.friction import STICK
from fenics_contact.model.problem import ContactProblem
from fenics_contact.model.scaling import DEFAULT_FORCE_RTOL, scaled_atol
from fenics_contact.scene.spec import Scene
from fenics_contact.solvers import PAPER_NAMES, STRATEGIES, make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings, Status
from fenics_contact.solvers.stepping import (
    RunRecord,
    StepRecord,
    solve_load_path,
    start_record,
)
from fenics_contact.sweeps.cases import build_case, case_steps
from fenics_contact.sweeps.coulomb import coulomb_ratio
from fenics_contact.sweeps.study import relative_l2_error

#: r values relative to E/h of the full sweep: 1e-4 ... 1e8, a decade apart.
FULL_R = tuple(10.0**e for e in range(-4, 9))
#: Smallest displacement error a plot draws (relative L2): smaller ones, 0 too, sit on it.
ERROR_FLOOR = 1e-15
#: Displacement errors at or below this reach the reference to round-off: such points tie.
ROUNDOFF_ERROR = 10.0 * ERROR_FLOOR
#: r of the reference (relative to E/h) and its tolerance relative to E h^(d-1).
REFERENCE_R = 1.0
REFERENCE_FORCE_RTOL = 1e-13
#: Methods whose run at the reference's r follows its path: GNRM, and ``auto``
#: (plain GNRM at its working r).
REFERENCE_PATH_METHODS = ("gnrm", "auto")
METHODS = tuple(STRATEGIES)
@dataclass(frozen=True)
class TradeoffCase:
    """One scene on one mesh in the trade-off.

    Attributes:
        scene: the family's name in tables (e.g. 'hertz').
        mesh: the mesh's label (e.g. 'h=0.01').
        case: the validated scene.
        peak_error: relative peak-pressure error of a solved problem against a
            closed form (None: not known for this scene).
    """

    scene: str
    mesh: str
    case: Scene
    peak_error: Callable[[ContactProblem], float] | None = None


@dataclass
class TradeoffRecord(RunRecord):
    """One (scene, mesh, method, r) point of the trade-off: the run record plus its place.

    ``error`` is the displacement error against the GNRM reference on the
    same mesh; ``p0_error`` the Hertz peak-pressure error (NaN off Hertz);
    ``wall_s`` the median over ``repeats`` runs. Friction cases (NaN
    otherwise): ``mu`` the Coulomb coefficient, ``ft_error`` the largest
    |F_t / (mu N) - 1| over the reference's fully sliding steps,
    ``stick_slip`` the largest slip increment at a sticking node (length),
    ``t_residual`` the largest tangential complementarity residual (force).
    ``r_working``: the r the solves worked at, relative to E/h (``auto``'s
    clamped r; the user's r otherwise); ``atol`` the stopping tolerance (force).
    """

    scene: str = ""
    mesh: str = ""
    repeats: int = 1
    r_working: float = math.nan
    atol: float = math.nan
    p0_error: float = math.nan
    mu: float = math.nan
    ft_error: float = math.nan
    stick_slip: float = math.nan
    t_residual: float = math.nan
    pareto_u: bool = False
    pareto_p0: bool = False

    @property
    def case(self) -> str:
        """The scene, with its Coulomb coefficient for friction cases."""
        return self.scene if math.isnan(self.mu) else f"{self.scene} mu={self.mu:g}"

    @property
    def u_error(self) -> float:
        """Relative L2 displacement error against the reference."""
        return self.error

    def row(self) -> dict[str, object]:
        """Flat row, with the displacement error also named ``u_error``."""
        return {**super().row(), "u_error": self.error}


@dataclass(frozen=True)
class Reference:
    """A tight GNRM solution on a scene's mesh.

    Attributes:
        u: displacement dof values at the end of the load path (length).
        sliding_steps: 1-based load steps at whose end every contact node
            slips (friction cases; empty otherwise).
    """

    u: np.ndarray
    sliding_steps: frozenset[int] = frozenset()


def _fully_sliding(step: StepRecord) -> bool:
    return step.active_count > 0 and step.slip_count == step.active_count


def reference_solution(scene: Scene, comm: MPI.Comm = MPI.COMM_WORLD) -> Reference | None:
    """Tight GNRM solution on the scene's mesh; None if it fails."""
    problem = build_case(scene, REFERENCE_R, True, None, comm)
    settings = SolverSettings(atol=scaled_atol(problem, REFERENCE_FORCE_RTOL),
                              max_iterations=100)
    path = solve_load_path(make_strategy("gnrm", problem, settings), case_steps(scene),
                           max_cutbacks=4)
    if not path.converged:
        return None  # errors against it are then NaN
    sliding = frozenset(s.step for s in path.steps if _fully_sliding(s))
    return Reference(problem.u.x.array.copy(), sliding if _mu(scene) > 0 else frozenset())


def _mu(scene: Scene) -> float:
    """The scene's (first) Coulomb coefficient (NaN for a frictionless scene)."""
    coefficients = [o.contact.mu for o in scene.obstacles] + [p.mu for p in scene.pairs]
    return next((float(m) for m in coefficients if m is not None), math.nan)


@dataclass
class FrictionMeter:
    """Measures the friction law at the end of every converged load step (``on_step``).

    Attributes:
        problem: a frictional :class:`~fenics_contact.model.problem.ContactProblem`.
        multiplier: False for the penalty method (no tangential multiplier:
            the complementarity residual is then not measured).
        stick_slip: largest |dg_t| at a node in the stick state (length).
        t_residual: largest tangential complementarity residual norm (force).
        elapsed_s: time spent measuring (taken off the run's wall time).
        ratios: F_t / (mu N) at the end of each measured step, by step number.
    """

    problem: object
    multiplier: bool = True
    stick_slip: float = 0.0
    t_residual: float = 0.0
    elapsed_s: float = 0.0
    ratios: dict[int, float] = field(default_factory=dict)

    def __call__(self, step: StepRecord) -> None:
        """Measure the problem's state at the end of ``step``."""
        start = time.perf_counter()
        p = self.problem
        local = 0.0
        for state in p.frictional_states():  # frictionless contacts have no stick
            stuck = state.node_state == STICK
            local = max(local, float(np.max(np.linalg.norm(state.slip[stuck], axis=1),
                                            initial=0.0)))
        self.stick_slip = max(self.stick_slip, p.comm.allreduce(local, op=MPI.MAX))
        if self.multiplier:
            self.t_residual = max(self.t_residual, p.complementarity_norms()[1])
        self.ratios[step.step] = coulomb_ratio(step, p.friction_coefficients())
        self.elapsed_s += time.perf_counter() - start

    def score(self, record: TradeoffRecord, reference: Reference | None) -> None:
        """Write the measures into ``record`` (the F_t error needs the reference's steps)."""
        record.stick_slip = self.stick_slip
        record.t_residual = self.t_residual if self.multiplier else math.nan
        if reference is not None and reference.sliding_steps:
            record.ft_error = max(abs(self.ratios.get(k, math.nan) - 1.0)
                                  for k in sorted(reference.sliding_steps))
        record.wall_s -= self.elapsed_s


def run_point(
    case: TradeoffCase,
    method: str,
    r: float,
    reference: Reference | None,
    *,
    repeats: int = 3,
    max_iterations: int = 200,
    force_rtol: float = DEFAULT_FORCE_RTOL,
    contact_set: str = "sign",
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> TradeoffRecord:
    """Solve one point ``repeats`` times (once if it fails); score the last run.

    ``contact_set``: each Newton step's contact set ("sign", the paper's, or
    "exact", a scene's default).
    """
    times: list[float] = []
    for _ in range(max(repeats, 1)):
        problem = build_case(case.case, r, True, None, comm)
        settings = SolverSettings(atol=scaled_atol(problem, force_rtol),
                                  max_iterations=max_iterations)
        strategy = make_strategy(method, problem, settings, contact_set=contact_set)
        record = TradeoffRecord(
            **vars(start_record(strategy)), scene=case.scene, mesh=case.mesh,
            mu=_mu(case.case), atol=settings.atol,
        )
        meter = None
        if not math.isnan(record.mu):
            meter = FrictionMeter(problem, getattr(strategy, "exact_constraint", True))
        solve_load_path(strategy, case_steps(case.case), max_cutbacks=0, record=record,
                        on_step=meter)
        if meter is not None:
            meter.score(record, reference)
        record.r_working = strategy.working_r() / problem.stiffness_scale
        times.append(record.wall_s)
        if not record.converged:
            break
    record.repeats = len(times)
    record.wall_s = statistics.median(times)
    if record.converged and reference is not None:
        record.error = relative_l2_error(problem.u, reference.u)
    if record.converged and case.peak_error is not None:
        record.p0_error = abs(case.peak_error(problem))
    return record


def run_tradeoff(
    cases: Sequence[TradeoffCase],
    methods: Sequence[str],
    r_values: Sequence[float],
    *,
    progress: Callable[[TradeoffRecord], None] | None = None,
    **options: float,
) -> list[TradeoffRecord]:
    """Sweep cases x methods x r (relative to E/h); mark the Pareto fronts.

    ``options`` go to :func:`run_point` (repeats, max_iterations, force_rtol).
    """
    records = []
    for case in cases:
        reference = reference_solution(case.case)
        for method in methods:
            for r in r_values:
                record = run_point(case, method, r, reference, **options)
                records.append(record)
                if progress is not None:
                    progress(record)
    mark_pareto(records)
    return records


def error_of(record: TradeoffRecord) -> float:
    """The accuracy a user sees: the Hertz peak error where known, else the u error."""
    return record.p0_error if math.isfinite(record.p0_error) else record.u_error


def _front(points: Sequence[TradeoffRecord], error: Callable[[TradeoffRecord], float]) -> set[int]:
    """Indices of the points no other point beats in both wall time and error."""
    front = set()
    for i, rec in enumerate(points):
        e, t = error(rec), rec.wall_s
        beaten = any(
            error(o) <= e and o.wall_s <= t and (error(o) < e or o.wall_s < t)
            for j, o in enumerate(points) if j != i
        )
        if not beaten:
            front.add(i)
    return front


def on_reference_path(record: TradeoffRecord) -> bool:
    """Whether a point is the reference's own run, whose error measures nothing.

    GNRM iterates at the reference's r: GNRM at r = 1 E/h, or ``auto`` working
    at r = 1 E/h (plain GNRM there, whatever r it was given).
    """
    return (record.method in REFERENCE_PATH_METHODS
            and math.isclose(record.r_working, REFERENCE_R, rel_tol=1e-9))


def candidates(points: Sequence[TradeoffRecord]) -> list[TradeoffRecord]:
    """The points a pick chooses from: all but the reference's own run, unless only it is left."""
    return [r for r in points if not on_reference_path(r)] or list(points)


def _u_score(record: TradeoffRecord) -> float:
    """The u error a front compares: errors at round-off tie."""
    return max(record.u_error, ROUNDOFF_ERROR)


def mark_pareto(records: Sequence[TradeoffRecord]) -> None:
    """Mark the Pareto fronts among converged records (:func:`candidates` of each group).

    ``pareto_u``: displacement error against time, per case (scene, and mu
    with friction) and mesh (the solver's trade on one discretisation);
    errors at round-off tie. ``pareto_p0``: Hertz peak-pressure error against
    time over all meshes of the scene (the whole trade).
    """
    ok = [r for r in records if r.status == Status.CONVERGED]
    for key in {(r.case, r.mesh) for r in ok}:
        points = candidates([r for r in ok if (r.case, r.mesh) == key
                             and math.isfinite(r.u_error)])
        for i in _front(points, _u_score):
            points[i].pareto_u = True
    for case in {r.case for r in ok}:
        points = candidates([r for r in ok if r.case == case and math.isfinite(r.p0_error)])
        for i in _front(points, lambda r: r.p0_error):
            points[i].pareto_p0 = True


_OWN_PATH = " (the reference's own path)"


def _fmt(x: float) -> str:
    return "-" if not math.isfinite(x) else f"{x:.1e}"


def _worst(values: Sequence[float]) -> float:
    """Largest finite value (NaN when there is none)."""
    finite = [v for v in values if math.isfinite(v)]
    return max(finite) if finite else math.nan


def most_accurate(good: Sequence[TradeoffRecord]) -> str:
    """The most accurate of converged points: 'r, error', or the r that tie at round-off.

    The reference's own run is left out unless only it converged (then
    marked); where several points reach the reference to round-off
    (u error <= :data:`ROUNDOFF_ERROR`) none of them is picked: all are named.
    """
    points = candidates(good)
    if not points:
        return "-"
    best = min(points, key=lambda r: (error_of(r), r.wall_s))
    tied = sorted((r for r in points if r.u_error <= ROUNDOFF_ERROR),
                  key=lambda r: r.r_relative)
    if len(tied) > 1 and best in tied:
        text = (f"r = {', '.join(f'{r.r_relative:g}' for r in tied)} reach the reference to "
                f"round-off (u error <= {max(r.u_error for r in tied):.1e})")
        if math.isfinite(best.p0_error):
            text += f", error {_fmt(best.p0_error)}"
    else:
        text = f"{best.r_relative:g}, {_fmt(error_of(best))}"
    return text + (_OWN_PATH if on_reference_path(best) else "")


def fastest(good: Sequence[TradeoffRecord]) -> str:
    """The fastest of converged points (:func:`candidates`): r, time, iterations, error."""
    fast = min(candidates(good), key=lambda r: r.wall_s)
    return (f"{fast.r_relative:g}, {fast.wall_s:.3f}, {fast.iterations}, "
            f"{_fmt(error_of(fast))}" + (_OWN_PATH if on_reference_path(fast) else ""))


def _summary(recs: Sequence[TradeoffRecord]) -> tuple[list[TradeoffRecord], str, str, str]:
    """Converged records, their r span, the fastest point and the r that did not converge."""
    good = [r for r in recs if r.status == Status.CONVERGED]
    bad = [f"{r.r_relative:g} ({r.status})" for r in recs if r.status != Status.CONVERGED]
    if not good:
        return good, "none", "-", ", ".join(bad) or "-"
    span = f"{min(r.r_relative for r in good):g} - {max(r.r_relative for r in good):g}"
    return good, span, fastest(good), ", ".join(bad) or "-"


def markdown_table(records: Sequence[TradeoffRecord]) -> str:
    """Per scene and mesh, per method: the best converged points and where it fails.

    Columns: fastest converged r, its time and error; the most accurate
    point (:func:`most_accurate`); and the r values (relative) that did not
    converge. Neither pick is the reference's own run (GNRM iterates at
    r = 1 E/h) unless only it converged, and then it is marked. Friction
    cases get their own table (:func:`friction_table`).
    """
    lines = [
        "| scene | mesh | method | converged r (E/h) | fastest: r, time s, iterations, error | "
        "most accurate: r, error | not converged at r |",
        "|---|---|---|---|---|---|---|",
    ]
    plain = [r for r in records if math.isnan(r.mu)]
    keys = list(dict.fromkeys((r.scene, r.mesh, r.method) for r in plain))
    for scene, mesh, method in keys:
        recs = [r for r in plain if (r.scene, r.mesh, r.method) == (scene, mesh, method)]
        good, span, fast, bad = _summary(recs)
        accurate = most_accurate(good) if good else "-"
        lines.append(
            f"| {scene} | {mesh} | {PAPER_NAMES.get(method, method)} | {span} | {fast} | "
            f"{accurate} | {bad} |"
        )
    friction = [r for r in records if not math.isnan(r.mu)]
    if not plain:
        return friction_table(friction)
    return "\n".join(lines) + ("\n\n" + friction_table(friction) if friction else "")


def friction_table(records: Sequence[TradeoffRecord]) -> str:
    """Friction cases per mesh, mu and method: the fastest point and the worst measures.

    Worst over the converged r: displacement error, |F_t / (mu N) - 1| at full
    sliding, slip at a sticking node (length) and tangential complementarity
    residual (force; '-' for the penalty method).
    """
    lines = [
        "| scene | mesh | mu | method | converged r (E/h) | fastest: r, time s, iterations, "
        "u error | worst over converged r: u error, F_t/(mu N) error, stick slip, tangential "
        "residual | not converged at r |",
        "|---|---|---|---|---|---|---|---|",
    ]
    keys = list(dict.fromkeys((r.scene, r.mesh, r.mu, r.method) for r in records))
    for scene, mesh, mu, method in keys:
        key = (scene, mesh, mu, method)
        recs = [r for r in records if (r.scene, r.mesh, r.mu, r.method) == key]
        good, span, fast, bad = _summary(recs)
        worst = ", ".join(
            _fmt(_worst([getattr(r, f) for r in good]))
            for f in ("u_error", "ft_error", "stick_slip", "t_residual")
        ) if good else "-"
        lines.append(
            f"| {scene} | {mesh} | {mu:g} | {PAPER_NAMES.get(method, method)} | {span} | "
            f"{fast} | {worst} | {bad} |"
        )
    return "\n".join(lines)
