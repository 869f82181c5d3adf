"""Check an output folder before any heavy work: it exists or can be made, and takes files."""

from __future__ import annotations

import contextlib
import os
import socket
import tempfile
from collections.abc import Iterator
from pathlib import Path


class OutputFolderError(ValueError):
    """The output folder cannot be created or written; the message names it and the fix."""


def prepare_output_folder(out: Path, comm=None, option: str = "--out") -> Path:
    """Prove that ``out`` can be created (with parents) and written, creating nothing.

    Raises :class:`OutputFolderError` (one line: the folder, the reason, the
    fix, naming the command-line ``option`` that gave the folder) instead of
    the OSError a solver would meet after minutes of work. With an MPI
    communicator, rank 0 checks and every rank raises alike.
    """
    if comm is None or comm.size == 1:
        return _prepare(Path(out), option)
    problem = None
    if comm.rank == 0:
        try:
            _prepare(Path(out), option)
        except OutputFolderError as exc:
            problem = str(exc)
    problem = comm.bcast(problem, root=0)
    if problem is not None:
        raise OutputFolderError(problem)
    return Path(out)


def _prepare(out: Path, option: str = "--out") -> Path:
    """Check without leaving a trace: the nearest existing ancestor takes a new entry."""
    out = out.absolute()
    existing = out
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir():
        what = "an existing file" if existing == out else f"below the file {existing}"
        raise OutputFolderError(
            f"cannot create output folder {out}: it is {what}, not a folder; "
            f"choose another {option}."
        )
    try:
        probe = tempfile.mkdtemp(prefix=".write-test-", dir=existing)
        os.rmdir(probe)
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise OutputFolderError(
            f"cannot write to output folder {out} ({existing}: {reason}); "
            f"choose a writable {option}."
        ) from None
    return out


#: The file in an output folder that says which process writes there.
LOCK = ".fenics-contact.lock"


def _alive(pid: int) -> bool:
    """True when a process ``pid`` runs on this machine (a zombie, killed, does not)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return True
    return state not in ("Z", "X")


def _take_lock(out: Path, option: str) -> str | None:
    """Write this process's lock into ``out``; the refusal when a live run holds it.

    A folder that does not exist yet is not created here (a scene refused
    later leaves nothing behind) and takes no lock: no run writes there.
    """
    if not out.is_dir():
        return None
    path = out / LOCK
    mine = f"{os.getpid()} {socket.gethostname()}"
    for _ in range(2):
        try:
            fd = os.open(path, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
        except FileExistsError:
            try:
                pid, host = path.read_text().split()[:2]
            except (OSError, ValueError):
                pid, host = "0", ""
            if host == socket.gethostname() and not _alive(int(pid)):
                path.unlink(missing_ok=True)  # left by a run that was killed
                continue
            where = "" if host == socket.gethostname() else f" on {host}"
            return (f"another run (process {pid}{where}) is writing to {out}; wait for it "
                    f"to finish or choose another {option} (if no run writes there, remove "
                    f"{path})")
        with os.fdopen(fd, "w") as f:
            f.write(mine)
        return None
    return None


@contextlib.contextmanager
def run_lock(out: Path, comm=None, option: str = "--out") -> Iterator[None]:
    """Hold ``out`` for one run: a second run or a ``--resume`` into it is refused.

    Raises :class:`OutputFolderError` on every process when a live process
    holds the folder (a run killed with SIGKILL leaves a lock whose process
    is gone: it is taken over). Rank 0 writes and removes the lock; a folder
    that does not exist yet takes none.
    """
    rank0 = comm is None or comm.rank == 0
    problem = _take_lock(Path(out), option) if rank0 else None
    if comm is not None and comm.size > 1:
        problem = comm.bcast(problem, root=0)
    if problem is not None:
        raise OutputFolderError(problem)
    held = rank0 and (Path(out) / LOCK).is_file()
    try:
        yield
    finally:
        if held:
            (Path(out) / LOCK).unlink(missing_ok=True)


class OutputWriteError(RuntimeError):
    """A file of the run's output could not be written (disk full, folder removed, read-only).

    Raised on every process alike (see :func:`agree`); the message names the
    file and the operating system's reason.
    """


def write_failure(exc: BaseException, path: Path) -> str:
    """One line naming the file a write failed on and why (``path`` when the error names none)."""
    name = getattr(exc, "filename", None) or path
    reason = getattr(exc, "strerror", None) or " ".join(str(exc).split()) or type(exc).__name__
    return f"cannot write {name} ({reason})"


def agree(comm, failure: str | None) -> None:
    """Collective: raise :class:`OutputWriteError` on every process when one of them failed.

    Stands where a barrier would: every process reaches it after its share of
    a write, so a failure on one process stops them all at the same point
    instead of leaving the others waiting in the next collective call.
    """
    failures = [f for f in comm.allgather(failure) if f]
    if failures:
        raise OutputWriteError(failures[0])
