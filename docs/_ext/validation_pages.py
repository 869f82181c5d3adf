"""Sphinx extension: one validation page per benchmark family, from committed JSON.

``docs/data/<name>.json`` is what ``benchmarks/validation/<name>.py`` wrote
(``--out``); :mod:`validation_families` says, per family, which table and
which figure to draw from it. At ``builder-inited`` each family gets
``_generated/validation/<name>.md`` (the benchmark's docstring, the machine
and date of the run, the table) and ``<name>.png`` (the figure), so no
number on these pages is copied by hand. A family whose JSON is missing
fails the build.
"""

from __future__ import annotations

import ast
import json
import re
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from scene_reference import write_if_changed
from validation_families import FAMILIES, Family

FOLDER = Path("_generated") / "validation"


def cell(value: object) -> str:
    """A table cell: floats to 4 significant digits, lists joined by spaces."""
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, list | tuple):
        return " ".join(cell(v) for v in value)
    return str(value)


def markdown_table(header: list[str], rows: list[list[object]]) -> str:
    """A Markdown (pipe) table; pipes inside cells escaped."""
    def line(cells: list[str]) -> str:
        return "| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |"

    lines = [line(header), "|" + "---|" * len(header)]
    lines += [line([cell(v) for v in row]) for row in rows]
    return "\n".join(lines)


def docstring(script: Path) -> str:
    """The benchmark script's module docstring as Markdown, its ``Run:`` line left out."""
    text = ast.get_docstring(ast.parse(script.read_text())) or ""
    text = re.sub(r":\w+:`([^`]+)`", r"`\1`", text.split("\nRun:")[0].strip())  # rST roles
    pieces = re.split(r"(``[^`]*``|`[^`]*`)", text)  # escape < outside code spans only
    return "".join(p if i % 2 else p.replace("<", "&lt;") for i, p in enumerate(pieces))


#: Options that only say where a benchmark writes its files.
WHERE = ("--out", "--image", "--picture", "--figure")


def options(machine: dict) -> str:
    """The options a run was given (``machine["argv"]``), its output paths left out."""
    argv, kept = list(machine.get("argv", [])), []
    while argv:
        word = argv.pop(0)
        if word.split("=")[0] in WHERE:
            if "=" not in word and argv:
                argv.pop(0)
            continue
        kept.append(word)
    return " ".join(kept)


def page(name: str, family: Family, data: dict, root: Path) -> str:
    """The Markdown of one validation page."""
    machine = data.get("machine", {})
    header, rows = family.table(data)
    given = options(machine)
    command = f"python benchmarks/validation/{name}.py {given} --out results/bench".replace(
        "  ", " ")
    ran = (f"with the options `{given}`" if given else "with its default options"
           ) if "argv" in machine else ""
    return "\n\n".join([
        f"# {family.title}",
        docstring(root / "benchmarks" / "validation" / f"{name}.py"),
        f"![{family.title}]({name}.png)",
        "## Measured",
        markdown_table(header, rows),
        family.reading,
        "## Where these numbers come from",
        f"Run {ran + ' ' if ran else ''}on `{machine.get('host', '?')}` "
        f"({machine.get('cpus', '?')} cores, Python "
        f"{machine.get('python', '?')}) on {machine.get('date', '?')}; the table and the "
        f"figure are drawn from `docs/data/{name}.json` when the site is built. To measure "
        f"again: `{command}` and copy `results/bench/{name}.json` to `docs/data/`.",
    ]) + "\n"


def generate(app) -> None:
    """Builder-inited: a page and a figure per family."""
    src = Path(app.srcdir)
    root = src.parent
    folder = src / FOLDER
    folder.mkdir(parents=True, exist_ok=True)
    for name, family in FAMILIES.items():
        data = json.loads((src / "data" / f"{name}.json").read_text())
        write_if_changed(folder / f"{name}.md", page(name, family, data, root))
        figure = folder / f"{name}.png"
        source = src / "data" / f"{name}.json"
        if not figure.exists() or figure.stat().st_mtime < source.stat().st_mtime:
            fig = family.figure(data)
            fig.savefig(figure, dpi=110)
            plt.close(fig)


def setup(app):
    """Register the generator."""
    app.connect("builder-inited", generate)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
