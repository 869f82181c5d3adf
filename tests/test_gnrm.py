"""GNRM on the Example 2 analog: Signorini conditions, r-independence, convergence rate."""

import itertools
import math

import numpy as np
import pytest

from mpi4py import MPI

from benchmarks import cases
from benchmarks.cases import PAPER_E
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings, signorini_report
from fenics_contact.solvers.stepping import solve_load_path

EXAMPLE = cases.bar_on_cradle()
#: The cradle's radius and the bar's length (bar_on_cradle's defaults).
RADIUS, LENGTH = 10.0, 6.0


def solve(method="gnrm", r=1.0, relative=True, comm=MPI.COMM_WORLD, cutbacks=0, **kw):
    problem = cases.build(EXAMPLE, r, relative, comm=comm, **kw)
    strategy = make_strategy(method, problem, SolverSettings(atol=1e-8, max_iterations=60))
    path = solve_load_path(strategy, EXAMPLE.solver.steps, max_cutbacks=cutbacks)
    return problem, path


def test_signorini_conditions_hold_at_every_converged_step():
    reports, patterns = [], []

    def check(step):
        state = problem.contact_state()
        reports.append(signorini_report(state.gap, state.multiplier, problem.comm))
        patterns.append(state.active_count)

    problem = cases.build(EXAMPLE, 1.0, comm=MPI.COMM_WORLD)
    strategy = make_strategy("gnrm", problem, SolverSettings(atol=1e-10))
    path = solve_load_path(strategy, EXAMPLE.solver.steps, max_cutbacks=0, on_step=check)
    assert path.converged
    scale = RADIUS
    for rep in reports:
        assert rep.min_gap >= -1e-10 * scale
        assert rep.max_pressure <= 1e-10 * PAPER_E
        assert rep.max_complementarity <= 1e-10 * PAPER_E * scale
    # the contact pattern changes: ends only, then all seven nodes, then the ends lift off
    assert patterns[0] == 2 and max(patterns) == 7 and patterns[-1] == 5


def test_ends_lift_off_while_the_centre_stays_closed():
    problem, path = solve()
    assert path.converged
    state = problem.contact_state()
    x = problem.nodal_coordinates()[:, 0]
    ends = np.isclose(np.abs(x), LENGTH / 2)
    assert np.all(state.gap[ends] > 0.05)
    assert np.all(state.active[~ends])


def test_gnrm_displacement_does_not_depend_on_r():
    """Nodal variant: complementarity holds exactly at the nodes, whatever r."""
    solutions = []
    for r in (1.0, 100.0, 1e4):
        problem, path = solve(r=r)
        assert path.converged, (r, path.status)
        solutions.append(problem.u.x.array.copy())
    scale = np.abs(solutions[0]).max()
    for other in solutions[1:]:
        assert np.abs(other - solutions[0]).max() <= 1e-8 * scale


def test_integral_variant_settles_as_r_grows():
    """Gauss variant: min(lam + r g, 0) at Gauss points is not P1, so the discrete
    solution depends on r; it must settle toward a limit as r grows."""
    solutions = []
    for r in (1.0, 10.0, 100.0, 1000.0):
        problem, path = solve(r=r, quadrature="gauss", cutbacks=2)
        assert path.converged, (r, path.status)
        solutions.append(problem.u.x.array.copy())
    steps = [np.abs(b - a).max() for a, b in itertools.pairwise(solutions)]
    assert steps[0] > steps[1] > steps[2]


def test_gnrm_converges_superlinearly():
    _, path = solve(r=1.0)
    orders = []
    for step in path.steps:
        history = [v for v in step.residuals[-1] if v > 1e-12]
        if len(history) >= 3:
            a, b, c = history[-3:]
            orders.append(math.log(c / b) / math.log(b / a))
    assert len(orders) >= 8
    assert min(orders) > 1.5  # quadratic: close to 2


def test_penalty_approaches_the_augmented_lagrangian_solution_like_one_over_r():
    reference, _ = solve("gnrm")
    u_ref = reference.u.x.array.copy()
    penetrations, errors = [], []
    for r in (1e2, 1e3, 1e4):
        problem, path = solve("penalty", r=r)
        assert path.converged
        penetrations.append(path.steps[-1].max_penetration)
        errors.append(np.abs(problem.u.x.array - u_ref).max())
    for k in range(2):
        assert penetrations[k] / penetrations[k + 1] == pytest.approx(10.0, rel=0.15)
        assert errors[k] / errors[k + 1] == pytest.approx(10.0, rel=0.25)


@pytest.mark.mpi
def test_parallel_run_matches_serial_iterations_and_results():
    """Run on COMM_WORLD (2 ranks under `make test`) and on COMM_SELF; compare."""
    results = {}
    for name, comm in (("world", MPI.COMM_WORLD), ("self", MPI.COMM_SELF)):
        problem, path = solve(r=10.0, comm=comm)
        assert path.converged
        state = problem.contact_state()
        order = np.lexsort(problem.nodal_coordinates()[:, :2].T[::-1])
        gathered = comm.allgather((problem.nodal_coordinates()[order], state.pressure[order]))
        coords = np.concatenate([g[0] for g in gathered])
        pressure = np.concatenate([g[1] for g in gathered])
        key = np.lexsort(coords[:, :2].T[::-1])
        results[name] = (
            [s.iterations for s in path.steps],
            [s.active_count for s in path.steps],
            state.contact_force,
            pressure[key],
        )
    world, serial = results["world"], results["self"]
    assert world[0] == serial[0]
    assert world[1] == serial[1]
    assert world[2] == pytest.approx(serial[2], rel=1e-10)
    assert np.allclose(world[3], serial[3], rtol=1e-10, atol=1e-10 * PAPER_E)
