"""Each strategy against GNRM and the exact answer; real cycling and divergence."""

import json
from pathlib import Path

import numpy as np
import pytest
from dolfinx import mesh

from mpi4py import MPI

from benchmarks.cases import bar_on_cradle, build, wedge_on_corner
from benchmarks.research.paper_ex1 import corner_displacement
from fenics_contact.cli import main
from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.materials import SaintVenantKirchhoff
from fenics_contact.model.obstacles import RigidPlane
from fenics_contact.model.problem import SurfaceTraction, one_body_problem
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings, Status
from fenics_contact.solvers.stepping import solve_load_path

EX1 = wedge_on_corner()
EXACT_U = -0.5  # the wedge's slope 2 times its slide -0.25
EX2 = bar_on_cradle()
SCENES = Path(__file__).resolve().parents[1] / "scenes"


def corner_u(method, r, max_iterations=500):
    problem = build(EX1, r, relative=False)
    strategy = make_strategy(method, problem, SolverSettings(max_iterations=max_iterations))
    path = solve_load_path(strategy, EX1.solver.steps, max_cutbacks=0)
    return path, corner_displacement(problem)


@pytest.mark.parametrize("method", ["gnrm", "sua", "nua"])
def test_augmented_lagrangian_strategies_hit_the_exact_answer(method):
    path, u = corner_u(method, 1000.0)
    assert path.converged
    assert u == pytest.approx(EXACT_U, abs=1e-9)


def test_gnrm_takes_two_iterations_whatever_r():
    for r in (1.0, 10.0, 100.0, 1000.0, 1e4):
        path, _ = corner_u("gnrm", r)
        assert path.converged and path.iterations == 2


def test_penalty_error_falls_like_one_over_r_on_example_1():
    errors = [abs(corner_u("penalty", r)[1] - EXACT_U) for r in (1e4, 1e5, 1e6)]
    for k in range(2):
        assert errors[k] / errors[k + 1] == pytest.approx(10.0, rel=0.2)


@pytest.mark.parametrize(("method", "r"), [("nua", 1000.0), ("penalty", 1e5)])
def test_example_2_strategies_agree_with_gnrm(method, r):
    reference = build(EX2, r, relative=False)
    solve_load_path(make_strategy("gnrm", reference, SolverSettings()), EX2.solver.steps)
    problem = build(EX2, r, relative=False)
    path = solve_load_path(
        make_strategy(method, problem, SolverSettings(max_iterations=500)), EX2.solver.steps,
        max_cutbacks=0,
    )
    assert path.converged
    diff = np.abs(problem.u.x.array - reference.u.x.array).max()
    # NUA is exact to the tolerance; penalty is off by about pressure / r
    tolerance = 1e-8 if method == "nua" else 50.0 / r
    assert diff < tolerance


def test_simultaneous_uzawa_cycles_on_example_2_at_large_r():
    problem = build(EX2, 1000.0, relative=False)
    strategy = make_strategy("sua", problem, SolverSettings(max_iterations=500))
    result = solve_load_path(strategy, EX2.solver.steps, max_cutbacks=0)
    assert result.status == Status.CYCLING
    assert result.steps[0].iterations < 50


def test_singular_system_is_reported_as_divergence_not_an_exception():
    """A traction, no Dirichlet condition and no contact: the stiffness is singular."""
    domain = mesh.create_unit_square(MPI.COMM_WORLD, 2, 2)
    fdim = 1
    bottom = mesh.locate_entities_boundary(domain, fdim, lambda x: np.isclose(x[1], 0.0))
    plane = RigidPlane(domain, [0.0, -1.0], [0.0, 1.0])
    top = mesh.locate_entities_boundary(domain, fdim, lambda x: np.isclose(x[1], 1.0))
    problem = one_body_problem(
        domain, SaintVenantKirchhoff(210.0, 0.3), plane, bottom, ContactSettings(),
        tractions=[SurfaceTraction(top, (1.0, 0.0))],
    )
    path = solve_load_path(make_strategy("gnrm", problem, SolverSettings()), 1, max_cutbacks=1)
    assert path.status == Status.DIVERGED
    assert np.all(np.isfinite(problem.u.x.array))


def test_study_command_writes_the_table_json_csv_and_plots(tmp_path, capsys):
    code = main(
        ["study", str(SCENES / "paper_ex1.toml"), "--methods", "penalty,gnrm", "--r", "10,1000",
         "--out",
         str(tmp_path)]
    )
    assert code == 0
    printed = capsys.readouterr().out
    assert "| GNRM | 2 | 2 |" in printed
    records = json.loads((tmp_path / "study.json").read_text())
    assert len(records) == 4
    keys = {"method", "r", "status", "iterations", "updates", "wall_s", "max_penetration", "error"}
    assert all(keys <= set(rec) for rec in records)
    gnrm = [rec for rec in records if rec["method"] == "gnrm"]
    assert all(rec["error"] < 1e-12 for rec in gnrm)
    header = (tmp_path / "study.csv").read_text().splitlines()[0].split(",")
    assert keys <= set(header)
    for png in ("residuals.png", "iterations.png"):
        assert (tmp_path / png).stat().st_size > 10_000


def test_study_command_rejects_bad_r_before_any_work(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["study", str(SCENES / "paper_ex1.toml"), "--r", "10,-1"])
    assert exc.value.code == 2
    assert "every r must be > 0" in capsys.readouterr().err
