"""Run a scene: solve its load path, write XDMF, JSON and pictures as it goes."""

from __future__ import annotations

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
from fenics_contact.solvers.stepping import RunRecord, StepRecord, solve_load_path, start_record


@dataclass
class RunOutcome:
    """What a run produced."""

    problem: ContactProblem
    path: RunRecord
    summary: dict
    out: Path


def _summary(scene: Scene, record: RunRecord) -> dict:
    """summary.json: the scene's identity and settings, then the run record."""
    return {
        "scene": scene.name,
        "scene_file": str(scene.path),
        "dimension": scene.dimension,
        "law": scene.law,
        "E": scene.E,
        "nu": scene.nu,
        "quadrature": scene.contact.quadrature,
        "mu": scene.contact.mu,
        "predictor": scene.solver.predictor,
        "linear_solver": scene.solver.linear_solver,
        "load_steps": scene.solver.steps,
        **record.to_dict(),
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
    problem = build_problem(scene, comm)
    settings = SolverSettings(
        atol=scene.solver.atol, rtol=scene.solver.rtol,
        max_iterations=scene.solver.max_iterations,
    )
    strategy = make_strategy(
        scene.solver.method, problem, settings,
        linear=LinearSolverSettings(kind=scene.solver.linear_solver),
        observer=on_residual, predictor=scene.solver.predictor,
    )
    writer = StepWriter(problem, out / "solution.xdmf", scene.fields)
    record = start_record(strategy)

    def finished(step: StepRecord) -> None:
        writer.write(step.load_factor)
        if comm.rank == 0:
            write_json(out / "summary.json", _summary(scene, record))
        if on_step is not None:
            on_step(step)

    try:
        path = solve_load_path(
            strategy, scene.solver.steps, max_cutbacks=scene.solver.max_cutbacks,
            on_step=finished, record=record,
        )
    finally:
        writer.close()
    summary = _summary(scene, path)
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
        if scene.contact.mu is not None:
            from fenics_contact.output.friction_plot import friction_profile

            friction_profile(
                problem, out / "friction.png",  # type: ignore[arg-type]
                title=f"{scene.name}: tangential traction, load factor "
                f"{path.steps[-1].load_factor:g}",
            )
    return RunOutcome(problem, path, summary, out)


__all__ = ["RunOutcome", "SolveResult", "run_scene"]
