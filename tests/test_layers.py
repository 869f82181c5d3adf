"""The package's layers, as docs/layout.md states them: no module imports a layer above its own.

Every ``import`` and ``from ... import`` of every module is read with ``ast``
(those inside functions and ``TYPE_CHECKING`` blocks too: a lazy import is
still a dependency).
"""

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).parent.parent / "fenics_contact"

#: What each layer may import besides itself (docs/layout.md, "What may import what").
#: Layers not named here (cli, runner, the package's top-level modules) may import
#: anything.
ALLOWED = {
    "model": set(),
    "solvers": {"model"},
    "scene": {"model", "solvers"},
    "output": {"model", "solvers", "scene"},
    "references": {"model"},
    "sweeps": {"model", "solvers", "scene", "output"},
}


def violations(package: Path) -> list[str]:
    """'module -> imported (line)' for every import against :data:`ALLOWED`."""
    name = package.name
    found = []
    for path in sorted(package.rglob("*.py")):
        parts = path.relative_to(package).with_suffix("").parts
        if len(parts) < 2 or parts[0] not in ALLOWED:
            continue
        layer = parts[0]
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.ImportFrom) and node.level:
                raise AssertionError(f"{path}: relative import; write the absolute one")
            targets = (
                [node.module] if isinstance(node, ast.ImportFrom) and node.module
                else [a.name for a in node.names] if isinstance(node, ast.Import) else []
            )
            for target in targets:
                pieces = target.split(".")
                if pieces[0] != name:
                    continue
                other = pieces[1] if len(pieces) > 1 else "(package)"
                if other != layer and other not in ALLOWED[layer]:
                    found.append(f"{name}.{'.'.join(parts)} -> {target} (line {node.lineno})")
    return found


def test_no_module_imports_against_the_layers():
    assert violations(PACKAGE) == []


@pytest.mark.parametrize(("layer", "source", "caught"), [
    ("model", "from pkg.solvers.newton import NewtonKernel\n", True),
    ("output", "def f():\n    import pkg.studies.tradeoff\n", True),
    ("references", "from pkg.solvers import make_strategy\n", True),
    ("sweeps", "from pkg.cli.study import methods\n", True),
    ("scene", "import pkg\n", True),
    ("output", "from pkg.scene.schema import FIELDS\n", False),
])
def test_the_check_finds_an_upward_import(tmp_path, layer, source, caught):
    """The checker itself, on a small package: it must be able to fail."""
    package = tmp_path / "pkg"
    (package / layer).mkdir(parents=True)
    (package / layer / "bad.py").write_text(source)
    assert bool(violations(package)) == caught


def test_no_module_outside_the_model_probes_the_problem_kind():
    """Solvers, output and studies read ``problem.frictional`` and the problem's methods
    (``laws``, ``body_ids``); they never ask what kind of problem they hold."""
    import re

    probe = re.compile(r"\b(hasattr|getattr|isinstance)\((self\.)?(problem|state)\b")
    found = [
        f"{path.relative_to(PACKAGE)}:{number}"
        for path in sorted(PACKAGE.rglob("*.py")) if "model" not in path.parts
        for number, line in enumerate(path.read_text().splitlines(), 1) if probe.search(line)
    ]
    assert found == []
