"""Solution fields per load step that survive any stop of the run.

An HDF5 file that is open when its process dies (SIGKILL, MPI_Abort, a
node failure) is not readable afterwards ("bad object header version
number"). So no file stays open between steps: each load step goes into its
own HDF5 file, written and closed by DOLFINx's XDMF writer,

    DIR/solution/step_0001.h5 (+ step_0001.xdmf, that step alone)
    DIR/solution/step_0002.h5 ...

and ``DIR/solution.xdmf`` is an index, one temporal collection with one grid
per finished step (mesh and every field), rewritten under a temporary name
and renamed over the old index after the step's file is closed. A rename
within a folder is atomic: a reader (or a kill) sees either the old index or
the new one, and every step an index names is complete on disk.
"""

from __future__ import annotations

import copy
import errno
import os
import re
from collections.abc import Sequence
from pathlib import Path
from xml.etree import ElementTree

import numpy as np
from dolfinx import fem, io

from fenics_contact.model.materials import von_mises
from fenics_contact.model.problem import ContactProblem
from fenics_contact.output.folders import agree, write_failure
from fenics_contact.output.io import ContactsToBody
from fenics_contact.scene.schema import FIELDS, FRICTION_FIELDS

_STEP = re.compile(r"step_(\d{4,})\.(h5|xdmf)$")


#: How a surface field combines at a node two contacts share: pressures add, the
#: nearer partner's gap, and a node in contact anywhere is in contact.
SHARED_NODE = {"contact_pressure": "add", "gap": "min", "active": "max", "stick_slip": "max"}


def step_folder(index: Path) -> Path:
    """The folder of the per-step files of index ``DIR/NAME.xdmf``: ``DIR/NAME``."""
    return index.with_suffix("")


def _step_name(step: int) -> str:
    return f"step_{step:04d}"


def step_grid(step_xdmf: Path, index: Path) -> ElementTree.Element:
    """One uniform grid (mesh, time and every field) from a per-step DOLFINx file.

    DOLFINx writes the mesh once and each function as its own temporal
    collection that includes the mesh by ``xi:include``; not every reader
    follows that. The grid returned holds copies of the mesh's Topology and
    Geometry and all attributes, with HDF5 paths relative to ``index``'s folder.
    """
    root = ElementTree.parse(step_xdmf).getroot()
    domain = root.find("Domain")
    if domain is None:
        raise ValueError(f"{step_xdmf} has no XDMF Domain; the step file is damaged.")
    grids = domain.findall("Grid")
    mesh = next((g for g in grids if g.get("GridType") == "Uniform"), None)
    if mesh is None:
        raise ValueError(f"{step_xdmf} holds no mesh; the step file is damaged.")
    grid = ElementTree.Element("Grid", Name="solution", GridType="Uniform")
    for child in mesh:
        if child.tag in ("Topology", "Geometry"):
            grid.append(copy.deepcopy(child))
    time = None
    attributes = []
    for collection in (g for g in grids if g.get("CollectionType") == "Temporal"):
        for sub in collection.findall("Grid"):
            time = sub.find("Time") if time is None else time
            attributes.extend(copy.deepcopy(a) for a in sub.findall("Attribute"))
    if time is None:
        raise ValueError(f"{step_xdmf} holds no field; the step file is damaged.")
    grid.append(copy.deepcopy(time))
    grid.extend(attributes)
    prefix = os.path.relpath(step_xdmf.parent, index.parent)
    for item in grid.iter("DataItem"):
        if item.get("Format") == "HDF" and item.text:
            item.text = f"{prefix}/{item.text.strip()}"
    return grid


def write_index(index: Path, grids: Sequence[ElementTree.Element]) -> None:
    """Write the temporal collection of ``grids`` to ``index``, replacing it atomically."""
    root = ElementTree.Element("Xdmf", Version="3.0")
    domain = ElementTree.SubElement(root, "Domain")
    series = ElementTree.SubElement(
        domain, "Grid", Name="solution", GridType="Collection", CollectionType="Temporal"
    )
    series.extend(grids)
    tree = ElementTree.ElementTree(root)
    ElementTree.indent(tree)
    tmp = index.with_name(f".{index.name}.{os.getpid()}.tmp")
    with tmp.open("wb") as f:
        tree.write(f, xml_declaration=True, encoding="utf-8")
        f.flush()
        os.fsync(f.fileno())
    tmp.replace(index)


def step_files(index: Path) -> list[Path]:
    """Every step file (``step_NNNN.h5`` or ``.xdmf``, whole or not) in the step folder."""
    folder = step_folder(index)
    if not folder.is_dir():
        return []
    return sorted(e for e in folder.iterdir() if _STEP.fullmatch(e.name))


def finished_steps(index: Path) -> list[int]:
    """Step numbers whose HDF5 and XDMF files are both in the step folder, sorted."""
    found: dict[int, set[str]] = {}
    folder = step_folder(index)
    if folder.is_dir():
        for entry in folder.iterdir():
            match = _STEP.fullmatch(entry.name)
            if match:
                found.setdefault(int(match.group(1)), set()).add(match.group(2))
    return sorted(k for k, kinds in found.items() if kinds == {"h5", "xdmf"})


class StepWriter:
    """Writes the chosen fields of every load step into its own closed HDF5 file.

    Fields: displacement (P1 vector), contact_pressure (p = -lam >= 0 in
    compression, stress), gap and active (P1 scalars, zero off the contact
    surface) and von_mises (cell-wise Cauchy
    von Mises stress). With friction also tangential_traction (the tangential
    traction the obstacle puts on the body, P1 vector, stress), slip (the
    slip increment of the load step relative to the obstacle, P1 vector,
    length) and stick_slip (0 open, 1 stick, 2 slip); a frictionless
    contact of such a scene writes 2 at its closed nodes (nothing holds
    them along the surface) and zero traction and slip (its slip is not
    measured), and the summary counts neither. Time is the load
    factor. After each step the index
    ``path`` (an XDMF temporal collection) names every step written so far.

    Args:
        problem: the problem whose fields are written (P1 displacement).
        path: the index, e.g. ``DIR/solution.xdmf``; step files go to ``DIR/solution/``.
        fields: the fields to write.
        first_step: the number of the next step. 1 starts afresh (step files
            left by an earlier run in the folder are removed); k > 1 continues
            a run whose steps 1 .. k-1 are on disk (later ones are removed).
    """

    def __init__(
        self,
        problem: ContactProblem,
        path: Path,
        fields: Sequence[str] = FIELDS,
        *,
        first_step: int = 1,
    ) -> None:
        if problem.V.ufl_element().embedded_superdegree != 1:
            raise ValueError("XDMF output needs P1 displacement; interpolate higher orders first.")
        known = FIELDS + FRICTION_FIELDS if problem.frictional else FIELDS
        unknown = set(fields) - set(known)
        if unknown:
            raise ValueError(f"Unknown output fields {sorted(unknown)}; choose from {known}.")
        self.problem = problem
        self.path = path
        self.folder = step_folder(path)
        self.fields = tuple(fields)
        self.step = first_step
        self._grids: list[ElementTree.Element] = []
        comm = problem.comm
        error = None
        if comm.rank == 0:
            try:
                self._prepare(first_step)
            except (OSError, ValueError) as exc:
                error = str(exc)
        error = comm.bcast(error, root=0)
        if error is not None:
            raise ValueError(error)
        self.mapper = ContactsToBody(problem)
        self._stress = None
        S = fem.functionspace(problem.domain, ("DG", 0))
        # Each body's law on its own cells; several bodies add a body-id field.
        self._body_id = problem.body_ids()
        if "von_mises" in self.fields:
            self._stress = fem.Function(S, name="von_mises")
            self._stress_exprs = [
                (fem.Expression(von_mises(sigma), S.element.interpolation_points), cells)
                for sigma, cells in problem.stresses()
            ]

    def _prepare(self, first_step: int) -> None:
        """Rank 0: clear or check the step folder and write the index of the kept steps."""
        self.folder.mkdir(parents=True, exist_ok=True)
        kept = range(1, first_step)
        missing = [k for k in kept if k not in finished_steps(self.path)]
        if missing:
            raise ValueError(
                f"Cannot continue the output in {self.folder}: the files of step(s) "
                f"{missing} are missing; start the run afresh."
            )
        for entry in self.folder.iterdir():
            match = _STEP.fullmatch(entry.name)
            if match and int(match.group(1)) >= first_step:
                entry.unlink()
        self._grids = [
            step_grid(self.folder / f"{_step_name(k)}.xdmf", self.path) for k in kept
        ]
        if self._grids:
            write_index(self.path, self._grids)
        else:  # no index until the first step is on disk
            self.path.unlink(missing_ok=True)

    def _contact_values(self) -> tuple[dict[str, list[np.ndarray]], dict[str, list[np.ndarray]]]:
        """Each contact's owned nodal values by field name: scalars, then vectors.

        A frictionless contact of a frictional problem writes no traction or
        slip and marks its pressed nodes as slipping (2): nothing holds them.
        """
        scalars: dict[str, list[np.ndarray]] = {
            "contact_pressure": [], "gap": [], "active": [], "stick_slip": []}
        vectors: dict[str, list[np.ndarray]] = {"tangential_traction": [], "slip": []}
        friction = any(name in FRICTION_FIELDS for name in self.fields)
        for contact in self.problem.contacts:
            state = contact.contact_state()
            scalars["contact_pressure"].append(-state.pressure)  # p = -lam >= 0
            scalars["gap"].append(state.gap)
            scalars["active"].append(state.active.astype(float))
            if not friction:
                continue
            if contact.friction is None:
                zero = np.zeros((state.gap.size, self.problem.gdim))
                vectors["tangential_traction"].append(zero)
                vectors["slip"].append(zero)
                scalars["stick_slip"].append(2.0 * state.active)
            else:
                traction, slip = contact.friction.tangential_fields()
                vectors["tangential_traction"].append(traction)
                vectors["slip"].append(slip)
                scalars["stick_slip"].append(state.node_state.astype(float))
        return scalars, vectors

    def write(self, t: float) -> None:
        """Write the current fields at load factor ``t`` as the next step (collective)."""
        p = self.problem
        surface, vectors = self._contact_values()
        step_xdmf = self.folder / f"{_step_name(self.step)}.xdmf"
        failure = None
        try:
            with io.XDMFFile(p.comm, str(step_xdmf), "w") as file:
                file.write_mesh(p.domain)
                for name in self.fields:
                    if name == "displacement":
                        file.write_function(p.u, t)
                    elif name == "von_mises":
                        assert self._stress is not None
                        for expr, cells in self._stress_exprs:
                            if cells is None:
                                self._stress.interpolate(expr)
                            else:
                                self._stress.interpolate(expr, cells0=cells)
                        file.write_function(self._stress, t)
                    elif name in vectors:
                        file.write_function(self.mapper.vector_field(
                            name, vectors[name], add=name == "tangential_traction"), t)
                    else:
                        file.write_function(self.mapper.field(
                            name, surface[name], combine=SHARED_NODE.get(name, "last")), t)
                if self._body_id is not None:
                    file.write_function(self._body_id, t)
                    file.write_function(p.target_force(), t)
        except (OSError, RuntimeError) as exc:  # HDF5 errors reach Python as RuntimeError
            failure = write_failure(exc, step_xdmf.with_suffix(".h5"))
        agree(p.comm, failure)  # every rank's part of the HDF5 file is written and closed
        if p.comm.rank == 0:
            gone = [k for k in range(1, self.step)
                    if not (self.folder / f"{_step_name(k)}.h5").is_file()]
            try:
                if gone:  # the folder was removed or emptied while the run went on
                    raise FileNotFoundError(
                        errno.ENOENT, f"the files of step(s) {gone} were removed during the run",
                        str(self.path),
                    )
                self._grids.append(step_grid(step_xdmf, self.path))
                write_index(self.path, self._grids)
            except OSError as exc:
                failure = write_failure(exc, self.path)
        agree(p.comm, failure)
        #: The files of the step just written (closed).
        self.written = (step_xdmf, step_xdmf.with_suffix(".h5"))
        self.step += 1

    def close(self) -> None:
        """Nothing stays open between steps; kept for callers that close writers."""

