"""Output: JSON and CSV records, surface fields mapped onto the body.

The XDMF fields per load step are written by :mod:`fenics_contact.output.xdmf`.
"""

from __future__ import annotations

import csv
import json
import math
import os
from collections.abc import Iterable, Mapping
from pathlib import Path

import numpy as np
from dolfinx import fem

from fenics_contact.model.problem import ContactProblem


def _clean(value: object) -> object:
    """Make a value JSON-safe: numpy scalars to Python, NaN/inf to strings."""
    if isinstance(value, dict):
        return {str(k): _clean(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_clean(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, np.ndarray):
        return [_clean(v) for v in value.tolist()]
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    return value


def write_json(path: Path, data: object) -> None:
    """Write ``data`` as indented JSON (parent folders created), replacing the file atomically.

    Call it from one process: it knows nothing of MPI.
    """
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text(json.dumps(_clean(data), indent=2) + "\n")
    tmp.replace(path)


def write_csv(path: Path, rows: Iterable[Mapping[str, object]]) -> None:
    """Write dict rows as CSV; the columns are the keys of the first row."""
    rows = list(rows)
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as f:
        if not rows:
            return
        writer = csv.DictWriter(f, fieldnames=list(rows[0]), extrasaction="ignore")
        writer.writeheader()
        for row in rows:
            writer.writerow({k: _clean(v) for k, v in row.items()})


class SurfaceToBody:
    """Copies nodal values on the contact submesh into a P1 field on the body.

    Each multiplier node is mapped to its own parent vertex through the
    submesh's node map (never by coordinates: two bodies meshed touching have
    distinct vertices at one point); body nodes off the contact surface keep
    the fill value.
    """

    def __init__(self, problem: ContactProblem) -> None:
        self.W = fem.functionspace(problem.domain, ("Lagrange", 1))
        self.body_dofs = problem.surface.parent_dofs(self.W).astype(np.int32)

    def field(self, name: str, values: np.ndarray, fill: float = 0.0) -> fem.Function:
        """A body P1 function holding ``values`` (all local surface dofs) on the surface."""
        f = fem.Function(self.W, name=name)
        f.x.array[:] = fill
        f.x.array[self.body_dofs] = values
        return f

    def vector_field(self, name: str, values: np.ndarray) -> fem.Function:
        """A body vector P1 function holding nodal vectors, zero off the surface.

        ``values`` has shape (all local surface dofs, gdim), ghosts included.
        """
        gdim = values.shape[1]
        if getattr(self, "_Wv", None) is None:
            self._Wv = fem.functionspace(self.W.mesh, ("Lagrange", 1, (gdim,)))
        f = fem.Function(self._Wv, name=name)
        for i in range(gdim):
            f.x.array[self.body_dofs * gdim + i] = values[:, i]
        return f

