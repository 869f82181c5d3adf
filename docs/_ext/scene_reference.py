"""Sphinx extension: the scene reference, generated from the reader's key list.

Writes ``_generated/scene_reference.md`` (git-ignored) from
:data:`fenics_contact.scene.reader.KEYS`, the descriptions in
:data:`fenics_contact.scene.keys.KEY_DOCS` and the defaults of the spec
dataclasses. A key without a description, or a description of a key the
reader does not accept, is a build warning (an error under ``-W``).
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

from sphinx.util import logging

logger = logging.getLogger(__name__)

PAGE = Path("_generated") / "scene_reference.md"


def toml(value: object) -> str:
    """A default written as TOML."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{k} = {toml(v)}" for k, v in value.items()) + " }" \
            if value else "{}"
    if isinstance(value, tuple | list):
        return "[" + ", ".join(toml(v) for v in value) + "]"
    if value is None:
        return "absent"
    return repr(value)


def spec_default(field: str) -> str:
    """The default of ``"SpecClass.attribute"`` of :mod:`fenics_contact.scene.spec`."""
    from fenics_contact.scene import spec

    cls_name, attribute = field.split(".")
    for f in dataclasses.fields(getattr(spec, cls_name)):
        if f.name == attribute:
            if f.default is not dataclasses.MISSING:
                return toml(f.default)
            if f.default_factory is not dataclasses.MISSING:
                return toml(f.default_factory())
            raise ValueError(f"{field} has no default")
    raise ValueError(f"{field} is not a field of {cls_name}")


def coverage() -> list[str]:
    """Every disagreement between the reader's keys and their descriptions."""
    from fenics_contact.scene.keys import KEY_DOCS, SECTIONS
    from fenics_contact.scene.reader import KEYS

    problems = []
    for section in sorted(set(KEYS) | set(KEY_DOCS) | set(SECTIONS)):
        accepted = KEYS.get(section, set())
        described = set(KEY_DOCS.get(section, {}))
        if section not in SECTIONS:
            problems.append(f"section {section!r} has no title in SECTIONS")
        problems += [f"[{section}] {k}: accepted but not described" for k in
                     sorted(accepted - described)]
        problems += [f"[{section}] {k}: described but not accepted" for k in
                     sorted(described - accepted)]
    return problems


def cell(text: str) -> str:
    """Text for a Markdown table cell."""
    return text.replace("|", "\\|")


def markdown() -> str:
    """The scene reference page."""
    from fenics_contact.scene.keys import KEY_DOCS, SECTIONS
    from fenics_contact.scene.reader import KEYS

    lines = [
        "# Scene reference",
        "",
        "Every key of every section a scene file (TOML) accepts, generated from the "
        "reader's key list (`KEYS` in `fenics_contact/scene/reader.py`), the descriptions "
        "beside it (`KEY_DOCS` in `fenics_contact/scene/keys.py`) and the defaults of the "
        "scene's dataclasses (`fenics_contact/scene/spec.py`). Units are the user's, "
        "consistent: L a length, F a force (per unit thickness in plane strain), so a "
        "stress is F/L^2. A key not listed here is refused, naming the closest allowed one.",
        "",
    ]
    for section, (title, intro) in SECTIONS.items():
        docs = KEY_DOCS.get(section, {})
        lines += [f"## {title}", "", intro, "",
                  "| key | type | default | unit | meaning |", "|---|---|---|---|---|"]
        for key in sorted(KEYS.get(section, ()), key=lambda k: list(docs).index(k)
                          if k in docs else len(docs)):
            doc = docs.get(key)
            if doc is None:
                continue
            default = spec_default(doc.field) if doc.field else doc.default
            lines.append(
                f"| `{key}` | {cell(doc.type)} | {cell(default)} | {cell(doc.unit)} | "
                f"{cell(doc.meaning)} |"
            )
        lines.append("")
        if section == "mesh":
            from fenics_contact.scene.spec import GENERATOR_TAGS

            tags = "; ".join(f"{g}: " + ", ".join(f"{n} = {t}" for n, t in sides.items())
                             for g, sides in GENERATOR_TAGS.items())
            lines += [f"Generated meshes tag their sides ({tags}); tags may be given by "
                      "number or by name.", ""]
    return "\n".join(lines)


def write_if_changed(path: Path, text: str) -> None:
    """Write ``text`` unless the file holds it already (keeps Sphinx's incremental build)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        path.write_text(text, encoding="utf-8")


def generate(app) -> None:
    """Builder-inited: check the coverage, write the page."""
    for problem in coverage():
        logger.warning("scene reference: %s (fenics_contact/scene/keys.py)", problem)
    write_if_changed(Path(app.srcdir) / PAGE, markdown())


def setup(app):
    """Register the generator."""
    app.connect("builder-inited", generate)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
