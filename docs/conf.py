"""Sphinx configuration of the documentation site (`make docs`)."""

import sys
from pathlib import Path

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE / "_ext"))
sys.path.insert(0, str(HERE.parent))

project = "fenics-contact"
author = "fenics-contact contributors"
copyright = "fenics-contact contributors"
release = "0.1.0"

extensions = [
    "myst_nb",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "scene_reference",
    "demo_notebooks",
    "api_pages",
    "validation_pages",
]

# .rst first: autosummary writes its module pages (reStructuredText) with the first suffix.
source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}
exclude_patterns = ["_build", "**/.ipynb_checkpoints", "_generated/public_api.rst"]
templates_path = ["_templates"]

# MyST: heading anchors for the pages' `page.md#section` links.
myst_heading_anchors = 3
myst_enable_extensions = ["dollarmath"]

# The demos: executed (at their small CI size), cached by content, a failure fails the build.
nb_execution_mode = "cache"
nb_execution_timeout = 600
nb_execution_raise_on_error = True
nb_execution_show_tb = True
nb_merge_streams = True

# The API from the docstrings (Google style).
autosummary_generate = True
autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_default_options = {"show-inheritance": True}
napoleon_google_docstring = True
napoleon_numpy_docstring = False
napoleon_use_ivar = True

html_theme = "alabaster"
html_title = "fenics-contact"
html_static_path: list[str] = []
