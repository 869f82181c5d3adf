"""Sweep progress: every finished run appended to a CSV file at once and printed on rank 0."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any


def progress_to_csv(
    path: Path, line: Callable[[Any], str], tolerance: str
) -> tuple[list[Any], Callable[[Any], None]]:
    """The records so far and the callback that keeps one more.

    The callback names ``tolerance`` (where the sweep's tolerance is set) in
    a record's round-off stall advice
    (:func:`~fenics_contact.solvers.stepping.name_tolerance`), rewrites
    ``path`` with every record's ``row()`` (so a crash keeps the finished
    runs on disk) and prints ``line(record)`` on rank 0.
    """
    from mpi4py import MPI

    from fenics_contact.output.io import write_csv
    from fenics_contact.solvers.stepping import name_tolerance

    records: list[Any] = []
    rank0 = MPI.COMM_WORLD.rank == 0

    def keep(record: Any) -> None:
        name_tolerance(record, tolerance)
        records.append(record)
        write_csv(path, [r.row() for r in records])
        if rank0:
            print(line(record), flush=True)

    return records, keep
