"""Sphinx extension: the API reference's public-API table and plain-text docstrings.

* Writes ``_generated/public_api.rst`` (git-ignored): an autosummary of
  ``fenics_contact.__all__`` by each object's home module, so every object is
  described once (on its module's page) and the table links there.
* The package's docstrings write norms and absolute values as ``|x - c|``
  (plain text); reStructuredText would read them as substitutions. Bars
  outside literals are escaped as the docstrings are read (line blocks,
  ``| `` at the start of a line, and grid tables are left alone).
"""

from __future__ import annotations

import inspect
import re
from pathlib import Path

from scene_reference import write_if_changed

PAGE = Path("_generated") / "public_api.rst"
#: Literal and interpreted text, whose bars stay as they are.
_LITERAL = re.compile(r"(``.*?``|`[^`]*`)")


def home(name: str) -> str | None:
    """``module.qualname`` of a public name's class or function; None for data."""
    import fenics_contact

    obj = getattr(fenics_contact, name)
    if not (inspect.isclass(obj) or inspect.isfunction(obj)):
        return None
    return f"{obj.__module__}.{obj.__qualname__}"


def public_api() -> str:
    """The autosummary of ``fenics_contact.__all__`` (classes and functions; then data)."""
    import fenics_contact

    names = sorted(fenics_contact.__all__, key=str.lower)
    homes = [home(n) for n in names]
    lines = [".. autosummary::", "   :nosignatures:", ""]
    # relative to the current module, fenics_contact (the page's automodule)
    lines += [f"   {h.removeprefix('fenics_contact.')}" for h in homes if h is not None]
    data = [n for n, h in zip(names, homes, strict=True) if h is None]
    if data:
        lines += ["", "Data: " + ", ".join(f"``fenics_contact.{n}``" for n in data) + "."]
    return "\n".join(lines) + "\n"


def escape_bars(app, what, name, obj, options, lines: list[str]) -> None:
    """Escape ``|`` outside literals in docstring lines (autodoc-process-docstring)."""
    for i, line in enumerate(lines):
        if "|" not in line or line.lstrip().startswith(("| ", "+-", "+=")):
            continue
        pieces = _LITERAL.split(line)
        lines[i] = "".join(p if j % 2 else p.replace("|", "\\|") for j, p in enumerate(pieces))


def generate(app) -> None:
    """Builder-inited: write the public-API table."""
    write_if_changed(Path(app.srcdir) / PAGE, public_api())


def setup(app):
    """Register the generator and the docstring filter."""
    app.connect("builder-inited", generate)
    app.connect("autodoc-process-docstring", escape_bars)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
