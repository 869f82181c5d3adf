"""The demos run as they are (serially, and on 2 ranks under `make test`)."""

import gc
import json
import runpy
import sys
from pathlib import Path

import pytest

from mpi4py import MPI

DEMOS = Path(__file__).parent.parent / "demos"


def run_demo(name, out, monkeypatch):
    monkeypatch.setattr(sys, "argv", [name, "--out", str(out)])
    runpy.run_path(str(DEMOS / name), run_name="__main__")
    # free the demo's PETSc objects now, on every rank together (their destruction is
    # collective: left to the garbage collector it may come mid-solve on one rank only)
    gc.collect()


def shared_tmp(tmp_path):
    """One folder for all ranks (rank 0's tmp_path)."""
    return Path(MPI.COMM_WORLD.bcast(str(tmp_path), root=0))


@pytest.mark.mpi
def test_paper_example2_demo(tmp_path, monkeypatch):
    out = shared_tmp(tmp_path)
    run_demo("paper_example2.py", out, monkeypatch)
    MPI.COMM_WORLD.Barrier()
    summary = json.loads((out / "summary.json").read_text())
    runs = summary["runs"]
    assert [run["status"] for run in runs] == ["converged"] * 5
    assert [run["iterations"] for run in runs][:4] == [40, 40, 40, 40]
    assert max(run["error"] for run in runs) < 1e-10


@pytest.mark.mpi
def test_hertz_cylinder_demo(tmp_path, monkeypatch):
    out = shared_tmp(tmp_path)
    run_demo("hertz_cylinder.py", out, monkeypatch)
    MPI.COMM_WORLD.Barrier()
    summary = json.loads((out / "summary.json").read_text())
    assert summary["solver"]["mpi_ranks"] == MPI.COMM_WORLD.size
    assert all(abs(e) < 0.02 for e in summary["relative_error"].values())
    assert (out / "pressure.png").stat().st_size > 10_000


@pytest.mark.mpi
def test_hertz_ufl_demo(tmp_path, monkeypatch):
    """The plain-UFL demo matches Hertz and the library's own Hertz problem."""
    monkeypatch.setenv("CI", "1")  # the coarse mesh (h = 0.008 at the contact)
    out = shared_tmp(tmp_path)
    run_demo("demo_hertz_ufl.py", out, monkeypatch)
    MPI.COMM_WORLD.Barrier()
    summary = json.loads((out / "summary.json").read_text())
    assert summary["mpi_ranks"] == MPI.COMM_WORLD.size
    assert summary["mesh"]["h_contact"] == 0.008
    assert len(summary["iterations_per_step"]) == 4
    assert max(summary["iterations_per_step"]) <= 6
    assert all(abs(e) < 0.02 for e in summary["relative_error"].values())
    assert summary["measured"]["nodes_in_contact"] >= 15
    kkt = summary["signorini"]
    assert kkt["min_gap"] > -1e-12 and kkt["max_lam"] <= 0.0 and kkt["max_lam_gap"] < 1e-12
    assert (out / "pressure.png").stat().st_size > 10_000

    # The library builds the same problem: the same force and half-width come out.
    from benchmarks import cases
    from fenics_contact.references.measure import measure_hertz
    from fenics_contact.solvers import make_strategy
    from fenics_contact.solvers.diagnostics import SolverSettings
    from fenics_contact.solvers.stepping import solve_load_path

    cylinder = cases.hertz_cylinder(summary["mesh"]["h_contact"])
    problem = cases.build(cylinder, 1.0, relative=True, quadrature="nodal")
    strategy = make_strategy("gnrm", problem, SolverSettings(atol=1e-10, max_iterations=30))
    assert solve_load_path(strategy, 4).converged
    library = measure_hertz(problem, 1.0, cylinder.E, cylinder.nu)  # R = 1
    assert summary["P"] == pytest.approx(library.P, rel=1e-8)
    assert summary["measured"]["a"] == pytest.approx(library.fit.a, rel=1e-8)
    assert summary["measured"]["p0"] == pytest.approx(library.fit.p0, rel=1e-8)


@pytest.mark.mpi
def test_hertz_ufl_demo_reports_failed_newton(tmp_path, monkeypatch):
    """A load step that does not converge stops the demo with a message."""
    monkeypatch.setenv("CI", "1")
    monkeypatch.setattr(
        sys, "argv",
        ["demo_hertz_ufl.py", "--out", str(shared_tmp(tmp_path)), "--max-iterations", "1"],
    )
    with pytest.raises(RuntimeError, match=r"Load step 1 .* did not converge"):
        runpy.run_path(str(DEMOS / "demo_hertz_ufl.py"), run_name="__main__")


@pytest.mark.parametrize("name", sorted(p.name for p in DEMOS.glob("*.py")))
def test_demo_converts_to_notebook(name):
    """The literate demos are jupytext percent scripts: text cells and code cells."""
    jupytext = pytest.importorskip("jupytext")
    source = (DEMOS / name).read_text()
    notebook = jupytext.reads(source, fmt="py:percent")
    kinds = [cell.cell_type for cell in notebook.cells]
    assert kinds.count("markdown") >= 3 and kinds.count("code") >= 3
    code = "\n".join(c.source for c in notebook.cells if c.cell_type == "code")
    compile(code, name, "exec")  # the cells together are the script
    again = jupytext.reads(jupytext.writes(notebook, fmt="ipynb"), fmt="ipynb")
    assert [c.source for c in again.cells] == [c.source for c in notebook.cells]


def test_hertz_ufl_demo_shows_the_formulation():
    """The UFL demo writes the formulation on the page, not behind a library call."""
    jupytext = pytest.importorskip("jupytext")
    notebook = jupytext.reads((DEMOS / "demo_hertz_ufl.py").read_text(), fmt="py:percent")
    text = "\n".join(c.source for c in notebook.cells if c.cell_type == "markdown")
    code = "\n".join(c.source for c in notebook.cells if c.cell_type == "code")
    assert "This demo illustrates how to:" in text
    for snippet in [
        "mesh.create_submesh(",
        'functionspace(contact_mesh, ("Lagrange", 1))',
        "def psi_linear(F)",
        "ufl.min_value(lam + r * g, 0) ** 2 - lam**2",
        '"quadrature_rule": "vertex"',
        "ufl.MixedFunctionSpace(V, Q)",
        "ufl.derivative(L, u, v)",
        "ufl.extract_blocks(",
        "entity_maps=entity_maps",
        'kind="mpi"',
        "getConvergedReason()",
        "hertz_line_contact(",
    ]:
        assert snippet in code, snippet
