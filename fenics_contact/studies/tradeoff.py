"""The speed-accuracy trade: methods x r x mesh on a scene, timed and scored.

For every (scene, mesh, method, r) the load path is solved from zero
(no cut-back, as in the paper) and we record: status, Newton iterations,
linear solves, multiplier updates, wall time (median of ``repeats`` runs;
a run that does not converge is timed once), largest penetration, the
relative L2 displacement error against a tight GNRM reference on the same
mesh, and on the Hertz scene the peak-pressure error against Hertz theory.

Stopping test for every method: atol = max(1e-10 E h^(d-1), round-off
floor at r) (:func:`fenics_contact.model.scaling.scaled_atol`). The reference is
GNRM at r = 1 E/h with 1e-13 E h^(d-1).
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from mpi4py import MPI

from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.scaling import DEFAULT_FORCE_RTOL, scaled_atol
from fenics_contact.solvers import PAPER_NAMES, STRATEGIES, make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings, Status
from fenics_contact.solvers.stepping import RunRecord, solve_load_path, start_record
from fenics_contact.studies.study import relative_l2_error
from fenics_contact.verification.bench_scenes import BarScene, HertzScene

#: r values relative to E/h of the full sweep: 1e-4 ... 1e8, a decade apart.
FULL_R = tuple(10.0**e for e in range(-4, 9))
#: Displacement errors below this are round-off (relative L2); plots and fronts clip to it.
ERROR_FLOOR = 1e-15
METHODS = tuple(STRATEGIES)


def scene_meshes(name: str, count: int = 3) -> list[object]:
    """The scene ``name`` ('hertz' or 'bar') on ``count`` meshes, coarse to fine."""
    if name == "hertz":
        sizes = (0.02, 0.01, 0.005)[:count]
        return [HertzScene(h_contact=h) for h in sizes]
    if name == "bar":
        # SVK: from 24 x 8 on, the strain under the punch corners reaches the law's
        # compressive instability and no method converges (see docs).
        return [BarScene(nx=6 * k, ny=2 * k) for k in (1, 2, 3)[:count]]
    raise ValueError(f"Unknown trade-off scene {name!r}; use 'hertz' or 'bar'.")


@dataclass
class TradeoffRecord(RunRecord):
    """One (scene, mesh, method, r) point of the trade-off: the run record plus its place.

    ``error`` is the displacement error against the GNRM reference on the
    same mesh; ``p0_error`` the Hertz peak-pressure error (NaN off Hertz);
    ``wall_s`` the median over ``repeats`` runs.
    """

    scene: str = ""
    mesh: str = ""
    repeats: int = 1
    p0_error: float = math.nan
    pareto_u: bool = False
    pareto_p0: bool = False

    @property
    def u_error(self) -> float:
        """Relative L2 displacement error against the reference."""
        return self.error

    def row(self) -> dict[str, object]:
        """Flat row, with the displacement error also named ``u_error``."""
        return {**super().row(), "u_error": self.error}


def reference_dofs(scene: object, comm: MPI.Comm = MPI.COMM_WORLD) -> object:
    """Tight GNRM solution on the scene's mesh (dof values of u); None if it fails."""
    problem = scene.build(ContactSettings(r=1.0, relative=True), comm)
    settings = SolverSettings(atol=scaled_atol(problem, 1e-13), max_iterations=100)
    path = solve_load_path(make_strategy("gnrm", problem, settings), scene.steps, max_cutbacks=4)
    if not path.converged:
        return None  # errors against it are then NaN
    return problem.u.x.array.copy()


def run_point(
    scene: object,
    scene_name: str,
    method: str,
    r: float,
    reference: object,
    *,
    repeats: int = 3,
    max_iterations: int = 200,
    force_rtol: float = DEFAULT_FORCE_RTOL,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> TradeoffRecord:
    """Solve one point ``repeats`` times (once if it fails); score the last run."""
    times: list[float] = []
    for _ in range(max(repeats, 1)):
        problem = scene.build(ContactSettings(r=r, relative=True), comm)
        settings = SolverSettings(atol=scaled_atol(problem, force_rtol),
                                  max_iterations=max_iterations)
        strategy = make_strategy(method, problem, settings)
        record = TradeoffRecord(
            **vars(start_record(strategy)), scene=scene_name, mesh=scene.label
        )
        solve_load_path(strategy, scene.steps, max_cutbacks=0, record=record)
        times.append(record.wall_s)
        if not record.converged:
            break
    record.repeats = len(times)
    record.wall_s = statistics.median(times)
    if record.converged and reference is not None:
        record.error = relative_l2_error(problem.u, reference)
    if record.converged and hasattr(scene, "peak_pressure_error"):
        record.p0_error = abs(scene.peak_pressure_error(problem))
    return record


def run_tradeoff(
    scenes: Sequence[str],
    methods: Sequence[str],
    r_values: Sequence[float],
    *,
    meshes: int = 3,
    progress: Callable[[TradeoffRecord], None] | None = None,
    **options: float,
) -> list[TradeoffRecord]:
    """Sweep scenes x meshes x methods x r; mark the Pareto front per scene."""
    records = []
    for name in scenes:
        for scene in scene_meshes(name, meshes):
            reference = reference_dofs(scene)
            for method in methods:
                for r in r_values:
                    record = run_point(scene, name, method, r, reference, **options)
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


def mark_pareto(records: Sequence[TradeoffRecord]) -> None:
    """Mark the Pareto fronts among converged records.

    ``pareto_u``: displacement error against time, per scene and mesh (the
    solver's trade on one discretisation). ``pareto_p0``: Hertz peak-pressure
    error against time over all meshes of the scene (the whole trade).
    """
    ok = [r for r in records if r.status == Status.CONVERGED]
    for key in {(r.scene, r.mesh) for r in ok}:
        points = [r for r in ok if (r.scene, r.mesh) == key and math.isfinite(r.u_error)]
        for i in _front(points, lambda r: max(r.u_error, ERROR_FLOOR)):
            points[i].pareto_u = True
    for scene in {r.scene for r in ok}:
        points = [r for r in ok if r.scene == scene and math.isfinite(r.p0_error)]
        for i in _front(points, lambda r: r.p0_error):
            points[i].pareto_p0 = True


def _fmt(x: float) -> str:
    return "-" if not math.isfinite(x) else f"{x:.1e}"


def markdown_table(records: Sequence[TradeoffRecord]) -> str:
    """Per scene and mesh, per method: the best converged point and where it fails.

    Columns: fastest converged r, its time and error; the r at which the
    method is most accurate; and the r values (relative) that did not converge.
    """
    lines = [
        "| scene | mesh | method | converged r (E/h) | fastest: r, time s, iterations, error | "
        "most accurate: r, error | not converged at r |",
        "|---|---|---|---|---|---|---|",
    ]
    keys = list(dict.fromkeys((r.scene, r.mesh, r.method) for r in records))
    for scene, mesh, method in keys:
        recs = [r for r in records if (r.scene, r.mesh, r.method) == (scene, mesh, method)]
        good = [r for r in recs if r.status == Status.CONVERGED]
        bad = [f"{r.r_relative:g} ({r.status})" for r in recs if r.status != Status.CONVERGED]
        if good:
            fast = min(good, key=lambda r: r.wall_s)
            best = min(good, key=lambda r: (max(error_of(r), ERROR_FLOOR), r.wall_s))
            span = f"{min(r.r_relative for r in good):g} - {max(r.r_relative for r in good):g}"
            fastest = (f"{fast.r_relative:g}, {fast.wall_s:.3f}, {fast.iterations}, "
                       f"{_fmt(error_of(fast))}")
            accurate = f"{best.r_relative:g}, {_fmt(error_of(best))}"
        else:
            span, fastest, accurate = "none", "-", "-"
        lines.append(
            f"| {scene} | {mesh} | {PAPER_NAMES.get(method, method)} | {span} | {fastest} | "
            f"{accurate} | {', '.join(bad) or '-'} |"
        )
    return "\n".join(lines)
