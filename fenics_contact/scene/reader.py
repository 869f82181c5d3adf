"""Typed, named access to the tables of a TOML scene: every mistake names key, value and fix."""

from __future__ import annotations

import difflib
import math
from pathlib import Path
from typing import Any

from fenics_contact.scene.spec import SceneError

KEYS: dict[str, set[str]] = {
    "": {"scene", "mesh", "material", "dirichlet", "traction", "obstacle", "contact", "solver",
         "output", "body", "pair", "pairing"},
    "pairing": {"automatic", "r", "relative", "mu", "tangential_r_max", "margin"},
    "body": {"name", "tag", "law", "E", "nu", "stabilise"},
    "pair": {"name", "striker", "target", "r", "relative", "mu", "tangential_r_max",
             "self_contact", "neighbourhood", "discretisation", "interference_until",
             "slots"},
    "scene": {"name", "dimension", "description"},
    "mesh": {"file", "generator", "origin", "size", "cells", "cell", "parameters"},
    "material": {"law", "E", "nu", "kinematics"},
    "dirichlet": {"tag", "value", "x", "y", "z", "path"},
    "traction": {"tag", "value"},
    "obstacle": {"type", "point", "normal", "centre", "radius", "inside", "motion", "schedule"},
    "contact": {"tag", "x", "y", "z", "detect", "margin", "r", "relative", "quadrature", "mu",
                "tangential_r_max"},
    # one [[obstacle]] block: the obstacle, its contact and a name
    "obstacles": {"name", "type", "point", "normal", "centre", "radius", "inside", "motion",
                  "schedule", "tag", "x", "y", "z", "detect", "margin", "r", "relative",
                  "quadrature", "mu", "tangential_r_max"},
    "solver": {"method", "steps", "max_iterations", "atol", "rtol", "max_cutbacks", "predictor",
               "contact_set", "linear_solver", "forcing", "reuse_preconditioner"},
    "output": {"fields", "pictures"},
}


class _Reader:
    """Typed access to one TOML table with errors that name the key."""

    def __init__(self, path: Path, section: str, table: dict[str, Any]) -> None:
        self.path = path
        self.section = section
        self.table = table
        #: Which entry of an array of tables, after the section in messages (e.g. " 'upper'").
        self.entry = ""

    def where(self, key: str) -> str:
        return f"{self.path.name}: [{self.section}]{self.entry} {key}"

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

    def integer(
        self, key: str, default: int, *, minimum: int = 0, maximum: int | None = None,
        why: str = "",
    ) -> int:
        value = self.table.get(key, default)
        if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
            raise self.fail(key, f"must be an integer >= {minimum}.")
        if maximum is not None and value > maximum:
            raise self.fail(key, f"must be at most {maximum}; {why}")
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


#: How messages write the sections that are arrays of tables.
_ARRAYS = {"pair": "[[pair]]", "body": "[[body]]", "dirichlet": "[[dirichlet]]",
           "traction": "[[traction]]", "obstacles": "[[obstacle]]"}


def _check_keys(path: Path, section: str, table: dict[str, Any],
                where: str | None = None) -> None:
    """Refuse a key the section does not know; ``where`` names the block (else the section)."""
    allowed = KEYS[section]
    for key in table:
        if key not in allowed:
            close = difflib.get_close_matches(key, sorted(allowed), n=1)
            hint = f" Did you mean {close[0]!r}?" if close else ""
            elsewhere = [other for other, keys in KEYS.items() if other and key in keys]
            if not close and elsewhere:
                hint = " It belongs to " + " or ".join(
                    _ARRAYS.get(o, f"[{o}]") for o in elsewhere) + "."
            where = where or (f"[{section}]" if section else "top level")
            raise SceneError(
                f"{path.name}: unknown key {key!r} at {where}.{hint} "
                f"Allowed: {', '.join(sorted(allowed))}."
            )


def _block_name(section: str, index: int, table: dict[str, Any]) -> str:
    """How a message names the index-th [[section]] block: by its name, else its number."""
    name = table.get("name")
    return (f"[{section} {name!r}]" if isinstance(name, str) and name
            else f"[[{section}]] {index + 1}")


def _non_finite(value: object) -> list[str | int] | None:
    """The keys and indices leading to the first NaN or infinite number in ``value``, or None."""
    if isinstance(value, float) and not math.isfinite(value):
        return []
    items = (
        value.items() if isinstance(value, dict)
        else enumerate(value) if isinstance(value, list) else ()
    )
    for key, item in items:
        found = _non_finite(item)
        if found is not None:
            return [key, *found]
    return None


def _check_finite(path: Path, data: dict[str, Any]) -> None:
    """Refuse a NaN or infinite number anywhere in the scene, naming where it is."""
    for section, table in data.items():
        tables = table if isinstance(table, list) else [table]
        for i, entry in enumerate(tables):
            found = _non_finite(entry)
            if not found:
                continue
            name = f"[{section} {i + 1}]" if isinstance(table, list) else f"[{section}]"
            key, *inner = found
            at = "".join(f"[{k}]" if isinstance(k, int) else f".{k}" for k in inner)
            raise SceneError(
                f"{path.name}: {name} {key} = {entry[key]!r}: holds a NaN or infinite number"
                f"{' at ' + at if at else ''}; give finite numbers."
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
    for i, t in enumerate(items):
        _check_keys(path, section, t, _block_name(section, i, t))
    return [_Reader(path, f"[{section}]", t) for t in items]
