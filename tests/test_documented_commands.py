"""Every command README.md and docs/*.md give in a ``sh`` block runs, so none rots.

The fenced ``sh`` blocks are parsed; each command must appear in COMMANDS
with the smoke-sized command that stands for it here (the same program and
subcommand, a temporary --out, fewer repeats or a reduced grid where the real
run is long), or with the reason it cannot run here. A command added to the
docs without an entry fails :func:`test_every_documented_command_is_listed`.
Placeholders: {python} (this interpreter), {cli} (the fenics-contact command),
{mpiexec}, {out} (a fresh folder).
"""

import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
BIN = Path(sys.executable).parent

#: documented command -> smoke command, or ("skip", reason)
COMMANDS: dict[str, str | tuple[str, str]] = {
    # make: a dry run proves the target and its recipe resolve; the demo itself
    # runs in tests/test_demos.py and the suite is this suite
    "make demo": "make -n demo",
    "make test": "make -n test",
    "fenics-contact run scenes/hertz_cylinder.toml --out results/hertz":
        "{cli} run scenes/hertz_cylinder.toml --out {out} --quiet",
    "docker build -t fenics-contact .": ("skip", "needs a Docker daemon"),
    'docker run --rm -v "$PWD/results:/app/results" fenics-contact':
        ("skip", "needs a Docker daemon"),
    'docker run --rm -v "$PWD/results:/app/results" -v "$PWD/scenes:/app/scenes" '
    "fenics-contact fenics-contact run scenes/hertz_cylinder.toml --out results/hertz":
        ("skip", "needs a Docker daemon (the same run is the fenics-contact run above)"),
    # benchmarks: the real runs take minutes to hours; --help imports everything
    # (the import order that once broke cost_of_contact.py) and the cheap ones run
    "python benchmarks/run_all.py": "{python} benchmarks/run_all.py --help",
    "python benchmarks/run_all.py --quick": "{python} benchmarks/run_all.py --help",
    "python benchmarks/validation/hertz2d.py": "{python} benchmarks/validation/hertz2d.py --help",
    "python benchmarks/targets.py": "{python} benchmarks/targets.py --bench {out}",
    "python benchmarks/performance/auto_r_range.py":
        "{python} benchmarks/performance/auto_r_range.py --help",
    "python benchmarks/performance/cost_of_contact.py":
        "{python} benchmarks/performance/cost_of_contact.py --help",
    "python benchmarks/validation/hertz3d.py": "{python} benchmarks/validation/hertz3d.py --help",
    "python benchmarks/performance/compile_cost.py":
        "{python} benchmarks/performance/compile_cost.py --help",
    "python benchmarks/performance/ladder3d.py --dofs 1e5 --solver iterative":
        "{python} benchmarks/performance/ladder3d.py --dofs 1e3 --solver iterative --repeats 1 "
        "--out {out}",
    "mpiexec -n 2 python benchmarks/performance/ladder3d.py --dofs 1e6 --solver iterative "
    "--repeats 1":
        "{mpiexec} -n 2 {python} benchmarks/performance/ladder3d.py --dofs 1e3 --solver "
        "iterative --repeats 1 --out {out}",
    "python benchmarks/performance/inexact_newton.py --dofs 1e5":
        "{python} benchmarks/performance/inexact_newton.py --dofs 1e3 --rounds 1 --out {out}",
    "python benchmarks/performance/ladder3d.py --table":
        "{python} benchmarks/performance/ladder3d.py --table --out {out}",
    "python benchmarks/performance/two_body.py --dim 3 --h 0.013 --solver iterative --steps 4":
        "{python} benchmarks/performance/two_body.py --dim 3 --h 0.1 --solver iterative "
        "--steps 1 --repeats 1 --out {out}",
    "mpiexec -n 2 python benchmarks/performance/two_body.py --dim 3 --h 0.013 --solver "
    "iterative --steps 4":
        "{mpiexec} -n 2 {python} benchmarks/performance/two_body.py --dim 3 --h 0.1 --solver "
        "iterative --steps 1 --repeats 1 --out {out}",
    "python benchmarks/run_all.py --only twobody": "{python} benchmarks/run_all.py --help",
    "python benchmarks/research/tradeoff.py --out results/tradeoff":
        "{python} benchmarks/research/tradeoff.py --scene bar --methods gnrm --r 1 --meshes 1 "
        "--repeats 1 --out {out}",
    "python benchmarks/research/tradeoff.py --scene friction --mu 0.1,0.3 --repeats 1 "
    "--meshes 3 --out results/trf":
        "{python} benchmarks/research/tradeoff.py --scene friction --mu 0.3 --methods gnrm "
        "--r 1 --meshes 1 --repeats 1 --out {out}",
    "python benchmarks/robustness/stability_grid.py --out results/stability":
        "{python} benchmarks/robustness/stability_grid.py --cases bar-r1e0 --methods gnrm "
        "--out {out}",
    "python benchmarks/robustness/stability_grid.py --cases E,bar-r1e12 --methods gnrm,auto":
        "{python} benchmarks/robustness/stability_grid.py --cases bar-E1e3,bar-r1e12 "
        "--methods gnrm,auto --out {out}",
    "python benchmarks/performance/candidate_facets.py":
        "{python} benchmarks/performance/candidate_facets.py --help",
    "fenics-contact run SCENE --resume DIR":
        ("skip", "a template; tests/test_interrupt.py stops and resumes real runs"),
    "mpiexec -n 2 fenics-contact run SCENE --resume DIR":
        ("skip", "a template; tests/test_interrupt.py resumes on 2 processes"),
    "pvpython results/hertz/paraview_state.py":
        ("skip", "needs ParaView's pvpython; tests/test_contact_pictures.py runs the script "
         "where pvpython is installed and against a stand-in paraview.simple everywhere"),
    "pvpython results/hertz/paraview_state.py --step 2 --png hertz_step2.png":
        ("skip", "needs ParaView's pvpython (see the entry above)"),
}

#: commands known to fail on this branch (fixed elsewhere): strict, so the
#: mark must go when the fix lands
KNOWN_BROKEN: dict[str, str] = {}


def documented_commands() -> list[str]:
    """Commands of every ``sh`` block: continuation lines joined, comments dropped."""
    commands = []
    for doc in DOCS:
        for block in re.findall(r"```sh\n(.*?)```", doc.read_text(), flags=re.S):
            text = re.sub(r"\\\n\s*", " ", block)
            for line in text.splitlines():
                line = re.sub(r"\s+#.*$", "", line).strip()
                if line and not line.startswith("#"):
                    commands.append(" ".join(line.split()))
    return commands


def test_every_documented_command_is_listed():
    found = documented_commands()
    assert len(found) >= 15
    missing = [c for c in found if c not in COMMANDS]
    assert not missing, f"documented commands without a smoke entry: {missing}"
    stale = [c for c in COMMANDS if c not in found]
    assert not stale, f"entries for commands the docs no longer give: {stale}"


def _cases():
    for doc_command, smoke in COMMANDS.items():
        marks = []
        if isinstance(smoke, tuple):
            marks.append(pytest.mark.skip(reason=smoke[1]))
        if doc_command in KNOWN_BROKEN:
            marks.append(pytest.mark.xfail(reason=KNOWN_BROKEN[doc_command], strict=True))
        yield pytest.param(doc_command, smoke, marks=marks, id=doc_command[:60])


@pytest.mark.parametrize(("doc_command", "smoke"), list(_cases()))
def test_documented_command_runs(doc_command, smoke, tmp_path):
    cli = BIN / "fenics-contact"
    mpiexec = BIN / "mpiexec" if (BIN / "mpiexec").exists() else shutil.which("mpiexec")
    command = smoke.format(
        python=sys.executable, cli=cli, mpiexec=mpiexec, out=tmp_path / "out"
    )
    env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg")
    done = subprocess.run(
        shlex.split(command), cwd=ROOT, env=env, capture_output=True, text=True, timeout=600,
    )
    assert done.returncode == 0, f"{command}\n{done.stdout[-2000:]}\n{done.stderr[-3000:]}"
    assert "Traceback" not in done.stderr, done.stderr[-3000:]
