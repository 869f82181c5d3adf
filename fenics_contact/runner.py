"""Run a scene: solve its load path, write XDMF, JSON and pictures as it goes."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from mpi4py import MPI

from fenics_contact.model.problem import ContactProblem
from fenics_contact.output.checkpoint import CheckpointWriter, identity, read_latest, restore
from fenics_contact.output.io import write_json
from fenics_contact.output.xdmf import StepWriter
from fenics_contact.scene.build import build_problem
from fenics_contact.scene.schema import Scene
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.base import SolveResult
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.linear import LinearSolverSettings
from fenics_contact.solvers.predictor import Extrapolated
from fenics_contact.solvers.stepping import PathResult, StepRecord, solve_load_path
from fenics_contact.stop import StopRequested


@dataclass
class RunOutcome:
    """What a run produced."""

    problem: ContactProblem
    path: PathResult
    summary: dict
    out: Path


def _summary(scene: Scene, problem: ContactProblem, path: PathResult | None, wall: float) -> dict:
    steps = path.steps if path is not None else []
    return {
        "scene": scene.name,
        "scene_file": str(scene.path),
        "status": path.status if path is not None else "running",
        "method": scene.solver.method,
        "dimension": scene.dimension,
        "law": scene.law,
        "E": scene.E,
        "nu": scene.nu,
        "r_absolute": problem.r_absolute,
        "r_relative": problem.r_relative,
        "quadrature": scene.contact.quadrature,
        "predictor": scene.solver.predictor,
        "linear_solver": scene.solver.linear_solver,
        "displacement_dofs": problem.V.dofmap.index_map.size_global * problem.V.dofmap.index_map_bs,
        "multiplier_dofs": problem.surface.num_dofs,
        "load_steps": scene.solver.steps,
        "steps_completed": sum(s.status == "converged" for s in steps),
        "iterations": sum(s.iterations for s in steps),
        "wall_s": wall,
        "processes": problem.comm.size,
        "steps": [s.to_dict() for s in steps],
    }


def run_scene(
    scene: Scene,
    out: Path,
    *,
    comm: MPI.Comm = MPI.COMM_WORLD,
    on_step: Callable[[StepRecord], None] | None = None,
    on_residual: Callable[[int, float], None] | None = None,
    pictures: bool | None = None,
    resume: bool = False,
) -> RunOutcome:
    """Build and solve ``scene``; write DIR/solution.xdmf, summary.json and pictures.

    Each converged load step is written (fields, checkpoint, summary.json)
    at once, so a failing or stopped run leaves the completed ones on disk.
    ``resume`` continues from the checkpoint in ``out`` (after its last
    finished step); a checkpoint of another scene or process count raises
    :class:`~fenics_contact.output.checkpoint.CheckpointError`.
    """
    start = time.perf_counter()
    run_identity = identity(scene, comm.size)
    marker = read_latest(out / "checkpoint", run_identity) if resume else None  # before building
    problem = build_problem(scene, comm)
    settings = SolverSettings(
        atol=scene.solver.atol, rtol=scene.solver.rtol,
        max_iterations=scene.solver.max_iterations,
    )
    strategy = make_strategy(scene.solver.method, problem, settings)
    strategy.observer = on_residual  # type: ignore[attr-defined]
    if scene.solver.linear_solver == "iterative":
        strategy.kernel.set_linear_solver(  # type: ignore[attr-defined]
            LinearSolverSettings(kind="iterative")
        )
    saved = restore(out / "checkpoint", problem, marker) if marker is not None else None
    if scene.solver.predictor == "extrapolate":
        strategy = Extrapolated(strategy)
        if saved is not None and saved.history:
            strategy.history = saved.history
    before = [StepRecord(**r) for r in saved.records] if saved is not None else []
    first = saved.step + 1 if saved is not None else 1
    # an old run's checkpoint goes before its step files: never one without the other
    checkpoint = CheckpointWriter(out / "checkpoint", problem, run_identity, fresh=not resume)
    writer = StepWriter(problem, out / "solution.xdmf", scene.fields, first_step=first)
    done: list[StepRecord] = list(before)

    def finished(step: StepRecord) -> None:
        writer.write(step.load_factor)
        done.append(step)
        history = strategy.history if isinstance(strategy, Extrapolated) else []
        checkpoint.write(step.step, [s.to_dict() for s in done], history)
        partial = PathResult("running", list(done))
        if comm.rank == 0:
            write_json(out / "summary.json", _summary(scene, problem, partial, 0.0))
        if on_step is not None:
            on_step(step)

    try:
        path = solve_load_path(
            strategy, scene.solver.steps, max_cutbacks=scene.solver.max_cutbacks,
            on_step=finished, first_step=first,
        )
    except StopRequested:
        if comm.rank == 0:
            write_json(out / "summary.json", _summary(
                scene, problem, PathResult("interrupted", done), time.perf_counter() - start
            ))
        raise
    finally:
        writer.close()
    path = PathResult(path.status, before + path.steps)
    summary = _summary(scene, problem, path, time.perf_counter() - start)
    if comm.rank == 0:
        write_json(out / "summary.json", summary)
    draw = scene.pictures if pictures is None else pictures
    if draw:
        from fenics_contact.output.pictures import deformed_contact_picture
        from fenics_contact.output.plotting import step_residuals

        deformed_contact_picture(
            problem, out / "deformed.png",
            title=f"{scene.name}: load factor {path.steps[-1].load_factor:g} ({path.status})",
        )
        if comm.rank == 0:
            step_residuals(path.steps, out / "residuals.png", title=scene.name)
    return RunOutcome(problem, path, summary, out)


__all__ = ["RunOutcome", "SolveResult", "run_scene"]
