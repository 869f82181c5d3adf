"""gmsh meshes of scenes: a .geo or .msh file opened with its parameters, meshed on one rank.

The gmsh model is created on one MPI rank only and distributed by
:func:`dolfinx.io.gmsh.model_to_mesh`. ``gmsh`` is an optional dependency
(the ``mesh`` extra); it is imported when a mesh is built. The geometries
themselves are the ``meshes/*.geo`` files, the only description of each.
"""

from __future__ import annotations

import json
import re
import signal
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np
from dolfinx.io.gmsh import MeshData, model_to_mesh

from mpi4py import MPI


@contextmanager
def gmsh_session() -> Iterator[tuple[Any, bool]]:
    """The gmsh module and whether this call opened the session (and will close it).

    Uses the caller's session when one is open. gmsh's C++ library resets
    the process's SIGINT and SIGTERM handling when it starts and stops,
    behind Python's back (``signal.getsignal`` still names the Python
    handler, which no longer runs: a SIGTERM then kills the process instead
    of stopping the run cleanly). The Python handlers found on entry are
    therefore installed again on exit.
    """
    import gmsh

    handlers = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    opened = not gmsh.isInitialized()
    if opened:
        gmsh.initialize(interruptible=False)
    try:
        yield gmsh, opened
    finally:
        if opened:
            gmsh.finalize()
        for s, handler in handlers.items():
            if handler is not None:
                try:
                    signal.signal(s, handler)
                except ValueError:  # not the main thread: nothing was installed here
                    pass


def mesh_on_rank(
    comm: MPI.Comm, rank: int, gdim: int, build: Callable[[Any], None]
) -> MeshData:
    """Run ``build(gmsh)`` on ``rank`` and distribute the resulting mesh over ``comm``.

    Uses the caller's gmsh session when one is open (its model is removed
    afterwards), or opens and closes its own. ``build`` must add and mesh a
    model with physical groups. Its nodes and elements are numbered 1 ... N
    before the mesh is handed over (a .msh file may number them with gaps).
    When ``build`` fails (gmsh cannot mesh the geometry), every rank raises
    ``ValueError`` with gmsh's reason.
    """
    if comm.rank != rank:
        import gmsh

        problem, kind = comm.bcast(None, root=rank)
        if problem:
            raise kind(problem)
        return model_to_mesh(gmsh.model, comm, rank, gdim=gdim)
    with gmsh_session() as (gmsh, opened):
        try:
            problem, kind = "", ValueError
            try:
                build(gmsh)
                gmsh.model.mesh.renumberNodes()
                gmsh.model.mesh.renumberElements()
            except Exception as exc:  # gmsh raises bare Exception
                problem = " ".join(str(exc).split()) or type(exc).__name__
            if not problem:
                problem, kind = facets_off_the_cells(gmsh, gdim), MeshGroupError
            comm.bcast((problem, kind), root=rank)
            if problem:
                raise kind(problem)
            return model_to_mesh(gmsh.model, comm, rank, gdim=gdim)
        finally:
            if not opened:
                gmsh.model.remove()


class MeshGroupError(ValueError):
    """A meshed model whose physical groups cannot become mesh tags."""


def facets_off_the_cells(gmsh: Any, gdim: int) -> str:
    """Why a facet group of the meshed model is not on its cells ("" when every one is).

    Every node of a facet physical group must be a node of some cell:
    DOLFINx finds each tagged facet among its cells' facets, and one that
    is not there aborted the whole process with an MPI error (seen with
    ``Geometry.AutoCoherence = 0`` and extruded boxes, whose side surfaces
    then got nodes of their own).
    """
    used: set[int] = set()
    for dim, tag in gmsh.model.getEntities(gdim):
        for nodes in gmsh.model.mesh.getElements(dim, tag)[2]:
            used.update(np.asarray(nodes, np.int64).tolist())
    kinds = {1: "Curve", 2: "Surface"}
    for dim, group in gmsh.model.getPhysicalGroups(gdim - 1):
        name = gmsh.model.getPhysicalName(dim, group) or str(group)
        for entity in gmsh.model.getEntitiesForPhysicalGroup(dim, group):
            nodes = np.concatenate([np.asarray(n, np.int64) for n in
                                    gmsh.model.mesh.getElements(dim, int(entity))[2]] or
                                   [np.zeros(0, np.int64)])
            off = int(np.setdiff1d(nodes, np.fromiter(used, np.int64, len(used))).size)
            if off:
                return (f"the physical group {name!r} holds {kinds[gdim - 1]} {int(entity)}, "
                        f"whose mesh has {off} nodes that no {gdim}D cell uses: that surface "
                        "is not meshed as a face of the bodies' cells. The built-in kernel's "
                        "Extrude under Geometry.AutoCoherence = 0 does this (the extruded "
                        "volume's top nodes are not its side faces' nodes); mesh the bodies "
                        "apart another way, e.g. with the OpenCASCADE kernel (SetFactory("
                        "\"OpenCASCADE\"), one Box per body, no BooleanFragments between them) "
                        "and physical groups of their faces.")
    return ""


def overlapping_groups(gmsh: Any) -> str:
    """Why the model's physical groups cannot become mesh tags ("" when they can).

    A mesh keeps one tag per cell and per facet: an entity in two physical
    groups of one dimension would silently stay in one of them only (a
    striker tagged over a part that another group also holds loses it).
    """
    kinds = {0: "Point", 1: "Curve", 2: "Surface", 3: "Volume"}
    for dim in range(4):
        holder: dict[int, tuple[int, str]] = {}
        for _, tag in gmsh.model.getPhysicalGroups(dim):
            name = gmsh.model.getPhysicalName(dim, tag) or str(tag)
            for entity in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
                entity = int(entity)
                if entity in holder and dim > 0:
                    other = holder[entity][1]
                    return (f"{kinds[dim]} {entity} of the mesh file is in two physical groups, "
                            f"{other!r} and {name!r}; a mesh keeps one tag per cell and facet, so "
                            "one group would silently lose it. Make the groups disjoint: give each "
                            "entity one group.")
                holder[entity] = (tag, name)
    return ""


def _toml_key(name: str) -> str:
    """``name`` as a key of a TOML table: bare when it may be, else quoted."""
    return name if re.fullmatch(r"[A-Za-z0-9_-]+", name) else json.dumps(name)


def _declared(names: set[str]) -> str:
    """A .geo file's parameter names as TOML keys, and how a quoted one is written."""
    keys = [_toml_key(n) for n in sorted(names)]
    quoted = any(k != n for k, n in zip(keys, sorted(names), strict=True))
    return ", ".join(keys) + ("; a name with a space is a quoted key in TOML, as written "
                              "here: parameters = { " + next(k for k in keys if k[0] == '"')
                              + " = ... }" if quoted else "")


def open_geo(gmsh: Any, path: Path | str, parameters: dict[str, float]) -> None:
    """Open a gmsh .geo or .msh file in the current session with ``parameters`` set.

    A .geo file declares its parameters with ``DefineConstant[x = {default,
    Name "Parameters/x"}]``; such a declaration keeps the ONELAB value, so
    each parameter is set both as a ONELAB number and as a parser variable
    before the file is read. A name the file does not declare raises
    ``ValueError`` listing the names it does.
    """
    if parameters and str(path).endswith(".geo"):
        gmsh.open(str(path))  # a first read learns which parameters the file declares
        declared = {n.split("/", 1)[1] for n in gmsh.onelab.getNames("Parameters/.*")}
        gmsh.clear()
        gmsh.onelab.clear()
        unknown = sorted(set(parameters) - declared)
        if unknown:
            first = unknown[0]
            # a variable whose parameter has another name: R = {1, Name "Parameters/radius"}
            # or t = {0.1, Name "Parameters/wall thickness"}
            named = dict(re.findall(r"(\w+)\s*=\s*\{[^}]*Name\s*\"Parameters/([^\"]+)\"",
                                    Path(path).read_text(errors="replace")))
            moved = [k for k in unknown if k in named and named[k] != k]
            renamed = [f"{k!r} is the .geo variable of the parameter {named[k]!r}: set "
                       f"{_toml_key(named[k])} = {parameters[k]!r}" for k in moved]
            if renamed:
                raise ValueError(
                    f"{Path(path).name} declares no parameter {', '.join(map(repr, unknown))}; "
                    + "; ".join(renamed) + f" (it declares: {_declared(declared)})."
                )
            # declared under another ONELAB path: x = {1, Name "P/x"}
            elsewhere = {k: v for k, v in re.findall(
                r"(\w+)\s*=\s*\{[^}]*Name\s*\"([^\"]+)\"", Path(path).read_text(
                    errors="replace")) if not v.startswith("Parameters/")}
            misplaced = [f"{k!r} is declared with Name {elsewhere[k]!r}; only names under "
                         f'"Parameters/" can be set from a scene: Name "Parameters/{k}"'
                         for k in unknown if k in elsewhere]
            if misplaced:
                raise ValueError(f"{Path(path).name} declares no parameter "
                                 f"{', '.join(map(repr, unknown))}; " + "; ".join(misplaced)
                                 + ".")
            raise ValueError(
                f"{Path(path).name} declares no parameter {', '.join(map(repr, unknown))}; "
                f"it declares: {_declared(declared) or 'none'}. A parameter the scene "
                f"may set is declared in the .geo as DefineConstant[{first} = {{value, Name "
                f'"Parameters/{first}"}}]; (the plain form DefineConstant[{first} = value] '
                "cannot be set from outside the file)."
            )
    for name, value in parameters.items():
        gmsh.onelab.setNumber(f"Parameters/{name}", [float(value)])
        gmsh.parser.setNumber(name, [float(value)])
    gmsh.open(str(path))
