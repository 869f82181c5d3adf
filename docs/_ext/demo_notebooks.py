"""Sphinx extension: the jupytext percent demos in ``demos/`` as notebook pages.

Each ``demos/<name>.py`` is read with jupytext and written as
``_generated/demos/<name>.ipynb`` (git-ignored), with one hidden cell in
front that sets what a script gets from its command line (``__file__``,
``--out`` into the build folder) and ``CI=1`` (the demos' small size), and
one hidden-input cell at the end that shows the figures the demo wrote.
myst-nb executes the notebooks (``nb_execution_mode``; cached by content).
"""

from __future__ import annotations

from pathlib import Path

import jupytext
import nbformat
from scene_reference import write_if_changed

FOLDER = Path("_generated") / "demos"


def notebook(script: Path, out: Path) -> str:
    """The demo as notebook JSON, with the set-up and figure cells added."""
    nb = jupytext.read(script, fmt="py:percent")
    setup = nbformat.v4.new_code_cell(
        "import os, sys\n"
        'os.environ["CI"] = "1"  # the small size of every demo\n'
        f"__file__ = {str(script)!r}\n"
        f"sys.argv = [{script.name!r}, '--out', {str(out)!r}]"
    )
    setup.metadata["tags"] = ["remove-cell"]
    figures = nbformat.v4.new_code_cell(
        "from pathlib import Path as _Path\n"
        "from IPython.display import Image as _Image, display as _display\n"
        f"for _png in sorted(_Path({str(out)!r}).glob('*.png')):\n"
        "    _display(_Image(filename=str(_png)))"
    )
    figures.metadata["tags"] = ["remove-input"]
    nb.cells = [setup, *nb.cells, figures]
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3",
                                 "language": "python"}
    nb.metadata.pop("jupytext", None)
    for c in nb.cells:  # stable ids: the execution cache keys on the content
        c.pop("id", None)
    nb.nbformat, nb.nbformat_minor = 4, 4
    return nbformat.writes(nb)


def generate(app) -> None:
    """Builder-inited: one notebook a demo script."""
    src = Path(app.srcdir)
    demos = src.parent / "demos"
    out = Path(app.outdir).parent / "demo-output"
    for script in sorted(demos.glob("*.py")):
        write_if_changed(src / FOLDER / f"{script.stem}.ipynb",
                         notebook(script.resolve(), (out / script.stem).resolve()))


def setup(app):
    """Register the generator."""
    app.connect("builder-inited", generate)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
