"""Scene files: what a contact run declares, read from TOML and validated.

A scene is checked completely before any mesh is made or form compiled:
every mistake raises :class:`SceneError` naming the key, the bad value and
the fix. Building the problem (:mod:`fenics_contact.scene.build`) creates
only what the scene declares.

Layout (units are the user's; be consistent)::

    [scene]      name, dimension (2: plane strain, 3), description
    [mesh]       file = "meshes/x.geo" | "x.msh" (physical groups), or
                 generator = "rectangle" | "box", origin, size, cells, cell
                 parameters = { h_contact = 0.004 } (set in a .geo file)
    [material]   law = "svk" | "neo-hookean" | "linear", E, nu,
                 kinematics = "finite" | "small" (optional, must match law)
    [[dirichlet]] tag, value = [ux, uy(, uz)] ("free" leaves one free),
                 optional x/y/z = [min, max] bounds on facet midpoints
    [[traction]]  tag, value = [tx, ty(, tz)]  (per reference area)
    [obstacle]   type = "plane" (point, normal) | "ball" (centre, radius,
                 inside), motion = [...] (displacement at load factor 1), or
                 schedule = [[t, dx, dy(, dz)], ...] (piecewise-linear
                 displacement against the load factor t, rows from t = 0 to
                 t = 1: a load path in phases, e.g. press then slide)
    [contact]    tag, or detect = true with margin; r, relative, quadrature,
                 mu (Coulomb friction coefficient, >= 0; absent: frictionless),
                 tangential_r_max (cap of the tangential parameter r_t =
                 min(r, tangential_r_max E/h); default 0.1)
    [solver]     method, steps, max_iterations, atol, rtol, max_cutbacks,
                 predictor = "extrapolate" (start a step from the linear
                 extrapolation of the last two) | "previous",
                 linear_solver = "direct" (MUMPS) | "iterative" (GMRES,
                 Schur field split, algebraic multigrid; for large 3D)
    [output]     fields = [...], pictures = true

Generated meshes tag their sides: rectangle left = 1, right = 2,
bottom = 3, top = 4; box xmin = 1, xmax = 2, ymin = 3, ymax = 4, zmin = 5,
zmax = 6. Tags may be given by number or by name.
"""

from __future__ import annotations

import difflib
import itertools
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fenics_contact.model.materials import MATERIALS
from fenics_contact.solvers import STRATEGIES

#: Method names a scene may give: the strategy registry's.
METHODS = tuple(STRATEGIES)
#: Fields the XDMF output can hold.
FIELDS = ("displacement", "contact_pressure", "gap", "active", "von_mises")
#: Further fields of a frictional scene (tangential traction, slip increment,
#: 0 open / 1 stick / 2 slip per node).
FRICTION_FIELDS = ("tangential_traction", "slip", "stick_slip")
GENERATOR_TAGS: dict[str, dict[str, int]] = {
    "rectangle": {"left": 1, "right": 2, "bottom": 3, "top": 4},
    "box": {"xmin": 1, "xmax": 2, "ymin": 3, "ymax": 4, "zmin": 5, "zmax": 6},
}

_SCHEMA: dict[str, set[str]] = {
    "": {"scene", "mesh", "material", "dirichlet", "traction", "obstacle", "contact", "solver",
         "output"},
    "scene": {"name", "dimension", "description"},
    "mesh": {"file", "generator", "origin", "size", "cells", "cell", "parameters"},
    "material": {"law", "E", "nu", "kinematics"},
    "dirichlet": {"tag", "value", "x", "y", "z"},
    "traction": {"tag", "value"},
    "obstacle": {"type", "point", "normal", "centre", "radius", "inside", "motion", "schedule"},
    "contact": {"tag", "detect", "margin", "r", "relative", "quadrature", "mu",
                "tangential_r_max"},
    "solver": {"method", "steps", "max_iterations", "atol", "rtol", "max_cutbacks", "predictor",
               "linear_solver"},
    "output": {"fields", "pictures"},
}


class SceneError(ValueError):
    """A scene file mistake: the message names the key, the value and the fix."""


@dataclass(frozen=True)
class MeshSpec:
    """Where the body mesh comes from."""

    file: Path | None = None
    generator: str | None = None
    origin: tuple[float, ...] = ()
    size: tuple[float, ...] = ()
    cells: tuple[int, ...] = ()
    cell: str = "quadrilateral"
    parameters: dict[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class BoundarySpec:
    """A Dirichlet or traction condition on tagged facets (value at load factor 1)."""

    tag: int | str
    value: tuple[float | None, ...]
    bounds: dict[int, tuple[float, float]] = field(default_factory=dict)


@dataclass(frozen=True)
class ObstacleSpec:
    """A rigid plane or ball and its motion."""

    type: str
    point: tuple[float, ...] = ()
    normal: tuple[float, ...] = ()
    radius: float = 0.0
    inside: bool = False
    motion: tuple[float, ...] = ()
    schedule: tuple[tuple[float, ...], ...] = ()


@dataclass(frozen=True)
class ContactSpec:
    """Where contact may happen and how it is regularised."""

    tag: int | str | None = None
    detect: bool = False
    margin: float = 0.0
    r: float = 1.0
    relative: bool = True
    quadrature: str = "nodal"
    mu: float | None = None
    tangential_r_max: float | None = 0.1


@dataclass(frozen=True)
class SolverSpec:
    """Strategy and load stepping."""

    method: str = "gnrm"
    steps: int = 10
    max_iterations: int = 50
    atol: float = 1e-8
    rtol: float = 1e-10
    max_cutbacks: int = 4
    predictor: str = "extrapolate"
    linear_solver: str = "direct"


@dataclass(frozen=True)
class Scene:
    """A validated scene."""

    path: Path
    name: str
    dimension: int
    mesh: MeshSpec
    law: str
    E: float
    nu: float
    dirichlet: tuple[BoundarySpec, ...]
    tractions: tuple[BoundarySpec, ...]
    obstacle: ObstacleSpec
    contact: ContactSpec
    solver: SolverSpec
    fields: tuple[str, ...] = FIELDS
    pictures: bool = True
    description: str = ""


class _Reader:
    """Typed access to one TOML table with errors that name the key."""

    def __init__(self, path: Path, section: str, table: dict[str, Any]) -> None:
        self.path = path
        self.section = section
        self.table = table

    def where(self, key: str) -> str:
        return f"{self.path.name}: [{self.section}] {key}"

    def fail(self, key: str, message: str) -> SceneError:
        return SceneError(f"{self.where(key)} = {self.table.get(key)!r}: {message}")

    def number(
        self, key: str, default: float | None = None, *, positive: bool = False,
        below: float | None = None,
    ) -> float:
        if key not in self.table:
            if default is None:
                raise SceneError(f"{self.where(key)} is missing: give a number.")
            return default
        value = self.table[key]
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.fail(key, "must be a number.")
        if not math.isfinite(value):
            raise self.fail(key, "must be finite.")
        if positive and not value > 0:
            raise self.fail(key, "must be > 0.")
        if below is not None and not value < below:
            raise self.fail(key, f"must be < {below}.")
        return float(value)

    def integer(self, key: str, default: int, *, minimum: int = 0) -> int:
        value = self.table.get(key, default)
        if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
            raise self.fail(key, f"must be an integer >= {minimum}.")
        return int(value)

    def flag(self, key: str, default: bool) -> bool:
        value = self.table.get(key, default)
        if not isinstance(value, bool):
            raise self.fail(key, "must be true or false.")
        return value

    def choice(self, key: str, options: tuple[str, ...], default: str | None = None) -> str:
        if key not in self.table and default is not None:
            return default
        value = self.table.get(key)
        if not isinstance(value, str) or value.lower() not in options:
            raise SceneError(
                f"{self.where(key)} = {value!r}: choose one of {', '.join(options)}."
            )
        return value.lower()

    def vector(
        self, key: str, dimension: int, *, allow_free: bool = False, default: tuple = (),
    ) -> tuple:
        if key not in self.table:
            if default:
                return default
            raise SceneError(f"{self.where(key)} is missing: give {dimension} numbers.")
        value = self.table[key]
        if not isinstance(value, list) or len(value) != dimension:
            raise self.fail(
                key, f"must be a list of {dimension} numbers (the scene is {dimension}D)."
            )
        out: list[float | None] = []
        for v in value:
            if allow_free and v == "free":
                out.append(None)
            elif isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v):
                out.append(float(v))
            else:
                hint = ' or "free"' if allow_free else ""
                raise self.fail(key, f"entries must be finite numbers{hint}.")
        return tuple(out)

    def tag(self, key: str) -> int | str:
        value = self.table.get(key)
        if isinstance(value, bool) or not isinstance(value, int | str):
            raise SceneError(
                f"{self.where(key)} = {value!r}: give a facet tag number or a physical name."
            )
        return value


def _check_keys(path: Path, section: str, table: dict[str, Any]) -> None:
    allowed = _SCHEMA[section]
    for key in table:
        if key not in allowed:
            close = difflib.get_close_matches(key, sorted(allowed), n=1)
            hint = f" Did you mean {close[0]!r}?" if close else ""
            where = f"[{section}]" if section else "top level"
            raise SceneError(
                f"{path.name}: unknown key {key!r} at {where}.{hint} "
                f"Allowed: {', '.join(sorted(allowed))}."
            )


def _table(path: Path, data: dict[str, Any], section: str, required: bool = True) -> _Reader:
    if section not in data:
        if required:
            raise SceneError(f"{path.name}: the [{section}] table is missing; add it.")
        return _Reader(path, section, {})
    table = data[section]
    if not isinstance(table, dict):
        raise SceneError(f"{path.name}: [{section}] must be a table, not {type(table).__name__}.")
    _check_keys(path, section, table)
    return _Reader(path, section, table)


def _array(path: Path, data: dict[str, Any], section: str) -> list[_Reader]:
    items = data.get(section, [])
    if not isinstance(items, list) or not all(isinstance(t, dict) for t in items):
        raise SceneError(f"{path.name}: use [[{section}]] blocks for {section} conditions.")
    for t in items:
        _check_keys(path, section, t)
    return [_Reader(path, f"[{section}]", t) for t in items]


def _mesh(path: Path, reader: _Reader, dimension: int) -> MeshSpec:
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
        file = Path(str(t["file"]))
        if not file.is_absolute():
            file = (path.parent / file).resolve()
            if not file.exists():
                file = Path(str(t["file"])).resolve()
        if not file.exists():
            raise reader.fail("file", f"no such mesh file ({file}); check the path.")
        if file.suffix not in (".geo", ".msh"):
            raise reader.fail("file", "must be a gmsh .geo or .msh file.")
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


def _boundary(reader: _Reader, dimension: int, allow_free: bool) -> BoundarySpec:
    bounds = {}
    for axis, key in enumerate("xyz"[:dimension]):
        if key in reader.table:
            lo_hi = reader.vector(key, 2)
            if lo_hi[0] > lo_hi[1]:
                raise reader.fail(key, "must be [min, max] with min <= max.")
            bounds[axis] = (lo_hi[0], lo_hi[1])
    return BoundarySpec(
        tag=reader.tag("tag"),
        value=reader.vector("value", dimension, allow_free=allow_free),
        bounds=bounds,
    )


def _schedule(reader: _Reader, dimension: int) -> tuple[tuple[float, ...], ...]:
    """Rows [t, offset...] with t strictly increasing from 0 to 1."""
    if "schedule" not in reader.table:
        return ()
    if "motion" in reader.table:
        raise reader.fail("schedule", "give either 'motion' or 'schedule', not both.")
    rows = reader.table["schedule"]
    fix = f"give rows [t, {', '.join('d' + 'xyz'[i] for i in range(dimension))}]"
    if not isinstance(rows, list) or len(rows) < 2:
        raise reader.fail("schedule", f"must be a list of at least two rows; {fix}.")
    out = []
    for row in rows:
        if (
            not isinstance(row, list) or len(row) != dimension + 1
            or not all(isinstance(v, int | float) and not isinstance(v, bool)
                       and math.isfinite(v) for v in row)
        ):
            raise reader.fail(
                "schedule", f"row {row!r} is not {dimension + 1} finite numbers; {fix}."
            )
        out.append(tuple(float(v) for v in row))
    times = [row[0] for row in out]
    rising = all(b > a for a, b in itertools.pairwise(times))
    if times[0] != 0.0 or times[-1] != 1.0 or not rising:
        raise reader.fail(
            "schedule", f"load factors {times} must increase strictly from 0 to 1."
        )
    return tuple(out)


def _obstacle(reader: _Reader, dimension: int) -> ObstacleSpec:
    kind = reader.choice("type", ("plane", "ball"))
    schedule = _schedule(reader, dimension)
    motion = (
        schedule[-1][1:] if schedule
        else reader.vector("motion", dimension, default=(0.0,) * dimension)
    )
    if kind == "plane":
        normal = reader.vector("normal", dimension)
        if all(v == 0 for v in normal):
            raise reader.fail("normal", "must be a nonzero vector (the body's side).")
        return ObstacleSpec(
            "plane", point=reader.vector("point", dimension), normal=normal, motion=motion,
            schedule=schedule,
        )
    return ObstacleSpec(
        "ball",
        point=reader.vector("centre", dimension),
        radius=reader.number("radius", positive=True),
        inside=reader.flag("inside", False),
        motion=motion,
        schedule=schedule,
    )


def _contact(reader: _Reader) -> ContactSpec:
    detect = reader.flag("detect", False)
    if detect == ("tag" in reader.table):
        raise SceneError(
            f"{reader.path.name}: [contact] needs either 'tag' (the candidate facets) "
            "or 'detect = true' (found from the obstacle's path), not both or neither."
        )
    return ContactSpec(
        tag=reader.tag("tag") if not detect else None,
        detect=detect,
        margin=reader.number("margin", 0.0) if detect else 0.0,
        r=reader.number("r", 1.0, positive=True),
        relative=reader.flag("relative", True),
        quadrature=reader.choice("quadrature", ("nodal", "gauss"), default="nodal"),
        mu=_friction(reader),
        tangential_r_max=reader.number("tangential_r_max", 0.1, positive=True),
    )


def _friction(reader: _Reader) -> float | None:
    """The Coulomb coefficient: absent (frictionless) or a finite number >= 0."""
    if "mu" not in reader.table:
        return None
    mu = reader.number("mu")
    if mu < 0:
        raise reader.fail("mu", "the friction coefficient must be >= 0 (0: frictionless).")
    return mu


def _solver(reader: _Reader) -> SolverSpec:
    return SolverSpec(
        method=reader.choice("method", METHODS, default="gnrm"),
        steps=reader.integer("steps", 10, minimum=1),
        max_iterations=reader.integer("max_iterations", 50, minimum=1),
        atol=reader.number("atol", 1e-8, positive=True),
        rtol=reader.number("rtol", 1e-10) if "rtol" in reader.table else 1e-10,
        max_cutbacks=reader.integer("max_cutbacks", 4, minimum=0),
        predictor=reader.choice("predictor", ("extrapolate", "previous"), default="extrapolate"),
        linear_solver=reader.choice("linear_solver", ("direct", "iterative"), default="direct"),
    )


def load_scene(path: Path | str) -> Scene:
    """Read and validate a scene file; raises :class:`SceneError` on the first mistake."""
    path = Path(path)
    if not path.exists():
        raise SceneError(f"Scene file {path} does not exist; check the path.")
    try:
        data = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{path.name}: not valid TOML ({exc}).") from None
    _check_keys(path, "", data)
    head = _table(path, data, "scene")
    dimension = head.table.get("dimension")
    if dimension not in (2, 3):
        raise SceneError(
            f"{path.name}: [scene] dimension = {dimension!r}: use 2 (plane strain) or 3."
        )
    material = _table(path, data, "material")
    law = material.choice("law", tuple(sorted(MATERIALS)))
    kinematics = material.choice("kinematics", ("finite", "small"), default="")
    small = law == "linear"
    if kinematics and (kinematics == "small") != small:
        raise material.fail(
            "kinematics", f"does not match law = {law!r}; small strain is law = 'linear'."
        )
    output = _table(path, data, "output", required=False)
    fields = output.table.get("fields")
    mesh_spec = _mesh(path, _table(path, data, "mesh"), dimension)
    E = material.number("E", positive=True)
    nu = _poisson(material)
    dirichlet = tuple(_boundary(r, dimension, True) for r in _array(path, data, "dirichlet"))
    tractions = tuple(_boundary(r, dimension, False) for r in _array(path, data, "traction"))
    obstacle = _obstacle(_table(path, data, "obstacle"), dimension)
    contact = _contact(_table(path, data, "contact"))
    if obstacle.schedule and contact.detect:
        raise SceneError(
            f"{path.name}: [contact] detect = true follows the obstacle's straight motion; "
            "with [obstacle] schedule give the candidate facets by [contact] tag."
        )
    allowed = FIELDS + FRICTION_FIELDS if contact.mu is not None else FIELDS
    fields = list(allowed) if fields is None else fields
    if not isinstance(fields, list) or any(f not in allowed for f in fields):
        hint = "" if contact.mu is not None else " (friction fields need [contact] mu)"
        raise output.fail("fields", f"choose from {', '.join(allowed)}{hint}.")
    return Scene(
        path=path,
        name=str(head.table.get("name", path.stem)),
        dimension=dimension,
        description=str(head.table.get("description", "")),
        mesh=mesh_spec,
        law=law,
        E=E,
        nu=nu,
        dirichlet=dirichlet,
        tractions=tractions,
        obstacle=obstacle,
        contact=contact,
        solver=_solver(_table(path, data, "solver", required=False)),
        fields=tuple(fields),
        pictures=output.flag("pictures", True),
    )


def _poisson(material: _Reader) -> float:
    nu = material.number("nu")
    if nu >= 0.5:
        raise material.fail(
            "nu", "must be < 0.5 (exact incompressibility is not supported); use 0.4999 "
            "for a near-incompressible body."
        )
    if nu <= -1.0:
        raise material.fail("nu", "must be > -1.")
    return nu
