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
    [contact]    tag (optionally x/y/z = [min, max] bounds on facet midpoints),
                 or detect = true with margin; r, relative, quadrature,
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
    [pairing]    automatic = true (every body against every other, instead of or
                 besides [[pair]]), r, relative, mu, tangential_r_max, margin
    [solver]     method, steps, max_iterations, atol, rtol, max_cutbacks,
                 predictor = "active-set" (start a step from the linear
                 extrapolation of the last two, the first iteration's
                 contact set from the gaps' history) | "extrapolate" |
                 "previous",
                 contact_set = "exact" (each Newton step takes the exact
                 contact set of its linear model) | "sign" (the sign of
                 lam + r g at the iterate),
                 linear_solver = "direct" (MUMPS) | "iterative" (GMRES,
                 Schur field split, algebraic multigrid; for large 3D),
                 forcing = "fixed" | "eisenstat-walker" and
                 reuse_preconditioner = "no" | "step" | "path" (iterative
                 only: inexact Newton, multigrid kept between steps)
    [output]     fields = [...], pictures = true

Deformable bodies in one mesh replace [material] and [contact] by::

    [[body]]     name, tag (cell tag), law, E, nu      (one per body)
    [[pair]]     name, striker, target (facet tags), r, relative,
                 mu, tangential_r_max (Coulomb friction, as in [contact]),
                 self_contact = true (the target on the striker's own body; target
                 defaults to striker; one [[body]] is then enough; so it is with
                 [[obstacle]] blocks and no pair), neighbourhood
                 (facet sizes along the surface a node does not search; default 3)
                 discretisation = "mortar" (the default between bodies: exact on
                 non-matching meshes; 2D and 3D, with or without mu) |
                 "node-to-segment" (the default for self-contact)
    [[obstacle]] as above, its tag on the facets of one body

In every scene a [[dirichlet]] may give path = [[t, ux, uy], ...] (a
piecewise-linear displacement against the load factor, every component
prescribed) instead of value.

Generated meshes tag their sides: rectangle left = 1, right = 2,
bottom = 3, top = 4; box xmin = 1, xmax = 2, ymin = 3, ymax = 4, zmin = 5,
zmax = 6. Tags may be given by number or by name.
"""

import tomllib
from pathlib import Path
from typing import Any

from fenics_contact.model.materials import MATERIALS
from fenics_contact.scene.contact_sections import (
    read_obstacle_blocks,
    read_obstacles,
    read_pairs,
)
from fenics_contact.scene.pairing import read_pairing
from fenics_contact.scene.reader import _array, _check_finite, _check_keys, _Reader, _table
from fenics_contact.scene.sections import (
    MAX_CUTBACKS,
    MAX_ITERATIONS,
    MAX_STEPS,
    elastic_constants,
    read_bodies,
    read_boundary,
    read_mesh,
    read_solver,
    why_bounded,
)
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
    return scene_from_data(data, path)


def scene_from_data(data: dict[str, Any], path: Path | str) -> Scene:
    """Validate a scene given as the TOML document's data (nested dicts and lists).

    The route of scenes written in Python: the same checks and messages as
    :func:`load_scene`. ``path`` names the scene in messages, and relative
    mesh files are found beside it (it need not exist).
    """
    path = Path(path)
    _check_keys(path, "", data)
    _check_finite(path, data)
    head = _table(path, data, "scene")
    dimension = head.table.get("dimension")
    if dimension is None:
        raise SceneError(f"{path.name}: [scene] needs 'dimension': 2 (plane strain) or 3.")
    if dimension not in (2, 3):
        raise SceneError(
            f"{path.name}: [scene] dimension = {dimension!r}: use 2 (plane strain) or 3."
        )
    if "pair" in data or "body" in data or "pairing" in data:
        return _two_body_scene(path, data, head, dimension)
    material = _table(path, data, "material")
    law = material.choice("law", tuple(sorted(MATERIALS)))
    kinematics = material.choice("kinematics", ("finite", "small"), default="")
    small = law == "linear"
    if kinematics and (kinematics == "small") != small:
        raise material.fail(
            "kinematics", f"does not match law = {law!r}; small strain is law = 'linear'."
        )
    E, nu = elastic_constants(material)
    output = _table(path, data, "output", required=False)
    mesh_spec, dirichlet, tractions = _conditions(path, data, dimension)
    obstacles = read_obstacles(path, data, dimension)
    mu = next((o.contact.mu for o in obstacles if o.contact.mu is not None), None)
    fields = _fields(output, mu, "[contact]")
    return Scene(
        **_header(path, head, dimension),
        mesh=mesh_spec,
        law=law,
        E=E,
        nu=nu,
        dirichlet=dirichlet,
        tractions=tractions,
        obstacle=obstacles[0].obstacle,
        contact=obstacles[0].contact,
        **_run_settings(path, data, output, fields),
        obstacles=obstacles,
    )


def _header(path: Path, head: _Reader, dimension: int) -> dict[str, Any]:
    """The Scene fields of [scene]: path, name (default: the file's stem), dimension."""
    return {
        "path": path,
        "name": str(head.table.get("name", path.stem)),
        "dimension": dimension,
        "description": str(head.table.get("description", "")),
    }


def _conditions(path: Path, data: dict[str, Any], dimension: int
                ) -> tuple[MeshSpec, tuple[BoundarySpec, ...], tuple[BoundarySpec, ...]]:
    """[mesh], then the [[dirichlet]] and [[traction]] blocks, read in this order."""
    mesh_spec = read_mesh(path, _table(path, data, "mesh"), dimension)
    dirichlet = tuple(read_boundary(r, dimension, True) for r in _array(path, data, "dirichlet"))
    tractions = tuple(read_boundary(r, dimension, False) for r in _array(path, data, "traction"))
    return mesh_spec, dirichlet, tractions


def _run_settings(path: Path, data: dict[str, Any], output: _Reader, fields: tuple[str, ...]
                  ) -> dict[str, Any]:
    """The Scene fields of [solver] and [output] (fields already read)."""
    return {
        "solver": read_solver(_table(path, data, "solver", required=False)),
        "fields": tuple(fields),
        "pictures": output.flag("pictures", True),
    }


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
    bodies = read_bodies(path, data)
    pairs = read_pairs(path, data, dimension)
    obstacles = read_obstacle_blocks(path, data, dimension)
    pairing = read_pairing(path, data)
    between = [p.name for p in pairs if not p.self_contact]
    if len(bodies) < 2 and (between or pairing is not None):
        what, drop = ((f"[[pair]] {between[0]!r} is a contact pair between two bodies",
                       f"self_contact = true in [[pair]] {between[0]!r} for a surface touching "
                       "its own body") if between else
                      ("[pairing] automatic = true pairs every body with every other",
                       "remove [pairing] (one body against obstacles needs no pair)"))
        raise SceneError(f"{path.name}: {len(bodies)} [[body]] block(s); {what}, and a "
                         "contact pair needs two bodies: add a [[body]] per body (name, tag, "
                         f"law, E, nu), or {drop}.")
    if not pairs and pairing is None and not obstacles:
        raise SceneError(f"{path.name}: no contact: add a [[pair]] with striker and target "
                         "facet tags, [pairing] automatic = true, or an [[obstacle]] block.")
    names = [p.name for p in pairs] + [o.name for o in obstacles]
    if len(set(names)) != len(names):
        raise SceneError(f"{path.name}: contact names {names} repeat; give each [[pair]] and "
                         "[[obstacle]] its own name.")
    if pairs:
        contact = _pair_contact(pairs[0])
    elif pairing is not None:
        contact = _pair_contact(PairSpec("automatic", "", "", r=pairing.r,
                                         relative=pairing.relative, mu=pairing.mu))
    else:  # obstacles only: the first obstacle's, as in a [material] scene
        contact = obstacles[0].contact
    output = _table(path, data, "output", required=False)
    mu = next((m for m in [p.mu for p in pairs] + [o.contact.mu for o in obstacles]
               + [pairing.mu if pairing else None]
               if m is not None), None)
    fields = _fields(output, mu, "[[pair]] or [[obstacle]]")
    mesh_spec, dirichlet, tractions = _conditions(path, data, dimension)
    return Scene(
        **_header(path, head, dimension),
        mesh=mesh_spec,
        law=bodies[0].law,
        E=bodies[0].E,
        nu=bodies[0].nu,
        dirichlet=dirichlet,
        tractions=tractions,
        obstacle=ObstacleSpec("none") if pairs or pairing else obstacles[0].obstacle,
        contact=contact,
        **_run_settings(path, data, output, fields),
        bodies=bodies,
        pairs=pairs,
        obstacles=obstacles,
        pairing=pairing,
    )


def _pair_contact(pair: PairSpec) -> ContactSpec:
    """The scene's first contact's fields from a pair (its striker as the tag)."""
    return ContactSpec(tag=pair.striker, r=pair.r, relative=pair.relative, mu=pair.mu,
                       tangential_r_max=pair.tangential_r_max)


def _fields(output: _Reader, mu: float | None, section: str) -> tuple[str, ...]:
    """The output fields: all by default; friction fields only with a coefficient mu."""
    allowed = FIELDS + FRICTION_FIELDS if mu is not None else FIELDS
    fields = output.table.get("fields")
    fields = list(allowed) if fields is None else fields
    if not isinstance(fields, list) or any(f not in allowed for f in fields):
        hint = "" if mu is not None else f" (friction fields need {section} mu)"
        raise output.fail("fields", f"choose from {', '.join(allowed)}{hint}.")
    return tuple(fields)


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
    "scene_from_data",
    "why_bounded",
]
