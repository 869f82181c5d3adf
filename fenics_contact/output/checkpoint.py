"""Checkpoints: the state after each finished load step, to resume a stopped run.

Layout (in the run's output folder)::

    checkpoint/latest.json              which step, the run's identity, the step records
    checkpoint/step_0007/rank_0000.npz  each process's owned displacement and
    checkpoint/step_0007/rank_0001.npz  multiplier values (and predictor history)

Every process writes its own NumPy file of the degrees of freedom it owns
(no parallel I/O library needed, so it works with the DOLFINx wheel and
with any MPI). Once all have written, process 0 replaces ``latest.json``
atomically and removes the previous step's folder, so a stop at any moment
leaves one complete checkpoint. The owned DOF coordinates are stored too:
a resume checks them, so a changed mesh, order or partition is refused
rather than read into the wrong places.

What must match to resume (:func:`identity`): number of processes, method,
load steps, body, material, conditions, obstacle and contact settings.
Solver tolerances, iteration limits, cut-backs, predictor, linear solver,
output fields and pictures may change (e.g. more iterations for a step
that failed).
"""

from __future__ import annotations

import dataclasses
import json
import shutil
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from dolfinx import fem

from fenics_contact.model.problem import ContactProblem
from fenics_contact.output.io import _clean, write_json
from fenics_contact.scene.schema import Scene

#: Checkpoint layout version; a reader refuses others.
FORMAT = 1
LATEST = "latest.json"
_KEYS = {
    "u", "lam", "load_factor", "history_t", "history_u", "history_lam", "u_coordinates",
    "lam_coordinates",
}


class CheckpointError(ValueError):
    """A checkpoint that is missing, damaged or made for another run."""


@dataclass
class Checkpoint:
    """The state of a run after its last finished load step.

    Attributes:
        step: the last finished load step (1-based).
        load_factor: its load factor.
        records: the step records (dicts) of steps 1 .. step, for summary.json.
        history: the predictor's converged states (load factor, full local
            displacement, full local multiplier arrays, ghosts included), oldest first.
    """

    step: int
    load_factor: float
    records: list[dict]
    history: list[tuple[float, np.ndarray, np.ndarray]]


def identity(scene: Scene, processes: int) -> dict:
    """What a checkpoint must share with the scene that resumes it (JSON-safe)."""
    return _json_roundtrip({
        "format": FORMAT,
        "processes": processes,
        "method": scene.solver.method,
        "load_steps": scene.solver.steps,
        "dimension": scene.dimension,
        "mesh": dataclasses.asdict(scene.mesh),
        "law": scene.law,
        "E": scene.E,
        "nu": scene.nu,
        "dirichlet": [dataclasses.asdict(b) for b in scene.dirichlet],
        "tractions": [dataclasses.asdict(b) for b in scene.tractions],
        "obstacle": dataclasses.asdict(scene.obstacle),
        "contact": dataclasses.asdict(scene.contact),
    })


def _json_roundtrip(data: dict) -> dict:
    """``data`` as JSON reads it back (tuples to lists, paths to strings, int keys to str)."""
    return json.loads(json.dumps(_clean(data), default=str))


def read_latest(folder: Path, expected: dict) -> dict:
    """Read ``folder/latest.json`` and check it against ``expected`` (cheap: no mesh needed).

    Raises:
        CheckpointError: no checkpoint, or it differs from ``expected``; the
            message names each difference.
    """
    latest = folder / LATEST
    if not latest.is_file():
        raise CheckpointError(
            f"No checkpoint in {folder} (no {LATEST}): nothing to resume; "
            "run without --resume to start afresh."
        )
    try:
        marker = json.loads(latest.read_text())
        saved = marker["identity"]
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise CheckpointError(f"Checkpoint {latest} is damaged ({exc}); start afresh.") from exc
    expected = _json_roundtrip(expected)
    differ = [
        f"{key}: checkpoint {saved.get(key)!r}, now {expected.get(key)!r}"
        for key in sorted(set(saved) | set(expected))
        if saved.get(key) != expected.get(key)
    ]
    if differ:
        raise CheckpointError(
            f"The checkpoint in {folder} was written by another run and cannot be "
            f"resumed by this one ({'; '.join(differ)}). Resume with the scene and number "
            "of processes that wrote it, or run without --resume to start afresh."
        )
    return marker


def _owned(f: fem.Function) -> np.ndarray:
    im = f.function_space.dofmap.index_map
    return f.x.array[: im.size_local * f.function_space.dofmap.index_map_bs]


def _owned_coordinates(f: fem.Function) -> np.ndarray:
    im = f.function_space.dofmap.index_map
    return f.function_space.tabulate_dof_coordinates()[: im.size_local]


def _rank_file(folder: Path, step: int, rank: int) -> Path:
    return folder / f"step_{step:04d}" / f"rank_{rank:04d}.npz"


class CheckpointWriter:
    """Writes a checkpoint after each finished load step (collective).

    Args:
        folder: the checkpoint folder, e.g. ``DIR/checkpoint``.
        problem: the problem whose state is saved.
        identity: what a resume must match (see :func:`identity`).
        fresh: remove an earlier run's checkpoint first (a new run in an old folder).
    """

    def __init__(
        self, folder: Path, problem: ContactProblem, identity: dict, *, fresh: bool
    ) -> None:
        self.folder = folder
        self.problem = problem
        self.identity = identity
        comm = problem.comm
        if comm.rank == 0:
            if fresh:
                shutil.rmtree(folder, ignore_errors=True)
            folder.mkdir(parents=True, exist_ok=True)
        comm.Barrier()
        self._coordinates = {
            "u_coordinates": _owned_coordinates(problem.u),
            "lam_coordinates": _owned_coordinates(problem.lam),
        }

    def write(
        self,
        step: int,
        records: list[dict],
        history: list[tuple[float, np.ndarray, np.ndarray]] = (),  # type: ignore[assignment]
    ) -> None:
        """Save the state after load step ``step`` (records: steps 1 .. step)."""
        p = self.problem
        comm = p.comm
        path = _rank_file(self.folder, step, comm.rank)
        path.parent.mkdir(parents=True, exist_ok=True)
        nu, nl = _owned(p.u).size, _owned(p.lam).size
        np.savez(
            path,
            u=_owned(p.u),
            lam=_owned(p.lam),
            load_factor=np.float64(p.load_factor),
            history_t=np.array([h[0] for h in history], dtype=np.float64),
            history_u=np.array([h[1][:nu] for h in history]).reshape(len(history), nu),
            history_lam=np.array([h[2][:nl] for h in history]).reshape(len(history), nl),
            **self._coordinates,
        )
        comm.Barrier()  # every process's file is complete
        if comm.rank == 0:
            write_json(self.folder / LATEST, {
                "step": step,
                "load_factor": p.load_factor,
                "identity": self.identity,
                "records": records,
            })
            for old in self.folder.glob("step_*"):
                if old.name != f"step_{step:04d}":
                    shutil.rmtree(old, ignore_errors=True)


def _full(f: fem.Function, owned: np.ndarray) -> np.ndarray:
    """The full local array (ghosts included) of ``f``'s space holding ``owned``."""
    g = fem.Function(f.function_space)
    g.x.array[: owned.size] = owned
    g.x.scatter_forward()
    return g.x.array.copy()


def restore(folder: Path, problem: ContactProblem, marker: dict) -> Checkpoint:
    """Load the checkpoint ``marker`` names into ``problem`` (fields and load factor).

    Collective. Raises :class:`CheckpointError` (on every process) when a
    process's file is missing or its DOFs do not sit where the problem's do.
    """
    comm = problem.comm
    step = int(marker["step"])
    path = _rank_file(folder, step, comm.rank)
    problem_here = None
    data: dict[str, np.ndarray] = {}
    try:
        with np.load(path) as npz:
            data = {k: npz[k] for k in npz.files}
    except (OSError, ValueError, EOFError) as exc:
        problem_here = f"process {comm.rank}: {path} unreadable ({exc})"
    missing = sorted(_KEYS - set(data))
    if problem_here is None and missing:
        problem_here = f"process {comm.rank}: {path} lacks {missing}"
    if problem_here is None:
        for name, f in (("u", problem.u), ("lam", problem.lam)):
            mine = _owned_coordinates(f)
            saved = data[f"{name}_coordinates"]
            if saved.shape != mine.shape or not np.allclose(saved, mine, rtol=0, atol=1e-12 * (
                1.0 + float(np.abs(mine).max(initial=0.0))
            )):
                problem_here = (
                    f"process {comm.rank}: the {'displacement' if name == 'u' else 'multiplier'}"
                    f" DOFs ({saved.shape[0]} saved, {mine.shape[0]} now) are not where the "
                    "checkpoint has them: the mesh changed"
                )
                break
    problems = [m for m in comm.allgather(problem_here) if m is not None]
    if problems:
        raise CheckpointError(
            f"Checkpoint {folder} (step {step}) does not fit this scene: {'; '.join(problems)}. "
            "Run without --resume to start afresh."
        )
    problem.u.x.array[:] = _full(problem.u, data["u"])
    problem.lam.x.array[:] = _full(problem.lam, data["lam"])
    problem.set_load(float(data["load_factor"]))
    history = [
        (float(t), _full(problem.u, hu), _full(problem.lam, hl))
        for t, hu, hl in zip(data["history_t"], data["history_u"], data["history_lam"],
                             strict=True)
    ]
    comm.Barrier()
    return Checkpoint(step, float(data["load_factor"]), list(marker["records"]), history)


__all__ = [
    "FORMAT", "Checkpoint", "CheckpointError", "CheckpointWriter", "identity", "read_latest",
    "restore",
]
