"""Checkpoints: the state after each finished load step, to resume a stopped run.

Layout (in the run's output folder)::

    checkpoint/latest.json              which step, the run's identity, the step records
    checkpoint/step_0007/rank_0000.npz  each process's owned displacement and
    checkpoint/step_0007/rank_0001.npz  multiplier values (and predictor history,
                                        and each contact's search memory)

Every process writes its own NumPy file of the degrees of freedom it owns
(no parallel I/O library needed, so it works with the DOLFINx wheel and
with any MPI). Once all have written, process 0 replaces ``latest.json``
atomically and removes the previous step's files, so a stop at any moment
leaves one complete checkpoint. Nothing else in the folder is touched: a new
run in an old folder removes the files above and leaves any other. The owned
DOF coordinates are stored too: a resume checks them, so a changed mesh,
order or partition is refused rather than read into the wrong places.

What must match to resume (:func:`identity`): everything of the scene that
changes the answer, taken from the scene's dataclasses as a whole (so a new
scene key is covered without a word here): the number of processes, the
method and load steps, the mesh (its parameters and the file's content), the
bodies and their laws and constants, the conditions, obstacles, contact
settings and pairs. Only what cannot change the answer may differ (e.g. more
iterations for a step that failed): the scene's name and description, solver
tolerances, iteration limits, cut-backs, predictor, linear solver, output
fields and pictures. The step files named by the index are fingerprinted
(size and SHA-256) in ``latest.json``, so a truncated or altered step file is
named on resume instead of being continued.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import re
import zipfile
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from dolfinx import fem

from fenics_contact.model.problem import ContactProblem
from fenics_contact.output.folders import agree, write_failure
from fenics_contact.output.io import _clean, write_json
from fenics_contact.scene.schema import Scene

#: Checkpoint layout version; a reader refuses others.
FORMAT = 3
#: Scene fields that cannot change the answer (a resume may change them).
_FREE_SCENE_KEYS = frozenset({"path", "name", "description", "fields", "pictures"})
#: Solver settings that change the answer; the others (tolerances, limits, predictor,
#: linear solver) may change on resume.
_ANSWER_SOLVER_KEYS = ("method", "steps")
LATEST = "latest.json"
#: The names a checkpoint gives its step folders and its processes' files (nothing else
#: in the folder is removed).
_STEP_FOLDER = re.compile(r"step_\d{4,}")
_RANK_FILE = re.compile(r"rank_\d{4,}\.npz")
_KEYS = {
    "u", "load_factor", "committed_load_factor", "history_t", "history_u", "history_lam",
    "u_coordinates",
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
        gaps: the nodal gaps of those states, when the predictor keeps them
            (owned values joined over the contacts; empty otherwise).
        r_cap: the top of the working r that ``auto`` lowered after a failure
            (relative to E/h; None when it did not, or another method).
    """

    step: int
    load_factor: float
    records: list[dict]
    history: list[tuple[float, np.ndarray, np.ndarray]]
    gaps: list[np.ndarray] = field(default_factory=list)
    r_cap: float | None = None


def _file_digest(path: Path) -> str:
    """SHA-256 of a file's content (hex)."""
    digest = hashlib.sha256()
    with path.open("rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def identity(scene: Scene, processes: int) -> dict:
    """What a checkpoint must share with the scene that resumes it (JSON-safe).

    The whole scene but the keys in ``_FREE_SCENE_KEYS`` and the solver
    settings outside ``_ANSWER_SOLVER_KEYS``, plus the process count and the
    content of the mesh file.
    """
    data = {k: v for k, v in dataclasses.asdict(scene).items() if k not in _FREE_SCENE_KEYS}
    data["solver"] = {k: data["solver"][k] for k in _ANSWER_SOLVER_KEYS}
    mesh_file = scene.mesh.file
    if mesh_file is not None and mesh_file.is_file():
        data["mesh_file_sha256"] = _file_digest(mesh_file)
    return _json_roundtrip({"format": FORMAT, "processes": processes, **data})


def _flat(value: object, prefix: str = "") -> dict[str, object]:
    """Nested dicts and lists as {'bodies[1].E': 100.0, ...}, for naming differences."""
    if isinstance(value, dict):
        items = [(f"{prefix}.{k}" if prefix else str(k), v) for k, v in value.items()]
    elif isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
        items = [(f"{prefix}[{i}]", v) for i, v in enumerate(value)]
    else:
        return {prefix: value}
    out: dict[str, object] = {}
    for key, item in items:
        out.update(_flat(item, key))
    return out


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
    if not isinstance(saved, dict):
        raise CheckpointError(f"Checkpoint {latest} is damaged (no identity); start afresh.")
    expected = _flat(_json_roundtrip(expected))
    saved = _flat(saved)
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
    _check_files(folder.parent, marker.get("files", {}))
    return marker


def _check_files(out: Path, files: dict) -> None:
    """Every output file the checkpoint fingerprinted is there, whole and unchanged."""
    for name, (size, digest) in files.items():
        path = out / name
        if not path.is_file():
            why = "is missing"
        elif path.stat().st_size != size:
            why = f"has {path.stat().st_size} bytes instead of {size} (truncated or rewritten)"
        elif _file_digest(path) != digest:
            why = "changed since the step was written (its content differs)"
        else:
            continue
        raise CheckpointError(
            f"Output file {path} {why}; the finished steps cannot be continued. "
            "Run without --resume to start afresh."
        )


def _owned(f: fem.Function) -> np.ndarray:
    im = f.function_space.dofmap.index_map
    return f.x.array[: im.size_local * f.function_space.dofmap.index_map_bs]


def _owned_coordinates(f: fem.Function) -> np.ndarray:
    im = f.function_space.dofmap.index_map
    return f.function_space.tabulate_dof_coordinates()[: im.size_local]


def _state_functions(problem: ContactProblem) -> dict[str, fem.Function]:
    """Every field a resume needs, by key: u, each multiplier, the last converged u.

    The multipliers are each contact's lam, then each frictional contact's
    lam_t (the penalty method's committed traction); ``u_prev`` is the
    start of the slip increment (friction only).
    """
    fields = {"u": problem.u}
    fields |= {f"multiplier_{i}": m for i, m in enumerate(problem.multipliers())}
    if problem.u_prev is not None:
        fields["u_prev"] = problem.u_prev
    return fields


def _owned_joined(problem: ContactProblem, joined: np.ndarray) -> np.ndarray:
    """The owned parts of a joined array of the normal multipliers (ghosts included)."""
    parts, start = [], 0
    for m in problem.normal_multipliers():
        parts.append(joined[start:start + _owned(m).size])
        start += m.x.array.size
    return np.concatenate(parts)


def _full_joined(problem: ContactProblem, owned: np.ndarray) -> np.ndarray:
    """Inverse of :func:`_owned_joined`: the joined full local arrays."""
    parts, start = [], 0
    for m in problem.normal_multipliers():
        n = _owned(m).size
        parts.append(_full(m, owned[start:start + n]))
        start += n
    return np.concatenate(parts)


#: The key of a contact's search array in a process's file: search_<contact>_<name>.
_SEARCH_KEY = re.compile(r"search_(\d+)_(.+)")


def _search_arrays(problem: ContactProblem) -> dict[str, np.ndarray]:
    """Each contact's search memory (:meth:`ContactProblem.search_states`) as file entries."""
    states = problem.search_states()
    out = {"search_contacts": np.int64(len(states))}
    for i, state in enumerate(states):
        out |= {f"search_{i}_{key}": np.asarray(value) for key, value in state.items()}
    return out


def _search_states(problem: ContactProblem, data: dict[str, np.ndarray]
                   ) -> list[dict[str, np.ndarray]] | None:
    """The search states of a process's file; None when it has none (an older checkpoint)."""
    if "search_contacts" not in data:
        return None
    states: list[dict[str, np.ndarray]] = [{} for _ in range(int(data["search_contacts"]))]
    for key, value in data.items():
        match = _SEARCH_KEY.fullmatch(key)
        if match is not None and int(match[1]) < len(states):
            states[int(match[1])][match[2]] = value
    return states


def _rank_file(folder: Path, step: int, rank: int) -> Path:
    return folder / f"step_{step:04d}" / f"rank_{rank:04d}.npz"


def _remove_step(step_folder: Path) -> None:
    """Remove a step folder's process files, then the folder if nothing else is left in it."""
    try:
        for entry in step_folder.iterdir():
            if _RANK_FILE.fullmatch(entry.name) and entry.is_file():
                entry.unlink(missing_ok=True)
        step_folder.rmdir()
    except OSError:  # another file in it, or gone already: left as it is
        pass


def _remove_steps(folder: Path, keep: int | None = None) -> None:
    """Remove the process files of every step folder but step ``keep``'s."""
    kept = None if keep is None else f"step_{keep:04d}"
    try:
        old = [e for e in folder.iterdir() if e.name != kept and e.is_dir()
               and _STEP_FOLDER.fullmatch(e.name)]
    except OSError:  # the folder went: the next write names it
        return
    for entry in old:
        _remove_step(entry)


def remove_checkpoint(folder: Path) -> None:
    """Remove the checkpoint files in ``folder`` (``latest.json``, ``step_NNNN/rank_RRRR.npz``).

    Only what a checkpoint writes: other files in the folder (and the folder) stay.
    """
    if not folder.is_dir():
        return
    try:
        (folder / LATEST).unlink(missing_ok=True)
    except OSError:  # unwritable: the next write names it
        return
    _remove_steps(folder)


class CheckpointWriter:
    """Writes a checkpoint after each finished load step (collective).

    Args:
        folder: the checkpoint folder, e.g. ``DIR/checkpoint``.
        problem: the problem whose state is saved.
        identity: what a resume must match (see :func:`identity`).
        fresh: remove an earlier run's checkpoint files first (a new run in an old
            folder; other files in ``folder`` stay).
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
                remove_checkpoint(folder)
            folder.mkdir(parents=True, exist_ok=True)
        comm.Barrier()
        self._coordinates = {
            f"{key}_coordinates": _owned_coordinates(f)
            for key, f in _state_functions(problem).items() if key != "u_prev"
        }
        #: Fingerprints [size, sha256] of the finished steps' files, by path in the run folder.
        self._files: dict[str, list] = {}
        latest = folder / LATEST
        if not fresh and comm.rank == 0 and latest.is_file():
            self._files = dict(json.loads(latest.read_text()).get("files", {}))

    def write(
        self,
        step: int,
        records: list[dict],
        history: list[tuple[float, np.ndarray, np.ndarray]] = (),  # type: ignore[assignment]
        files: Sequence[Path] = (),
        gaps: Sequence[np.ndarray] = (),
        r_cap: float | None = None,
    ) -> None:
        """Save the state after load step ``step`` (records: steps 1 .. step).

        ``history`` and ``gaps``: the predictor's converged states and their
        nodal gaps; ``r_cap``: the working r's cap of ``auto``
        (:class:`Checkpoint`). Each contact's search memory is saved too
        (:meth:`ContactProblem.search_states`).

        ``files``: output files (closed) that a resume must find unchanged;
        their sizes and SHA-256 go into ``latest.json``.
        """
        p = self.problem
        comm = p.comm
        path = _rank_file(self.folder, step, comm.rank)
        nu = _owned(p.u).size
        nl = sum(_owned(m).size for m in p.normal_multipliers())
        failure = None
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            np.savez(
                path,
                **{key: _owned(f) for key, f in _state_functions(p).items()},
                load_factor=np.float64(p.load_factor),
                committed_load_factor=np.float64(p.committed_load_factor),
                history_t=np.array([h[0] for h in history], dtype=np.float64),
                history_u=np.array([h[1][:nu] for h in history]).reshape(len(history), nu),
                history_lam=np.array([_owned_joined(p, h[2]) for h in history]).reshape(
                    len(history), nl),
                history_gap=np.array(list(gaps), dtype=np.float64).reshape(
                    len(gaps), gaps[0].size if len(gaps) else 0),
                **self._coordinates,
                **_search_arrays(p),
                r_cap=np.float64(np.nan if r_cap is None else r_cap),
            )
        except OSError as exc:
            failure = write_failure(exc, path)
        agree(comm, failure)  # every process's file is complete
        if comm.rank == 0:
            try:
                for f in files:
                    self._files[str(f.relative_to(self.folder.parent))] = [
                        f.stat().st_size, _file_digest(f)
                    ]
                write_json(self.folder / LATEST, {
                    "step": step,
                    "load_factor": p.load_factor,
                    "identity": self.identity,
                    "records": records,
                    "files": self._files,
                })
            except OSError as exc:
                failure = write_failure(exc, self.folder / LATEST)
            else:
                _remove_steps(self.folder, keep=step)
        agree(comm, failure)


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
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
        problem_here = f"process {comm.rank}: {path} is damaged or unreadable ({exc})"
    fields = _state_functions(problem)
    missing = sorted((_KEYS | set(fields)) - set(data))
    if problem_here is None and missing:
        problem_here = f"process {comm.rank}: {path} lacks {missing}"
    if problem_here is None:
        for name, f in fields.items():
            if name == "u_prev":
                continue
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
    for name, f in fields.items():
        f.x.array[:] = _full(f, data[name])
    problem.set_load(float(data["load_factor"]))
    searches = _search_states(problem, data)
    failure = None
    if searches is not None:  # absent in older checkpoints: the searches start afresh
        try:
            problem.restore_search_states(searches)
        except ValueError as exc:
            failure = f"process {comm.rank}: {exc}"
    failures = [m for m in comm.allgather(failure) if m is not None]
    if failures:
        raise CheckpointError(
            f"Checkpoint {folder} (step {step}) does not fit this scene: {'; '.join(failures)}. "
            "Run without --resume to start afresh."
        )
    problem.restore_commit(float(data["committed_load_factor"]))
    history = [
        (float(t), _full(problem.u, hu), _full_joined(problem, hl))
        for t, hu, hl in zip(data["history_t"], data["history_u"], data["history_lam"],
                             strict=True)
    ]
    gaps = list(data.get("history_gap", np.zeros((0, 0))))  # absent in older checkpoints
    r_cap = float(data.get("r_cap", np.nan))
    comm.Barrier()
    return Checkpoint(step, float(data["load_factor"]), list(marker["records"]), history, gaps,
                      None if np.isnan(r_cap) else r_cap)


__all__ = [
    "FORMAT", "Checkpoint", "CheckpointError", "CheckpointWriter", "identity", "read_latest",
    "remove_checkpoint", "restore",
]
