"""Run a scene: solve its load path, write XDMF, JSON and pictures as it goes."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from mpi4py import MPI

from fenics_contact.model.problem import ContactProblem
from fenics_contact.output.io import StepWriter, write_json
from fenics_contact.scene.build import build_problem
from fenics_contact.scene.schema import Scene
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.base import SolveResult
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.linear import LinearSolverSettings
from fenics_contact.solvers.predictor import Extrapolated
from fenics_contact.solvers.stepping import PathResult, StepRecord, solve_load_path


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
        "pairs": [
            {
                "name": pair.name, "striker": pair.striker, "target": pair.target,
                "steps": [
                    {"step": s.step, "load_factor": s.load_factor,
                     "normal_force": s.contact_force, "active_count": s.active_count,
                     "max_penetration": s.max_penetration}
                    for s in steps
                ],
            }
            for pair in scene.pairs
        ] if scene.two_body else [],
        "bodies": [
            {"name": b.name, "tag": b.tag, "law": b.law, "E": b.E, "nu": b.nu}
            for b in scene.bodies
        ],
    }


def run_scene(
    scene: Scene,
    out: Path,
    *,
    comm: MPI.Comm = MPI.COMM_WORLD,
    on_step: Callable[[StepRecord], None] | None = None,
    on_residual: Callable[[int, float], None] | None = None,
    pictures: bool | None = None,
) -> RunOutcome:
    """Build and solve ``scene``; write DIR/solution.xdmf, summary.json and pictures.

    Each converged load step is written to the XDMF file and summary.json at
    once, so a failing step leaves the completed ones on disk.
    """
    start = time.perf_counter()
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
    if scene.solver.predictor == "extrapolate":
        strategy = Extrapolated(strategy)
    writer = StepWriter(problem, out / "solution.xdmf", scene.fields)
    done: list[StepRecord] = []

    def finished(step: StepRecord) -> None:
        writer.write(step.load_factor)
        done.append(step)
        partial = PathResult("running", list(done))
        if comm.rank == 0:
            write_json(out / "summary.json", _summary(scene, problem, partial, 0.0))
        if on_step is not None:
            on_step(step)

    try:
        path = solve_load_path(
            strategy, scene.solver.steps, max_cutbacks=scene.solver.max_cutbacks,
            on_step=finished,
        )
    finally:
        writer.close()
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
