"""Output: XDMF fields per load step for ParaView, JSON and CSV records.

All file writing lives here. XDMF files are written as each step finishes,
so a run that fails later keeps the steps already done.
"""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Iterable, Mapping
from pathlib import Path

import numpy as np
from dolfinx import fem, io

from fenics_contact.problem import ContactProblem


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
    """Write ``data`` as indented JSON (parent folders created)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(_clean(data), indent=2) + "\n")


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

    Nodes are matched by their (identical) reference coordinates on each
    process; body nodes off the contact surface keep the fill value.
    """

    def __init__(self, problem: ContactProblem) -> None:
        self.W = fem.functionspace(problem.domain, ("Lagrange", 1))
        body = self.W.tabulate_dof_coordinates()
        surface = problem.Q.tabulate_dof_coordinates()
        index = {tuple(np.round(p, 12)): i for i, p in enumerate(body)}
        self.body_dofs = np.array(
            [index[tuple(np.round(p, 12))] for p in surface], dtype=np.int32
        )

    def field(self, name: str, values: np.ndarray, fill: float = 0.0) -> fem.Function:
        """A body P1 function holding ``values`` (all local surface dofs) on the surface."""
        f = fem.Function(self.W, name=name)
        f.x.array[:] = fill
        f.x.array[self.body_dofs] = values
        return f


class StepWriter:
    """Writes displacement, contact pressure, gap and active set at every step.

    One XDMF file (with its .h5) on the body mesh; time = load factor.
    DOLFINx rewrites the XDMF index at each write, so completed steps survive a failure.
    """

    def __init__(self, problem: ContactProblem, path: Path) -> None:
        if problem.V.ufl_element().embedded_superdegree != 1:
            raise ValueError("XDMF output needs P1 displacement; interpolate higher orders first.")
        path.parent.mkdir(parents=True, exist_ok=True)
        self.problem = problem
        self.path = path
        self.mapper = SurfaceToBody(problem)
        self.file = io.XDMFFile(problem.comm, str(path), "w")
        self.file.write_mesh(problem.domain)

    def write(self, t: float) -> None:
        """Append the current fields at load factor ``t``."""
        p = self.problem
        q = fem.Function(p.Q)
        state = p.contact_state()
        n = state.gap.size
        fields = [p.u]
        for name, values in (
            ("contact_pressure", state.pressure),
            ("gap", state.gap),
            ("active", state.active.astype(float)),
        ):
            q.x.array[:n] = values
            q.x.scatter_forward()
            fields.append(self.mapper.field(name, q.x.array))
        for f in fields:
            self.file.write_function(f, t)

    def close(self) -> None:
        """Close the file."""
        self.file.close()
