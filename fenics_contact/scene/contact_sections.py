"""The contacts' scene sections: rigid obstacles with their contacts, and pairs.

[obstacle] with [contact] (one obstacle), [[obstacle]] blocks (several, each
with its contact's keys) and [[pair]] blocks (two deformable bodies), read
into their specs (:mod:`.spec`); every mistake raises
:class:`~.spec.SceneError` naming the key, the bad value and the fix.
"""

import itertools
import math
from pathlib import Path
from typing import Any

from fenics_contact.model.contact import r_problem
from fenics_contact.scene.reader import _array, _block_name, _check_keys, _Reader, _table
from fenics_contact.scene.sections import read_bounds
from fenics_contact.scene.spec import (
    ContactSpec,
    ObstacleContactSpec,
    ObstacleSpec,
    PairSpec,
    SceneError,
    default_discretisation,
)


def read_obstacles(path: Path, data: dict[str, Any], dimension: int
                   ) -> tuple[ObstacleContactSpec, ...]:
    """[obstacle] with [contact] (one, named "obstacle"), or [[obstacle]] blocks (several).

    A block holds the obstacle's keys and its contact's (tag or detect, r,
    relative, quadrature, mu, tangential_r_max) and an optional name.
    """
    if not isinstance(data.get("obstacle"), list):
        obstacle = _obstacle(_table(path, data, "obstacle"), dimension)
        return (_checked_entry(path, ObstacleContactSpec(
            "obstacle", obstacle, _contact(_table(path, data, "contact"), dimension))),)
    return read_obstacle_blocks(path, data, dimension)


def read_obstacle_blocks(path: Path, data: dict[str, Any], dimension: int
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
        _check_keys(path, "obstacles", table, _block_name("obstacle", i, table))
        name = table.get("name", f"obstacle{i + 1}")
        if not isinstance(name, str) or not name:
            raise SceneError(f"{path.name}: [[obstacle]] {i + 1} name = {name!r}: give a word.")
        reader = _Reader(path, f"obstacle '{name}'", table)
        out.append(_checked_entry(path, ObstacleContactSpec(
            name, _obstacle(reader, dimension), _contact(reader, dimension))))
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


def _contact(reader: _Reader, dimension: int) -> ContactSpec:
    detect = reader.flag("detect", False)
    if detect == ("tag" in reader.table):
        raise SceneError(
            f"{reader.path.name}: [{reader.section}] needs either 'tag' (the candidate facets) "
            "or 'detect = true' (found from the obstacle's path), not both or neither."
        )
    return ContactSpec(
        tag=reader.tag("tag") if not detect else None,
        bounds=read_bounds(reader, dimension) if not detect else {},
        detect=detect,
        margin=reader.number("margin", 0.0) if detect else 0.0,
        r=_contact_r(reader),
        relative=reader.flag("relative", True),
        quadrature=reader.choice("quadrature", ("nodal", "gauss"), default="nodal"),
        mu=_friction(reader),
        tangential_r_max=reader.number("tangential_r_max", 2.0, positive=True),
    )


def read_pairs(path: Path, data: dict[str, Any], dimension: int = 2) -> tuple[PairSpec, ...]:
    """The [[pair]] blocks: striker and target facet tags, r and friction per pair."""
    out = []
    for reader in _array(path, data, "pair"):
        self_contact = reader.flag("self_contact", False)
        two_surfaces = reader.table.get("target", reader.table.get("striker")) != \
            reader.table.get("striker")
        if self_contact:  # one surface against itself: the target defaults to the striker
            reader.table.setdefault("target", reader.table.get("striker"))
        elif "neighbourhood" in reader.table:
            raise reader.fail("neighbourhood", "belongs to self-contact: add self_contact = true "
                              "or remove neighbourhood.")
        for key in ("striker", "target"):
            if reader.table.get(key) is None:
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
            self_contact=self_contact,
            neighbourhood=reader.number("neighbourhood", 3.0, positive=True),
            discretisation=_discretisation(reader, dimension, two_surfaces),
            interference_until=_interference_until(reader),
            slots=_slots(reader, dimension),
        ))
    _refuse_repeated_surfaces(path, out)
    return tuple(out)


def _refuse_repeated_surfaces(path: Path, pairs: list[PairSpec]) -> None:
    """Two pairs on the same two surfaces (either way round) would constrain them twice."""
    seen: dict[frozenset, str] = {}
    for pair in pairs:
        key = frozenset((("s", pair.striker), ("t", pair.target)))
        swapped = frozenset((("s", pair.target), ("t", pair.striker)))
        other = seen.get(key) or seen.get(swapped)
        if other is not None:
            how = "the same" if key in seen else "the same two surfaces swapped"
            raise SceneError(
                f"{path.name}: [[pair]] '{pair.name}' joins {how} as [[pair]] '{other}' "
                f"(striker {pair.striker!r}, target {pair.target!r}): the interface would be "
                "constrained twice (a multiplier pair each way over-constrains it). Declare "
                'each contact once; for exactness on non-matching meshes use discretisation = '
                '"mortar".'
            )
        seen[key] = pair.name


def _interference_until(reader: _Reader) -> float | None:
    """[[pair]] interference_until: a load factor in (0, 1], or None (absent)."""
    if "interference_until" not in reader.table:
        return None
    value = reader.number("interference_until")
    if not 0.0 < value <= 1.0:
        raise reader.fail("interference_until", "is the load factor by which the starting "
                          "overlap is resolved: give a number in (0, 1] (1: over the whole "
                          "load path), or leave the key out to resolve it by the first step.")
    return value


def _slots(reader: _Reader, dimension: int) -> int | None:
    """[[pair]] slots: target facets a 2D mortar striker node may see; None: from the meshes."""
    if "slots" not in reader.table:
        return None
    discretisation = reader.table.get("discretisation", default_discretisation(
        reader.flag("self_contact", False)))
    if discretisation != "mortar" or dimension != 2:
        raise reader.fail("slots", "is the number of target facets a striker node of a 2D "
                          'mortar pair may see: it needs discretisation = "mortar" (the '
                          "default between bodies) in a 2D scene; remove it here.")
    return reader.integer("slots", 4, minimum=2, maximum=32,
                          why="each slot adds to the compiled forms; refine the striker "
                          "surface instead.")


def _discretisation(reader: _Reader, dim: int, two_surfaces: bool) -> str:
    """[[pair]] discretisation: "mortar" or "node-to-segment".

    The default is mortar for a pair between bodies (exact on non-matching
    meshes) and node-to-segment for self-contact (the key self_contact = true).
    A mortar pair joins two disjoint surfaces: of two bodies, or two surfaces
    of one body (self_contact = true with a target other than the striker).
    """
    value = reader.table.get("discretisation", default_discretisation(
        reader.flag("self_contact", False)))
    if value not in ("node-to-segment", "mortar"):
        raise reader.fail("discretisation", 'choose "mortar" (the default between bodies) or '
                          '"node-to-segment" (the default for self-contact).')
    if value == "mortar" and reader.flag("self_contact", False):
        if not two_surfaces:
            raise reader.fail(
                "discretisation", "a mortar pair joins two surfaces: with self_contact = true "
                "give a target, the part of the body's surface the striker meets, tagged apart "
                "from the striker (as scenes/tube_crush.toml does); one surface against itself "
                'is "node-to-segment".')
        if "neighbourhood" in reader.table:
            raise reader.fail(
                "neighbourhood", "belongs to node-to-segment self-contact; a mortar pair "
                "pairs only facets that face each other and needs no neighbourhood: remove it.")
    return value


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


__all__ = ["read_obstacle_blocks", "read_obstacles", "read_pairs"]
