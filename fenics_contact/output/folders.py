"""Check an output folder before any heavy work: it exists or can be made, and takes files."""

from __future__ import annotations

import os
import tempfile
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
