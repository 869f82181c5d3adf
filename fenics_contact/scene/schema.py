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
                 min(r, tangential_r_max E/L), L the extent of the contact
                 surface; default 2)
    [[obstacle]] several obstacles instead of [obstacle] and [contact]: each
                 block holds one obstacle's keys, its contact's keys (tag or
                 detect, r, relative, quadrature, mu, tangential_r_max) and
                 a name (default obstacle1, obstacle2, ...)
    [[body]]     name, tag (cell tag), law, E, nu      } deformable bodies
    [[pair]]     name, striker, target (facet tags),  } instead of [material]
                 r, relative, mu, tangential_r_max    } and [contact]; any
                                                      } number of pairs and
                                                      } of [[obstacle]] blocks
    [solver]     method, steps, max_iterations, atol, rtol, max_cutbacks,
                 predictor = "extrapolate" (start a step from the linear
                 extrapolation of the last two) | "previous",
                 linear_solver = "direct" (MUMPS) | "iterative" (GMRES,
                 Schur field split, algebraic multigrid; for large 3D)
    [output]     fields = [...], pictures = true

Deformable bodies in one mesh replace [material] and [contact] by::

    [[body]]     name, tag (cell tag), law, E, nu      (one per body)
    [[pair]]     name, striker, target (facet tags), r, relative,
                 mu, tangential_r_max (Coulomb friction, as in [contact]),
                 discretisation = "node-to-segment" (default) | "mortar"
                 (2D, frictionless; exact on non-matching meshes)
    [[obstacle]] as above, its tag on the facets of one body

In every scene a [[dirichlet]] may give path = [[t, ux, uy], ...] (a
piecewise-linear displacement against the load factor, every component
prescribed) instead of value.

Generated meshes tag their sides: rectangle left = 1, right = 2,
bottom = 3, top = 4; box xmin = 1, xmax = 2, ymin = 3, ymax = 4, zmin = 5,
zmax = 6. Tags may be given by number or by name.
"""


import itertools
import math
import tomllib
from pathlib import Path
from typing import Any

from fenics_contact.model.contact import r_problem
from fenics_contact.model.materials import MATERIALS, elastic_constants_problem
from fenics_contact.scene.reader import _array, _check_finite, _check_keys, _Reader, _table
from fenics_contact.scene.spec import (
    FIELDS,
    FRICTION_FIELDS,
    GENERATOR_TAGS,
    METHODS,
    BodySpec,
    BoundarySpec,
    ContactSpec,
    MeshSpec,
    ObstacleContactSpec,
    ObstacleSpec,
    PairSpec,
    Scene,
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


def _boundary(reader: _Reader, dimension: int, allow_free: bool) -> BoundarySpec:
    bounds = {}
    for axis, key in enumerate("xyz"[:dimension]):
        if key in reader.table:
            lo_hi = reader.vector(key, 2)
            if lo_hi[0] > lo_hi[1]:
                raise reader.fail(key, "must be [min, max] with min <= max.")
            bounds[axis] = (lo_hi[0], lo_hi[1])
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


def _bodies(path: Path, data: dict[str, Any]) -> tuple[BodySpec, ...]:
    out = []
    for reader in _array(path, data, "body"):
        law = reader.choice("law", tuple(sorted(MATERIALS)))
        if "tag" not in reader.table:
            raise SceneError(f"{path.name}: [[body]] needs 'tag', the cell tag of the body "
                             "(a number or a physical surface/volume name).")
        E, nu = _elastic_constants(reader)
        out.append(BodySpec(
            name=str(reader.table.get("name", f"body{len(out) + 1}")),
            tag=reader.tag("tag"), law=law, E=E, nu=nu,
        ))
    names = [b.name for b in out]
    if len(set(names)) != len(names):
        raise SceneError(f"{path.name}: [[body]] names {names} repeat; name each body once.")
    return tuple(out)


def _pairs(path: Path, data: dict[str, Any], dimension: int = 2) -> tuple[PairSpec, ...]:
    out = []
    for reader in _array(path, data, "pair"):
        for key in ("striker", "target"):
            if key not in reader.table:
                raise SceneError(
                    f"{path.name}: [[pair]] needs '{key}', the facet tag of the {key} surface "
                    "(a number or a physical curve/surface name)."
                )
        out.append(PairSpec(
            name=str(reader.table.get("name", f"pair{len(out) + 1}")),
            striker=reader.tag("striker"), target=reader.tag("target"),
            r=_contact_r(reader), relative=reader.flag("relative", True),
            mu=_friction(reader),
            tangential_r_max=reader.number("tangential_r_max", 2.0, positive=True),
            discretisation=_discretisation(reader, dimension),
        ))
    return tuple(out)


def _discretisation(reader: _Reader, dim: int) -> str:
    """[[pair]] discretisation: "node-to-segment" (default) or "mortar" (2D, frictionless)."""
    value = reader.table.get("discretisation", "node-to-segment")
    if value not in ("node-to-segment", "mortar"):
        raise reader.fail("discretisation", 'choose "node-to-segment" (the default) or "mortar".')
    if value == "mortar" and dim != 2:
        raise reader.fail("discretisation", 'mortar is 2D only; use "node-to-segment" in 3D.')
    if value == "mortar" and "mu" in reader.table:
        raise reader.fail("discretisation", "mortar is frictionless; remove mu or use "
                          '"node-to-segment".')
    return value


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
            f"{reader.path.name}: [{reader.section}] needs either 'tag' (the candidate facets) "
            "or 'detect = true' (found from the obstacle's path), not both or neither."
        )
    return ContactSpec(
        tag=reader.tag("tag") if not detect else None,
        detect=detect,
        margin=reader.number("margin", 0.0) if detect else 0.0,
        r=_contact_r(reader),
        relative=reader.flag("relative", True),
        quadrature=reader.choice("quadrature", ("nodal", "gauss"), default="nodal"),
        mu=_friction(reader),
        tangential_r_max=reader.number("tangential_r_max", 2.0, positive=True),
    )


def _contact_r(reader: _Reader) -> float:
    """R, checked by the contact term's own rule."""
    r = reader.number("r", 1.0)
    problem = r_problem(r)
    if problem is not None:
        raise reader.fail("r", problem)
    return r


def _friction(reader: _Reader) -> float | None:
    """The Coulomb coefficient: absent (frictionless) or a finite number >= 0."""
    if "mu" not in reader.table:
        if "tangential_r_max" in reader.table:
            raise reader.fail(
                "tangential_r_max", "is a friction setting, but there is no mu: give the "
                "Coulomb coefficient mu (0: frictionless) or remove tangential_r_max."
            )
        return None
    mu = reader.number("mu")
    if mu < 0:
        raise reader.fail("mu", "the friction coefficient must be >= 0 (0: frictionless).")
    return mu


def _solver(reader: _Reader) -> SolverSpec:
    def bounded(key: str, default: int, minimum: int, maximum: int) -> int:
        return reader.integer(key, default, minimum=minimum, maximum=maximum,
                              why=why_bounded(key))

    return SolverSpec(
        method=reader.choice("method", METHODS, default="gnrm"),
        steps=bounded("steps", 10, 1, MAX_STEPS),
        max_iterations=bounded("max_iterations", 50, 1, MAX_ITERATIONS),
        atol=reader.number("atol", 1e-8, positive=True),
        rtol=reader.number("rtol", 1e-10) if "rtol" in reader.table else 1e-10,
        max_cutbacks=bounded("max_cutbacks", 4, 0, MAX_CUTBACKS),
        predictor=reader.choice("predictor", ("extrapolate", "previous"), default="extrapolate"),
        linear_solver=reader.choice("linear_solver", ("direct", "iterative"), default="direct"),
    )


def load_scene(path: Path | str) -> Scene:
    """Read and validate a scene file; raises :class:`SceneError` on the first mistake."""
    path = Path(path)
    if not path.exists():
        raise SceneError(f"Scene file {path} does not exist; check the path.")
    if not path.is_file():
        raise SceneError(f"Scene file {path} is not a file; give a .toml scene file.")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{path.name}: not valid TOML ({exc}).") from None
    except UnicodeDecodeError:
        raise SceneError(f"{path.name}: not a text file (not UTF-8); give a TOML scene.") from None
    except OSError as exc:
        raise SceneError(f"Scene file {path} cannot be read ({exc.strerror}).") from None
    _check_keys(path, "", data)
    _check_finite(path, data)
    head = _table(path, data, "scene")
    dimension = head.table.get("dimension")
    if dimension not in (2, 3):
        raise SceneError(
            f"{path.name}: [scene] dimension = {dimension!r}: use 2 (plane strain) or 3."
        )
    if "pair" in data or "body" in data:
        return _two_body_scene(path, data, head, dimension)
    material = _table(path, data, "material")
    law = material.choice("law", tuple(sorted(MATERIALS)))
    kinematics = material.choice("kinematics", ("finite", "small"), default="")
    small = law == "linear"
    if kinematics and (kinematics == "small") != small:
        raise material.fail(
            "kinematics", f"does not match law = {law!r}; small strain is law = 'linear'."
        )
    E, nu = _elastic_constants(material)
    output = _table(path, data, "output", required=False)
    mesh_spec = _mesh(path, _table(path, data, "mesh"), dimension)
    dirichlet = tuple(_boundary(r, dimension, True) for r in _array(path, data, "dirichlet"))
    tractions = tuple(_boundary(r, dimension, False) for r in _array(path, data, "traction"))
    obstacles = _obstacles(path, data, dimension)
    mu = next((o.contact.mu for o in obstacles if o.contact.mu is not None), None)
    fields = _fields(output, mu, "[contact]")
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
        obstacle=obstacles[0].obstacle,
        contact=obstacles[0].contact,
        solver=_solver(_table(path, data, "solver", required=False)),
        fields=tuple(fields),
        pictures=output.flag("pictures", True),
        obstacles=obstacles,
    )


def _obstacles(path: Path, data: dict[str, Any], dimension: int) -> tuple[ObstacleContactSpec, ...]:
    """[obstacle] with [contact] (one, named "obstacle"), or [[obstacle]] blocks (several).

    A block holds the obstacle's keys and its contact's (tag or detect, r,
    relative, quadrature, mu, tangential_r_max) and an optional name.
    """
    if not isinstance(data.get("obstacle"), list):
        obstacle = _obstacle(_table(path, data, "obstacle"), dimension)
        return (_checked_entry(path, ObstacleContactSpec(
            "obstacle", obstacle, _contact(_table(path, data, "contact")))),)
    return _obstacle_blocks(path, data, dimension)


def _obstacle_blocks(path: Path, data: dict[str, Any], dimension: int
                     ) -> tuple[ObstacleContactSpec, ...]:
    """The [[obstacle]] blocks (none when the scene has none)."""
    if "obstacle" not in data:
        return ()
    blocks = data["obstacle"]
    if not blocks or not all(isinstance(t, dict) for t in blocks):
        raise SceneError(f"{path.name}: [obstacle] must be a table or [[obstacle]] blocks "
                         f"(tables), not {blocks!r}.")
    if "contact" in data:
        raise SceneError(
            f"{path.name}: [contact] goes with a single [obstacle]; with [[obstacle]] blocks "
            "give each block its own contact keys (tag, r, mu, ...) and remove [contact]."
        )
    out = []
    for i, table in enumerate(blocks):
        _check_keys(path, "obstacles", table)
        name = table.get("name", f"obstacle{i + 1}")
        if not isinstance(name, str) or not name:
            raise SceneError(f"{path.name}: [[obstacle]] {i + 1} name = {name!r}: give a word.")
        reader = _Reader(path, f"obstacle '{name}'", table)
        out.append(_checked_entry(path, ObstacleContactSpec(
            name, _obstacle(reader, dimension), _contact(reader))))
    names = [o.name for o in out]
    if len(set(names)) != len(names):
        raise SceneError(f"{path.name}: [[obstacle]] names {names} repeat; name each once.")
    return tuple(out)


def _checked_entry(path: Path, entry: ObstacleContactSpec) -> ObstacleContactSpec:
    if entry.obstacle.schedule and entry.contact.detect:
        where = "[contact]" if entry.name == "obstacle" else f"[obstacle '{entry.name}']"
        raise SceneError(
            f"{path.name}: {where} detect = true follows the obstacle's straight motion; "
            f"with a schedule give the candidate facets by tag."
        )
    return entry


def _fields(output: _Reader, mu: float | None, section: str) -> tuple[str, ...]:
    """The output fields: all by default; friction fields only with a coefficient mu."""
    allowed = FIELDS + FRICTION_FIELDS if mu is not None else FIELDS
    fields = output.table.get("fields")
    fields = list(allowed) if fields is None else fields
    if not isinstance(fields, list) or any(f not in allowed for f in fields):
        hint = "" if mu is not None else f" (friction fields need {section} mu)"
        raise output.fail("fields", f"choose from {', '.join(allowed)}{hint}.")
    return tuple(fields)


def _elastic_constants(material: _Reader) -> tuple[float, float]:
    """E and nu, checked by the materials' own rule."""
    E, nu = material.number("E"), material.number("nu")
    problem = elastic_constants_problem(E, nu)
    if problem is not None:
        raise material.fail(*problem)
    return E, nu


def _two_body_scene(path: Path, data: dict[str, Any], head: _Reader, dimension: int) -> Scene:
    """A scene of deformable bodies ([[body]]), contact pairs ([[pair]]) and obstacles.

    Any number of pairs and of [[obstacle]] blocks (each naming the facets of
    a body that may touch it).
    """
    for key in ("material", "contact"):
        if key in data:
            raise SceneError(
                f"{path.name}: [{key}] belongs to single-body scenes; with [[body]] and "
                "[[pair]] give each body its law in [[body]] and r in [[pair]] or [[obstacle]]."
            )
    if "obstacle" in data and not isinstance(data["obstacle"], list):
        raise SceneError(
            f"{path.name}: with [[body]] blocks give rigid obstacles as [[obstacle]] blocks, "
            "each with the facet tag that may touch it (tag) and its r and mu."
        )
    bodies = _bodies(path, data)
    pairs = _pairs(path, data, dimension)
    obstacles = _obstacle_blocks(path, data, dimension)
    if len(bodies) < 2:
        raise SceneError(f"{path.name}: {len(bodies)} [[body]] block(s); a contact pair needs "
                         "two bodies: add a [[body]] per body (name, tag, law, E, nu).")
    if not pairs:
        raise SceneError(f"{path.name}: no [[pair]] block; add one with striker and target "
                         "facet tags.")
    names = [p.name for p in pairs] + [o.name for o in obstacles]
    if len(set(names)) != len(names):
        raise SceneError(f"{path.name}: contact names {names} repeat; give each [[pair]] and "
                         "[[obstacle]] its own name.")
    pair = pairs[0]
    output = _table(path, data, "output", required=False)
    mu = next((m for m in [p.mu for p in pairs] + [o.contact.mu for o in obstacles]
               if m is not None), None)
    fields = _fields(output, mu, "[[pair]] or [[obstacle]]")
    return Scene(
        path=path,
        name=str(head.table.get("name", path.stem)),
        dimension=dimension,
        description=str(head.table.get("description", "")),
        mesh=_mesh(path, _table(path, data, "mesh"), dimension),
        law=bodies[0].law,
        E=bodies[0].E,
        nu=bodies[0].nu,
        dirichlet=tuple(_boundary(r, dimension, True) for r in _array(path, data, "dirichlet")),
        tractions=tuple(_boundary(r, dimension, False) for r in _array(path, data, "traction")),
        obstacle=ObstacleSpec("none"),
        contact=ContactSpec(tag=pair.striker, r=pair.r, relative=pair.relative, mu=pair.mu,
                            tangential_r_max=pair.tangential_r_max),
        solver=_solver(_table(path, data, "solver", required=False)),
        fields=tuple(fields),
        pictures=output.flag("pictures", True),
        bodies=bodies,
        pairs=pairs,
        obstacles=obstacles,
    )


__all__ = [
    "FIELDS",
    "FRICTION_FIELDS",
    "GENERATOR_TAGS",
    "MAX_CUTBACKS",
    "MAX_ITERATIONS",
    "MAX_STEPS",
    "METHODS",
    "BodySpec",
    "BoundarySpec",
    "ContactSpec",
    "MeshSpec",
    "ObstacleContactSpec",
    "ObstacleSpec",
    "PairSpec",
    "Scene",
    "SceneError",
    "SolverSpec",
    "load_scene",
]
