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
    """Copies nodal values on a contact submesh into a P1 field on the body.

    Each multiplier node is mapped to its own parent vertex through the
    submesh's node map (never by coordinates: two bodies meshed touching have
    distinct vertices at one point); body nodes off the contact surface keep
    the fill value. ``contact``: which contact (default the first); ``W``:
    the body's P1 space to share with other mappers.
    """

    def __init__(self, problem: ContactProblem, contact=None,
                 W: fem.FunctionSpace | None = None) -> None:
        contact = problem.contacts[0] if contact is None else contact
        self.W = fem.functionspace(problem.domain, ("Lagrange", 1)) if W is None else W
        self.body_dofs = contact.surface.parent_dofs(self.W).astype(np.int32)

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


class ContactsToBody:
    """Every contact's owned nodal values as one body P1 field (contacts in order).

    Off every contact surface the field is zero. Where two contacts share a
    node (a body touching two obstacles at a corner) pressures and tractions
    add, the gap is the smaller one and the active and stick/slip marks the
    larger one (a node in contact anywhere is not written open); other
    values are the later contact's.
    """

    def __init__(self, problem: ContactProblem) -> None:
        self.W = fem.functionspace(problem.domain, ("Lagrange", 1))
        self._maps = [(SurfaceToBody(problem, c, self.W), fem.Function(c.Q))
                      for c in problem.contacts]
        self._Wv: fem.FunctionSpace | None = None

    def _local(self, values: np.ndarray, q: fem.Function) -> np.ndarray:
        """Owned values of one contact, ghosts filled in (all local surface dofs)."""
        q.x.array[:] = 0.0
        q.x.array[: values.size] = values
        q.x.scatter_forward()
        return q.x.array

    def field(self, name: str, per_contact: list[np.ndarray], *, add: bool = False,
              combine: str = "last") -> fem.Function:
        """A body P1 function from each contact's owned nodal values.

        At a node two contacts share: ``add`` (or ``combine = "add"``) sums,
        ``"min"`` and ``"max"`` keep the smaller or larger value, ``"last"``
        the later contact's.
        """
        combine = "add" if add else combine
        f = fem.Function(self.W, name=name)
        seen = np.zeros(f.x.array.size, bool)
        for (mapper, q), values in zip(self._maps, per_contact, strict=True):
            local = self._local(values, q)
            dofs = mapper.body_dofs
            if combine == "add":
                f.x.array[dofs] += local
            elif combine in ("min", "max"):
                pick = np.minimum if combine == "min" else np.maximum
                f.x.array[dofs] = np.where(seen[dofs], pick(f.x.array[dofs], local), local)
            else:
                f.x.array[dofs] = local
            seen[dofs] = True
        return f

    def vector_field(self, name: str, per_contact: list[np.ndarray], *, add: bool = False
                     ) -> fem.Function:
        """A body vector P1 function from each contact's owned nodal vectors (n, gdim)."""
        gdim = self.W.mesh.geometry.dim
        if self._Wv is None:
            self._Wv = fem.functionspace(self.W.mesh, ("Lagrange", 1, (gdim,)))
        f = fem.Function(self._Wv, name=name)
        blocks = f.x.array.reshape(-1, gdim)
        for (mapper, q), values in zip(self._maps, per_contact, strict=True):
            local = np.column_stack([self._local(values[:, i], q).copy() for i in range(gdim)])
            if add:
                blocks[mapper.body_dofs] += local
            else:
                blocks[mapper.body_dofs] = local
        return f

