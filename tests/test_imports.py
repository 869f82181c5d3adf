"""Every module of the package imports in any order, each time in a fresh interpreter.

Import order matters here: the DOLFINx wheel's MPI libraries must be loaded
before dolfinx or petsc4py (fenics_contact/__init__.py does it), and a module
that imports dolfinx first, or a circular import between layers, breaks only
in some orders. Each run imports every module, shuffled with its own seed.
"""

import os
import pkgutil
import random
import subprocess
import sys
from pathlib import Path

import pytest

import fenics_contact

ROOT = Path(__file__).resolve().parent.parent


def all_modules() -> list[str]:
    names = [
        m.name for m in pkgutil.walk_packages(fenics_contact.__path__, "fenics_contact.")
        if not m.name.endswith("__main__")
    ]
    return sorted(names)


def test_module_list_is_complete():
    names = all_modules()
    files = sorted(ROOT.glob("fenics_contact/**/*.py"))
    assert len(names) == len([f for f in files if f.name != "__main__.py"]) - 1  # top __init__
    for layer in ("model", "solvers", "scene", "output", "references", "sweeps", "cli"):
        assert f"fenics_contact.{layer}" in names


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_modules_import_in_random_order(seed):
    names = all_modules()
    random.Random(seed).shuffle(names)
    # a leaf module first, the package's own import last: the hardest orders
    script = "import importlib, sys\nfor n in sys.argv[1:]:\n    importlib.import_module(n)\n"
    env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg")
    done = subprocess.run(
        [sys.executable, "-c", script, *names], cwd=ROOT, env=env, capture_output=True,
        text=True, timeout=300,
    )
    assert done.returncode == 0, f"order {names}:\n{done.stderr[-3000:]}"


@pytest.mark.parametrize("module", ["fenics_contact.model.problem", "fenics_contact.runner",
                                    "fenics_contact.cli", "fenics_contact.solvers.newton"])
def test_each_entry_module_imports_alone(module):
    env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg")
    done = subprocess.run(
        [sys.executable, "-c", f"import {module}"], cwd=ROOT, env=env, capture_output=True,
        text=True, timeout=300,
    )
    assert done.returncode == 0, done.stderr[-3000:]
