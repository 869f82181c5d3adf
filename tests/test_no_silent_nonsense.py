"""No silent nonsense: inverted elements refuse a step, convergence means Signorini holds."""

import json
import re

import numpy as np
import pytest
from dolfinx import mesh

from mpi4py import MPI

from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.materials import material
from fenics_contact.model.obstacles import RigidPlane
from fenics_contact.model.problem import (
    ContactProblem,
    PrescribedDisplacement,
    one_body_problem,
)
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.base import SolveResult
from fenics_contact.solvers.diagnostics import (
    STATUSES,
    ConvergenceMonitor,
    SolverSettings,
    Status,
)
from fenics_contact.solvers.stepping import solve_load_path


def square_problem(cell=mesh.CellType.triangle) -> ContactProblem:
    """Unit square of SVK, bottom on the plane y = 0, left side held."""
    domain = mesh.create_unit_square(MPI.COMM_WORLD, 4, 4, cell)
    fdim = 1
    bottom = mesh.locate_entities_boundary(domain, fdim, lambda x: np.isclose(x[1], 0.0))
    left = mesh.locate_entities_boundary(domain, fdim, lambda x: np.isclose(x[0], 0.0))
    return one_body_problem(
        domain, material("svk", 210.0, 0.3), RigidPlane(domain, (0.0, 0.0), (0.0, 1.0)),
        bottom, ContactSettings(r=1.0), prescribed=[PrescribedDisplacement(left, (0.0, 0.0))],
    )


@pytest.mark.mpi
@pytest.mark.parametrize("cell", [mesh.CellType.triangle, mesh.CellType.quadrilateral])
def test_min_det_F_value_and_place(cell):
    problem = square_problem(cell)
    assert problem.min_det_F().value == pytest.approx(1.0, abs=1e-14)
    # u = (0, -a y): F = diag(1, 1 - a), det F = 1 - a everywhere
    problem.u.interpolate(lambda x: np.vstack([0 * x[0], -0.4 * x[1]]))
    assert problem.min_det_F().value == pytest.approx(0.6, rel=1e-12)
    # u = (0, -2 x y): det F = 1 - 2 x, inverted for x > 1/2, worst in the last column
    problem.u.interpolate(lambda x: np.vstack([0 * x[0], -2.0 * x[0] * x[1]]))
    worst = problem.min_det_F()
    assert worst.value < -0.5
    assert worst.where[0] > 0.75


class Squash:
    """A fake strategy whose 'converged' state is u_y = -2.5 t y: det F = 1 - 2.5 t."""

    name = "squash"

    def __init__(self, problem: ContactProblem) -> None:
        self.problem = problem
        self.settings = SolverSettings()

    def solve(self) -> SolveResult:
        t = self.problem.load_factor
        self.problem.u.interpolate(lambda x: np.vstack([0 * x[0], -2.5 * t * x[1]]))
        return SolveResult(Status.CONVERGED, 1, 0, 1, [1.0, 0.0])


@pytest.mark.mpi
def test_inverted_step_is_cut_back_then_refused_with_its_place():
    problem = square_problem()
    written = []
    path = solve_load_path(Squash(problem), 4, max_cutbacks=3, on_step=written.append)
    assert path.status == Status.INVERTED == "inverted"
    # step 1 (t = 0.25, det 0.375) is accepted; step 2 never passes t = 0.4 (det F = 0)
    assert [s.status for s in path.steps] == ["converged", "inverted"]
    assert path.steps[0].min_det_F == pytest.approx(0.375, rel=1e-12)
    assert [s.step for s in written] == [1]
    failed = path.steps[1]
    assert 0.375 <= failed.load_factor < 0.4  # cut back below the inverting load
    assert failed.cutbacks == 3  # halvings; the fourth attempt failed too
    assert failed.min_det_F <= 0.0
    assert "after 4 attempts, the increment halved 3 times" in failed.message
    assert "inverted: elements turned inside out (det F = " in failed.message
    assert "near (" in failed.message and "reduce the load" in failed.message
    assert np.all(np.isfinite(failed.worst_cell))
    # the state left behind is the last accepted one
    assert problem.min_det_F().value > 0.0


def test_statuses_are_documented():
    assert set(STATUSES) == {
        "converged", "cycling", "diverged", "max_iterations", "inverted", "held_by_springs",
        "error",
    }


def test_monitor_refuses_convergence_while_signorini_fails():
    reasons = iter(["penetration 1e-3 > gap_tol * h", None])
    monitor = ConvergenceMonitor(SolverSettings(atol=1e-8), admissible=lambda: next(reasons))
    assert monitor.check(1.0) is None
    assert monitor.check(1e-10) is None  # small residual, but the gap is open
    assert monitor.refused.startswith("penetration")
    assert monitor.check(1e-12) is Status.CONVERGED
    stuck = ConvergenceMonitor(
        SolverSettings(atol=1e-8, max_iterations=3), admissible=lambda: "tension"
    )
    statuses = [stuck.check(1e-10, state=i, iterations=i) for i in range(4)]
    assert statuses[-1] is Status.MAX_ITERATIONS


def test_tolerances_must_be_positive():
    with pytest.raises(ValueError, match="gap_tol and tension_tol must be > 0"):
        SolverSettings(gap_tol=0.0)


@pytest.mark.mpi
def test_tiny_r_gnrm_does_not_report_convergence_with_a_gap():
    """GNRM at r = 1e-8 E/h on the Hertz mesh: the residual r g hides a 12 % h gap.

    With the Signorini test in its own units the solve keeps iterating to the
    r-independent answer (the nodal rule gives the same discrete solution for
    every r); with that test disabled (gap_tol = 1) it stops at a gap of
    7.6e-4, which is what "converged" used to mean.
    """
    from benchmarks import cases

    cylinder = cases.hertz_cylinder()
    results = {}
    for gap_tol in (1e-6, 1.0):
        problem = cases.build(cylinder, 1e-8, relative=True)
        strategy = make_strategy("gnrm", problem, SolverSettings(rtol=1e-10, gap_tol=gap_tol))
        path = solve_load_path(strategy, 2)
        results[gap_tol] = (path.status, problem.contact_state(), problem.surface.h)
    status, state, h = results[1e-6]
    assert status == "converged"
    assert state.max_penetration <= 1e-6 * h
    assert state.contact_force == pytest.approx(1.0643006790, rel=1e-8)  # the r = 1 answer
    old_status, old_state, _ = results[1.0]
    assert old_status == "converged"
    assert old_state.max_penetration > 0.1 * h  # the hidden gap the test now refuses


def test_min_det_F_is_in_summary(tmp_path):
    from fenics_contact.cli import main

    scene = tmp_path / "s.toml"
    scene.write_text(
        '[scene]\nname = "s"\ndimension = 2\n[mesh]\ngenerator = "rectangle"\n'
        "size = [1.0, 0.5]\ncells = [4, 2]\n[material]\nlaw = \"svk\"\nE = 210.0\nnu = 0.3\n"
        '[[dirichlet]]\ntag = "top"\nvalue = [0.0, -0.05]\n[obstacle]\ntype = "plane"\n'
        'point = [0.0, 0.0]\nnormal = [0.0, 1.0]\n[contact]\ntag = "bottom"\n[solver]\n'
        "steps = 2\n[output]\npictures = false\n"
    )
    assert main(["run", str(scene), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    steps = json.loads((tmp_path / "out" / "summary.json").read_text())["steps"]
    dets = [s["min_det_F"] for s in steps]
    assert 0.8 < dets[1] < dets[0] < 1.0  # compressed by 10 %, more at the second step


def test_cli_run_that_would_invert_elements_stops_and_says_where(tmp_path, capsys):
    """Small-strain law, top pushed down by 1.2 heights: converges to inverted cells."""
    from fenics_contact.cli import main

    scene = tmp_path / "inv.toml"
    scene.write_text(
        '[scene]\nname = "inv"\ndimension = 2\n[mesh]\ngenerator = "rectangle"\n'
        "size = [1.0, 0.5]\ncells = [4, 2]\n[material]\nlaw = \"linear\"\nE = 210.0\n"
        'nu = 0.3\n[[dirichlet]]\ntag = "top"\nvalue = ["free", -0.6]\n[[dirichlet]]\n'
        'tag = "left"\nvalue = [0.0, "free"]\n[obstacle]\ntype = "plane"\n'
        'point = [0.0, 0.0]\nnormal = [0.0, 1.0]\n[contact]\ntag = "bottom"\n[solver]\n'
        "steps = 4\n[output]\npictures = false\n"
    )
    out = tmp_path / "out"
    assert main(["run", str(scene), "--out", str(out), "--quiet"]) == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "load step 4 of 4 did not converge (inverted" in err
    assert re.search(r"det F = -?[0-9.e-]+ <= 0\) near \([0-9.]+, [0-9.]+, 0\)", err), err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "inverted" and summary["steps_completed"] == 3
    steps = summary["steps"]
    # uniform compression: det F = (1 + nu/(1-nu) e)(1 - e) with e = 0.3 ... 0.9 per step
    for step, e in zip(steps[:3], (0.3, 0.6, 0.9), strict=True):
        assert step["min_det_F"] == pytest.approx((1 + 0.3 / 0.7 * e) * (1 - e), rel=1e-6)
    assert steps[3]["min_det_F"] <= 0.0


@pytest.mark.mpi
def test_signorini_test_names_penetration_and_tension_in_their_units():
    from fenics_contact.solvers.diagnostics import signorini_admissibility

    problem = square_problem()  # h = 0.25, E = 210
    check = signorini_admissibility(problem, SolverSettings(gap_tol=1e-6, tension_tol=1e-6))
    assert check() is None
    problem.u.interpolate(lambda x: np.vstack([0 * x[0], -1e-6 + 0 * x[1]]))  # 4e-6 h inside
    assert check().startswith("penetration 1e-06 > gap_tol * h = 1e-06 * 0.25")
    problem.u.interpolate(lambda x: np.vstack([0 * x[0], -1e-8 + 0 * x[1]]))  # 4e-8 h: fine
    assert check() is None
    problem.lam.x.array[:] = 1e-3  # tension 1e-3 > 1e-6 * 210
    assert check().startswith("tension 0.001 > tension_tol * E = 1e-06 * 210")
    problem.lam.x.array[:] = 1e-4  # below 2.1e-4
    assert check() is None
    gauss = one_body_problem(
        problem.domain, problem.material, problem.obstacle, problem.surface.facets,
        ContactSettings(r=1.0, quadrature="gauss"),
    )
    assert signorini_admissibility(gauss, SolverSettings()) is None


def test_prescribed_displacements_must_hold_at_convergence():
    """Two cylinders at r = 1e12 E/h: the round-off floor of the stopping test (0.4 of a
    contact force 0.6) let penalty and GNRM stop before the first Newton step of every
    load step, with the push not applied (u = 0, "converged", 0 iterations).

    The Dirichlet rows hold x - x_D (length), so the residual norm alone cannot tell.
    """
    from benchmarks import cases
    from fenics_contact.solvers.diagnostics import prescribed_admissibility
    from fenics_contact.sweeps.stability import StabilityCase, run_case

    push = 0.02
    scene = cases.two_cylinders(push=push)
    problem = cases.build(scene, 1.0)
    check = prescribed_admissibility(problem, SolverSettings())
    assert check() is None and problem.prescribed_mismatch() == 0.0
    problem.set_load(0.5)  # push 0.02: the top is 0.01 from its prescribed value
    assert problem.prescribed_mismatch() == pytest.approx(0.01, rel=1e-12)
    assert check().startswith("prescribed displacement mismatch 0.01 > gap_tol * h")
    run = solve_load_path(make_strategy("gnrm", problem, SolverSettings(atol=1e-8)), 1)
    assert run.converged and problem.prescribed_mismatch() < 1e-15 and check() is None

    case = StabilityCase("two-cyl-r1e12", "two-body-r", scene, 1e12)
    for method in ("penalty", "gnrm"):
        record = run_case(case, method)
        # measured: diverged at the first iteration of step 1 (formerly converged, 0 iterations)
        assert record.status != "converged" and record.iterations >= 1, (method, record.status)
    auto = run_case(case, "auto")
    assert auto.converged and auto.max_abs_u == pytest.approx(push, rel=1e-12)
