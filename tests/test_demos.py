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


def run_ci_demo(name, tmp_path, monkeypatch):
    """Run a demo at its CI size into a folder every rank shares; its summary."""
    monkeypatch.setenv("CI", "1")
    out = shared_tmp(tmp_path)
    run_demo(name, out, monkeypatch)
    MPI.COMM_WORLD.Barrier()
    return out, json.loads((out / "summary.json").read_text())


@pytest.mark.mpi
def test_paper_comparison_demo_gives_the_paper_table(tmp_path, monkeypatch):
    """PM converges to a penalised answer, SUA fails, NUA needs many solves, GNRM 40-42."""
    out, summary = run_ci_demo("paper_comparison.py", tmp_path, monkeypatch)
    runs = {(run["method"], run["r"]): run for run in summary["runs"]}
    assert summary["r_values"] == [1.0, 100.0, 10000.0]
    assert [runs[("gnrm", r)]["iterations"] for r in (1.0, 100.0, 10000.0)] == [40, 40, 42]
    assert all(runs[("gnrm", r)]["error"] < 1e-12 for r in (1.0, 100.0, 10000.0))
    # the penalty error falls with r but never to round-off
    errors = [runs[("penalty", r)]["error"] for r in (1.0, 100.0, 10000.0)]
    assert errors[0] > errors[1] > errors[2] > 1e-4
    assert all(runs[("sua", r)]["status"] != "converged" for r in (1.0, 100.0, 10000.0))
    assert runs[("nua", 100.0)]["status"] == "converged"
    assert runs[("nua", 100.0)]["iterations"] > 5 * runs[("gnrm", 100.0)]["iterations"]
    assert runs[("nua", 10000.0)]["error"] < 1e-10
    assert "| GNRM | 40 | 40 | 42 |" in (out / "table.md").read_text()
    assert (out / "residuals.png").stat().st_size > 10_000


@pytest.mark.mpi
def test_two_cylinders_demo_follows_hertz_with_both_pairs(tmp_path, monkeypatch):
    out, summary = run_ci_demo("two_cylinders.py", tmp_path, monkeypatch)
    assert summary["mpi_ranks"] == MPI.COMM_WORLD.size
    nts, mortar = summary["runs"]["node-to-segment"], summary["runs"]["mortar"]
    for run in (nts, mortar):
        assert run["h_contact"] == 0.005
        assert len(run["iterations_per_step"]) == 10 and max(run["iterations_per_step"]) <= 6
        assert abs(run["p0_error"]) < 0.01  # the fitted peak against Hertz
        kkt = run["signorini"]
        assert kkt["max_pressure"] <= 0.0 and kkt["max_complementarity"] < 1e-8
    assert abs(nts["a_error"]) < 0.01 and abs(mortar["a_error"]) < 0.03
    # on non-matching arcs mortar's largest nodal pressure is the closer one
    assert abs(mortar["p0_nodal_error"]) < 0.01 < abs(nts["p0_nodal_error"]) < 0.04
    assert mortar["P"] == pytest.approx(nts["P"], rel=2e-3)
    assert (out / "pressure.png").stat().st_size > 10_000


@pytest.mark.mpi
def test_cattaneo_mindlin_demo_stick_zone_matches_theory(tmp_path, monkeypatch):
    out, summary = run_ci_demo("cattaneo_mindlin.py", tmp_path, monkeypatch)
    assert summary["mesh"]["h_contact"] == 0.005 and summary["mu"] == 0.3
    assert max(summary["iterations_per_step"]) <= 10
    zones = summary["zones"]
    assert len(zones) == 9
    ratios = [z["load_ratio"] for z in zones]
    assert ratios == sorted(ratios) and 0.85 < ratios[-1] < 0.9
    for z in zones:  # the stick edge to within its node spacing
        assert abs(z["c_error"]) <= z["c_resolution"] + 0.005
    assert [z["stick_nodes"] for z in zones] == sorted(
        (z["stick_nodes"] for z in zones), reverse=True)
    assert max(z["traction_error"] for z in zones[3:]) < 0.08
    assert (out / "stick_zone.png").stat().st_size > 10_000


def test_speed_accuracy_demo_marks_gnrm_exact_and_penalty_approximate(tmp_path, monkeypatch):
    out, summary = run_ci_demo("speed_accuracy.py", tmp_path, monkeypatch)
    rows = summary["records"]
    assert {row["mesh"] for row in rows} == {"h=0.02", "h=0.01"}
    for row in rows:
        if row["method"] in ("gnrm", "auto"):
            assert row["status"] == "converged" and row["u_error"] < 1e-12
    for mesh in ("h=0.02", "h=0.01"):
        gnrm = [row for row in rows if row["mesh"] == mesh and row["method"] == "gnrm"]
        assert len({row["iterations"] for row in gnrm}) == 1  # the same at every r
        penalty = sorted((row for row in rows if row["mesh"] == mesh
                          and row["method"] == "penalty"), key=lambda row: row["r_relative"])
        assert [row["u_error"] for row in penalty] == sorted(
            (row["u_error"] for row in penalty), reverse=True)
        assert penalty[-1]["u_error"] > 1e-8
    assert any(row["pareto_u"] and row["method"] in ("gnrm", "auto") for row in rows)
    assert (out / "pareto.png").stat().st_size > 10_000


@pytest.mark.mpi
def test_block_3d_demo_iterative_solver_equals_direct(tmp_path, monkeypatch):
    out, summary = run_ci_demo("block_3d_iterative.py", tmp_path, monkeypatch)
    assert summary["mpi_ranks"] == MPI.COMM_WORLD.size
    direct, iterative = summary["runs"]["direct"], summary["runs"]["iterative"]
    assert iterative["iterations_per_step"] == direct["iterations_per_step"]
    assert max(direct["iterations_per_step"]) <= 5
    assert summary["force_difference"] < 1e-10
    assert iterative["active_nodes"] == direct["active_nodes"] > 0
    kkt = iterative["signorini"]
    assert kkt["min_gap"] > -1e-10 and kkt["max_pressure"] <= 0.0
    assert kkt["max_complementarity"] < 1e-10
    assert (out / "residuals.png").stat().st_size > 10_000
