"""Scene sections read from their tables: mesh, conditions, bodies, solver.

Each function checks one section's keys and returns its spec
(:mod:`.spec`), raising :class:`~.spec.SceneError` that names the key, the
bad value and the fix; :mod:`.schema` lists the keys and puts a scene
together. The contacts' sections are in :mod:`.contact_sections`.
"""

import itertools
from pathlib import Path
from typing import Any

from fenics_contact.model.materials import MATERIALS, elastic_constants_problem
from fenics_contact.scene.reader import _array, _Reader
from fenics_contact.scene.spec import (
    CONTACT_SETS,
    GENERATOR_TAGS,
    METHODS,
    BodySpec,
    BoundarySpec,
    MeshSpec,
    SceneError,
    SolverSpec,
)

#: Largest load-step count and Newton-iteration limit a scene may ask for: far
#: beyond any useful run (a million linear solves), well short of running forever.
MAX_STEPS = 100_000
MAX_ITERATIONS = 100_000
#: Largest number of halvings of a load increment (2^-60 of a step is below round-off).
MAX_CUTBACKS = 60


def why_bounded(key: str) -> str:
    """The fix that goes with a bounded integer key."""
    if key == "steps":
        return "a finer load path rarely helps past a few hundred steps; use fewer."
    if key == "max_cutbacks":
        return "each halves the increment; 60 halvings reach round-off."
    return "a Newton solve that needs more has failed; lower it."


def read_mesh(path: Path, reader: _Reader, dimension: int) -> MeshSpec:
    """[mesh]: a gmsh file (resolved beside the scene) or a generated rectangle or box."""
    t = reader.table
    if ("file" in t) == ("generator" in t):
        raise SceneError(
            f"{path.name}: [mesh] needs exactly one of 'file' (a .geo or .msh) or 'generator'."
        )
    parameters = t.get("parameters", {})
    if not isinstance(parameters, dict) or not all(
        isinstance(v, int | float) and not isinstance(v, bool) for v in parameters.values()
    ):
        raise reader.fail("parameters", "must be a table of numbers, e.g. { h_contact = 0.004 }.")
    if "file" in t:
        given = Path(str(t["file"]))
        file = given
        if not given.is_absolute():
            file = (path.parent / given).resolve()
            if not file.exists() and given.resolve().exists():
                file = given.resolve()  # relative to the working directory
        if not file.exists():
            where = "" if given.is_absolute() else " (a relative path is read beside the scene)"
            raise reader.fail("file", f"no such mesh file ({file}){where}; check the path.")
        if file.suffix not in (".geo", ".msh"):
            raise reader.fail("file", "must be a gmsh .geo or .msh file.")
        _check_mesh_file(reader, file)
        return MeshSpec(file=file, parameters=dict(parameters))
    generator = reader.choice("generator", tuple(GENERATOR_TAGS))
    needed = {"rectangle": 2, "box": 3}[generator]
    if needed != dimension:
        raise reader.fail(
            "generator", f"makes a {needed}D mesh but [scene] dimension = {dimension}."
        )
    size = reader.vector("size", dimension)
    if any(s is None or s <= 0 for s in size):
        raise reader.fail("size", "every side length must be > 0.")
    cells = t.get("cells")
    if (
        not isinstance(cells, list) or len(cells) != dimension
        or not all(isinstance(c, int) and not isinstance(c, bool) and c > 0 for c in cells)
    ):
        raise reader.fail("cells", f"must be {dimension} positive integers.")
    cell_types = ("quadrilateral", "triangle") if dimension == 2 else ("hexahedron", "tetrahedron")
    return MeshSpec(
        generator=generator,
        origin=reader.vector("origin", dimension, default=(0.0,) * dimension),
        size=size,
        cells=tuple(cells),
        cell=reader.choice("cell", cell_types, default=cell_types[0]),
    )


def _check_mesh_file(reader: _Reader, file: Path) -> None:
    """A mesh file must be a readable, non-empty file; a .msh starts with $MeshFormat."""
    if not file.is_file():
        raise reader.fail("file", f"{file} is not a file; give a .geo or .msh file.")
    try:
        with file.open("rb") as stream:
            head = stream.read(64)
    except OSError as exc:
        raise reader.fail(
            "file", f"cannot read {file} ({exc.strerror}); check its permissions."
        ) from None
    if not head.strip():
        raise reader.fail("file", f"{file} is empty; regenerate it (fenics-contact mesh).")
    if file.suffix == ".msh" and not head.lstrip().startswith(b"$MeshFormat"):
        raise reader.fail(
            "file", f"{file} is not a gmsh .msh file (no $MeshFormat header); regenerate it "
            "(fenics-contact mesh) or point to the .geo file."
        )


def read_bounds(reader: _Reader, dimension: int) -> dict[int, tuple[float, float]]:
    """Optional x/y/z = [min, max] bounds on facet midpoints, by axis."""
    bounds = {}
    for axis, key in enumerate("xyz"[:dimension]):
        if key in reader.table:
            lo_hi = reader.vector(key, 2)
            if lo_hi[0] > lo_hi[1]:
                raise reader.fail(key, "must be [min, max] with min <= max.")
            bounds[axis] = (lo_hi[0], lo_hi[1])
    return bounds


def read_boundary(reader: _Reader, dimension: int, allow_free: bool) -> BoundarySpec:
    """A [[dirichlet]] or [[traction]] block: tag, value or path, optional x/y/z bounds."""
    bounds = read_bounds(reader, dimension)
    path: tuple[tuple[float, ...], ...] = ()
    if "path" in reader.table:
        path = _path(reader, dimension)
        value = path[-1][1:]
    else:
        value = reader.vector("value", dimension, allow_free=allow_free)
    return BoundarySpec(tag=reader.tag("tag"), value=value, bounds=bounds, path=path)


def _path(reader: _Reader, dimension: int) -> tuple[tuple[float, ...], ...]:
    """Knots [t, u_1, ..., u_d] of a piecewise-linear path, t from 0 to 1 increasing."""
    knots = reader.table["path"]
    fix = f"give a list of [t, {', '.join('u' + 'xyz'[i] for i in range(dimension))}] " \
          "with t increasing from 0 to 1"
    if not isinstance(knots, list) or len(knots) < 2:
        raise reader.fail("path", fix + ".")
    out = []
    for k in knots:
        if (not isinstance(k, list) or len(k) != dimension + 1
                or not all(isinstance(v, int | float) and not isinstance(v, bool) for v in k)):
            raise reader.fail("path", f"knot {k!r} is not a list of {dimension + 1} numbers; "
                              + fix + ".")
        out.append(tuple(float(v) for v in k))
    ts = [k[0] for k in out]
    if ts[0] != 0.0 or ts[-1] != 1.0 or any(b <= a for a, b in itertools.pairwise(ts)):
        raise reader.fail("path", f"load factors {ts} must increase from 0 to 1; " + fix + ".")
    if "value" in reader.table:
        raise reader.fail("value", "give either 'value' or 'path', not both.")
    return tuple(out)


def read_bodies(path: Path, data: dict[str, Any]) -> tuple[BodySpec, ...]:
    """The [[body]] blocks: name, cell tag, law, E and nu; names must not repeat."""
    out = []
    for reader in _array(path, data, "body"):
        name = str(reader.table.get("name", f"body{len(out) + 1}"))
        reader.entry = f" {name!r}"  # messages name the body: [[body]] 'upper' nu = ...
        law = reader.choice("law", tuple(sorted(MATERIALS)))
        if "tag" not in reader.table:
            raise SceneError(f"{path.name}: [[body]] {name!r} needs 'tag', the cell tag of the "
                             "body (a number or a physical surface/volume name).")
        E, nu = elastic_constants(reader)
        stabilise = reader.number("stabilise", 0.0)
        if not 0.0 <= stabilise <= 1e-3:
            raise reader.fail("stabilise", "is the stiffness of weak springs that tie the body "
                              "to where it starts, relative to E / L^2: give a small number "
                              "(1e-6 holds a body that only friction holds once pressed; at "
                              "most 1e-3), or leave it out.")
        out.append(BodySpec(name=name, tag=reader.tag("tag"), law=law, E=E, nu=nu,
                            stabilise=stabilise))
    names = [b.name for b in out]
    if len(set(names)) != len(names):
        raise SceneError(f"{path.name}: [[body]] names {names} repeat; name each body once.")
    seen: dict[object, str] = {}
    for b in out:
        if b.tag in seen:
            raise SceneError(
                f"{path.name}: [[body]] {seen[b.tag]!r} and {b.name!r} have the same tag = "
                f"{b.tag!r}; each body is the cells of its own tag (a physical "
                "surface/volume of the mesh).")
        seen[b.tag] = b.name
    return tuple(out)


def elastic_constants(material: _Reader) -> tuple[float, float]:
    """E and nu, checked by the materials' own rule."""
    E, nu = material.number("E"), material.number("nu")
    problem = elastic_constants_problem(E, nu)
    if problem is not None:
        raise material.fail(*problem)
    return E, nu


def read_solver(reader: _Reader) -> SolverSpec:
    """[solver]: method, step and iteration limits, tolerances, predictor, linear solver."""
    def bounded(key: str, default: int, minimum: int, maximum: int) -> int:
        return reader.integer(key, default, minimum=minimum, maximum=maximum,
                              why=why_bounded(key))

    linear_solver = reader.choice("linear_solver", ("direct", "iterative"), default="direct")
    forcing = reader.choice("forcing", ("fixed", "eisenstat-walker"), default="fixed")
    reuse = reader.choice("reuse_preconditioner", ("no", "step", "path"), default="no")
    for key, value, default in (("forcing", forcing, "fixed"),
                                ("reuse_preconditioner", reuse, "no")):
        if value != default and linear_solver != "iterative":
            raise reader.fail(key, "needs linear_solver = \"iterative\" "
                              "(the direct solver solves exactly and has no preconditioner).")
    return SolverSpec(
        method=reader.choice("method", METHODS, default="gnrm"),
        steps=bounded("steps", 10, 1, MAX_STEPS),
        max_iterations=bounded("max_iterations", 50, 1, MAX_ITERATIONS),
        atol=reader.number("atol", 1e-8, positive=True),
        atol_given="atol" in reader.table,
        rtol=reader.number("rtol", 1e-10) if "rtol" in reader.table else 1e-10,
        max_cutbacks=bounded("max_cutbacks", 4, 0, MAX_CUTBACKS),
        predictor=reader.choice("predictor", ("active-set", "extrapolate", "previous"),
                                default="active-set"),
        contact_set=reader.choice("contact_set", CONTACT_SETS, default="exact"),
        linear_solver=linear_solver,
        forcing=forcing,
        reuse_preconditioner=reuse,
    )



__all__ = [
    "MAX_CUTBACKS", "MAX_ITERATIONS", "MAX_STEPS", "elastic_constants", "read_bodies",
    "read_boundary", "read_mesh", "read_solver", "why_bounded",
]
