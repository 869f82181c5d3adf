"""Output: XDMF fields per load step for ParaView, JSON and CSV records.

All file writing lives here. XDMF files are written as each step finishes,
so a run that fails later keeps the steps already done.
"""

from __future__ import annotations

import copy
import csv
import json
import math
import os
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from xml.etree import ElementTree

import numpy as np
from dolfinx import fem, io

from fenics_contact.model.materials import von_mises
from fenics_contact.model.problem import ContactProblem
from fenics_contact.scene.schema import FIELDS, FRICTION_FIELDS


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


def flatten_xdmf(path: Path) -> None:
    """Rewrite a DOLFINx XDMF file as one temporal collection with every field per step.

    DOLFINx writes one collection per function and shares the mesh through
    ``xi:include``; some readers (VTK's legacy XDMF reader, meshio) cannot
    follow that. The rewritten file keeps the same HDF5 datasets, copies the
    mesh's Topology and Geometry into every step and groups all attributes of
    a time value in one grid, which ParaView shows as one dataset with all
    fields. Safe to call repeatedly: the input is always DOLFINx's layout.
    """
    tree = ElementTree.parse(path)
    domain = tree.getroot().find("Domain")
    if domain is None:
        return
    grids = domain.findall("Grid")
    mesh_grid = next((g for g in grids if g.get("GridType") == "Uniform"), None)
    if mesh_grid is None:
        return
    shared = [c for c in mesh_grid if c.tag in ("Topology", "Geometry")]
    steps: dict[str, list[ElementTree.Element]] = {}
    for collection in (g for g in grids if g.get("CollectionType") == "Temporal"):
        for grid in collection.findall("Grid"):
            time = grid.find("Time")
            if time is None:
                continue
            steps.setdefault(time.get("Value", "0"), []).extend(grid.findall("Attribute"))
    if not steps:
        return
    for g in grids:
        domain.remove(g)
    series = ElementTree.SubElement(
        domain, "Grid", Name="solution", GridType="Collection", CollectionType="Temporal"
    )
    for value in sorted(steps, key=float):
        grid = ElementTree.SubElement(series, "Grid", Name="solution", GridType="Uniform")
        for element in shared:
            grid.append(copy.deepcopy(element))
        ElementTree.SubElement(grid, "Time", Value=value)
        for attribute in steps[value]:
            grid.append(attribute)
    ElementTree.indent(tree)
    tmp = path.with_suffix(".xdmf.tmp")
    tree.write(tmp, xml_declaration=True, encoding="utf-8")
    tmp.replace(path)


class StepWriter:
    """Writes the chosen fields at every load step into one XDMF file (with its .h5).

    Fields: displacement (P1 vector), contact_pressure, gap and active (P1
    scalars, zero off the contact surface) and von_mises (cell-wise Cauchy
    von Mises stress). With friction also tangential_traction (the
    tangential traction the obstacle puts on the body, P1 vector, stress),
    slip (the slip increment of the load step relative to the obstacle, P1
    vector, length) and stick_slip (0 open, 1 stick, 2 slip). Time is the
    load factor. DOLFINx rewrites the XDMF index at each write, so completed
    steps survive a later failure.
    """

    def __init__(
        self, problem: ContactProblem, path: Path, fields: Sequence[str] = FIELDS
    ) -> None:
        if problem.V.ufl_element().embedded_superdegree != 1:
            raise ValueError("XDMF output needs P1 displacement; interpolate higher orders first.")
        known = FIELDS + FRICTION_FIELDS if hasattr(problem, "lam_t") else FIELDS
        unknown = set(fields) - set(known)
        if unknown:
            raise ValueError(f"Unknown output fields {sorted(unknown)}; choose from {known}.")
        if problem.comm.rank == 0:
            path.parent.mkdir(parents=True, exist_ok=True)
        problem.comm.Barrier()
        self.problem = problem
        self.path = path
        self.fields = tuple(fields)
        self.mapper = SurfaceToBody(problem)
        self._q = fem.Function(problem.Q)
        self._stress = None
        if "von_mises" in self.fields:
            S = fem.functionspace(problem.domain, ("DG", 0))
            self._stress = fem.Function(S, name="von_mises")
            sigma = problem.material.cauchy_stress(problem.u)
            self._stress_expr = fem.Expression(von_mises(sigma), S.element.interpolation_points)
        self.file = io.XDMFFile(problem.comm, str(path), "w")
        self.file.write_mesh(problem.domain)

    def _surface_field(self, name: str, values: np.ndarray) -> fem.Function:
        self._q.x.array[: values.size] = values
        self._q.x.scatter_forward()
        return self.mapper.field(name, self._q.x.array)

    def write(self, t: float) -> None:
        """Append the current fields at load factor ``t``."""
        p = self.problem
        state = p.contact_state()
        surface = {
            "contact_pressure": state.pressure,
            "gap": state.gap,
            "active": state.active.astype(float),
        }
        if any(name in FRICTION_FIELDS for name in self.fields):
            traction, slip = p.tangential_fields()  # type: ignore[attr-defined]
            surface["stick_slip"] = state.node_state.astype(float)  # type: ignore[attr-defined]
            vectors = {"tangential_traction": traction, "slip": slip}
        for name in self.fields:
            if name == "displacement":
                self.file.write_function(p.u, t)
            elif name in ("tangential_traction", "slip"):
                local = np.column_stack([
                    self._surface_field("c", vectors[name][:, i]).x.array[self.mapper.body_dofs]
                    for i in range(vectors[name].shape[1])
                ])
                self.file.write_function(self.mapper.vector_field(name, local), t)
            elif name == "von_mises":
                assert self._stress is not None
                self._stress.interpolate(self._stress_expr)
                self.file.write_function(self._stress, t)
            else:
                self.file.write_function(self._surface_field(name, surface[name]), t)
        self._flatten()

    def _flatten(self) -> None:
        self.problem.comm.Barrier()
        if self.problem.comm.rank == 0:
            flatten_xdmf(self.path)
        self.problem.comm.Barrier()

    def close(self) -> None:
        """Close the file."""
        self.file.close()
        self._flatten()
