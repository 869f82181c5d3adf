"""The Dockerfile, pyproject.toml and Makefile agree (no Docker engine runs here)."""

import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).parent.parent
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())
DOCKERFILE = (ROOT / "Dockerfile").read_text()
MAKEFILE = (ROOT / "Makefile").read_text()


def pinned_minor() -> str:
    spec = next(
        d for d in PYPROJECT["project"]["optional-dependencies"]["dolfinx"]
        if d.startswith("dolfinx-solver-real")
    )
    lower = re.search(r">=\s*(\d+)\.(\d+)", spec)
    upper = re.search(r"<\s*(\d+)\.(\d+)", spec)
    assert lower and upper, spec
    assert (int(upper[1]), int(upper[2])) == (int(lower[1]), int(lower[2]) + 1), spec
    return f"{lower[1]}.{lower[2]}"


def test_docker_image_has_the_pinned_dolfinx_minor_version():
    image = re.search(r"^ARG DOLFINX_IMAGE=(\S+)$", DOCKERFILE, re.M)
    assert image, "the Dockerfile must declare ARG DOLFINX_IMAGE=..."
    assert image[1].startswith("ghcr.io/fenics/dolfinx/dolfinx:v")
    tag = image[1].rsplit(":v", 1)[1]
    assert tag.startswith(pinned_minor() + "."), (tag, pinned_minor())
    assert re.search(r"^FROM \$\{DOLFINX_IMAGE\}$", DOCKERFILE, re.M)


def test_docker_installs_the_makefile_extras_except_the_dolfinx_wheel():
    make_extras = re.search(r"^EXTRAS\s*\?=\s*(\S+)$", MAKEFILE, re.M)[1].split(",")
    docker_extras = re.search(r'pip install[^\n]*"\.\[([^\]]*)\]"', DOCKERFILE)[1].split(",")
    assert "dolfinx" in make_extras
    assert sorted(docker_extras) == sorted(e for e in make_extras if e != "dolfinx")
    assert set(make_extras) <= set(PYPROJECT["project"]["optional-dependencies"])


def test_dockerfile_hard_codes_no_interpreter_path():
    for line in DOCKERFILE.splitlines():
        if line.lstrip().startswith("#"):
            continue
        assert not re.search(r"/(usr|opt|dolfinx-env)[^\s\"]*/python", line), line
        assert not re.search(r"python3\.\d+", line), line


def test_readme_starts_with_the_two_commands_and_ci_calls_the_test_one():
    head = (ROOT / "README.md").read_text().splitlines()[:8]
    assert any(line.startswith("make demo") for line in head)
    assert any(line.startswith("make test") for line in head)
    assert "make test" in (ROOT / ".ci" / "run").read_text()
