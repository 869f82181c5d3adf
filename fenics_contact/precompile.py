"""Fill the form cache for a scene before its first run.

The first run of a scene on a machine compiles its UFL forms (FFCx, then a
C compiler) and keeps them in the form cache (``$XDG_CACHE_HOME/fenics``,
by default ``~/.cache/fenics``); later runs load them. The compilation is
what a user waits for on a fresh machine: seconds for a rigid obstacle, half
a minute for a 2D mortar pair, about a minute with friction
(docs/benchmarks.md, "Time to the first Newton iteration").
:func:`precompile` builds the scene as ``fenics-contact run`` does and
solves its first load step into a temporary folder, writing that step's
fields and drawing the run's pictures, so that every form a run needs up to
its first written step is compiled; the output is then thrown away. Forms that only a later
event asks for (``auto`` falling back to another strategy, a second
strategy in a sweep) are compiled when they are first used.
"""

from __future__ import annotations

import shutil
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from mpi4py import MPI

from fenics_contact.scene.schema import Scene


@dataclass(frozen=True)
class Precompiled:
    """What :func:`precompile` did for one scene."""

    #: the scene's name
    name: str
    #: "compiled" (first step solved and written) or the solver status of the
    #: first step when it did not converge (its forms are compiled all the same)
    status: str
    #: wall time, seconds (mesh, build, compilation, the first step)
    seconds: float


def precompile(scene: Scene, comm: MPI.Comm = MPI.COMM_WORLD) -> Precompiled:
    """Compile every form of ``scene`` that its run needs up to the first written step.

    Builds the problem and the strategy as ``fenics-contact run`` does, solves
    the first load step, records its support reactions, writes its fields and
    draws the run's pictures into a temporary folder (removed afterwards).
    """
    from fenics_contact.output.xdmf import StepWriter
    from fenics_contact.runner import draw_pictures, scene_strategy
    from fenics_contact.scene.build import build_problem
    from fenics_contact.solvers.stepping import solve_load_path, start_record

    start = time.perf_counter()
    folder = tempfile.mkdtemp(prefix="fenics-contact-compile-") if comm.rank == 0 else None
    out = Path(comm.bcast(folder, root=0))
    try:
        problem = build_problem(scene, comm)
        strategy = scene_strategy(scene, problem)
        record = start_record(strategy)
        writer = StepWriter(problem, out / "solution.xdmf", scene.fields)

        def finished(step) -> None:  # what the run does after each step
            step.reactions = problem.support_reactions()
            writer.write(step.load_factor)

        try:
            solve_load_path(strategy, scene.solver.steps, max_cutbacks=scene.solver.max_cutbacks,
                            on_step=finished, record=record, last_step=1)
        finally:
            writer.close()
        draw_pictures(scene, problem, record, out)
        status = "compiled" if record.steps and record.steps[0].status == "converged" \
            else record.status
    finally:
        comm.barrier()
        if comm.rank == 0:
            shutil.rmtree(out, ignore_errors=True)
    return Precompiled(scene.name, status, time.perf_counter() - start)


__all__ = ["Precompiled", "precompile"]
