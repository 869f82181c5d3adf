"""The auto strategy: converges where plain GNRM fails, costs what GNRM costs where it works."""

import numpy as np
import pytest

from mpi4py import MPI

from benchmarks import cases
from fenics_contact.model.scaling import force_scale, residual_floor, scaled_atol
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.auto import AutoSettings, AutoStrategy
from fenics_contact.solvers.diagnostics import SolverSettings, Status
from fenics_contact.solvers.stepping import solve_load_path

BAR = cases.bar_on_cradle()


def solve(scene, method, r, quadrature="nodal", comm=MPI.COMM_WORLD, **settings):
    problem = cases.build(scene, r, relative=True, quadrature=quadrature, comm=comm)
    options = {"atol": scaled_atol(problem), "max_iterations": 60, **settings}
    strategy = make_strategy(method, problem, SolverSettings(**options))
    switches = []
    path = solve_load_path(
        strategy, scene.solver.steps, max_cutbacks=0,
        on_iteration=lambda _, result: switches.extend(result.switches),
    )
    return problem, path, switches


@pytest.fixture(scope="module")
def bar_reference():
    problem, path, _ = solve(BAR, "gnrm", 1.0)
    assert path.converged
    return problem.u.x.array.copy()


@pytest.mark.parametrize("r", [1e8, 1e12])
def test_auto_converges_on_the_bar_where_gnrm_diverges(r, bar_reference):
    _, gnrm, _ = solve(BAR, "gnrm", r)
    assert gnrm.status == Status.DIVERGED
    problem, path, switches = solve(BAR, "auto", r)
    assert path.converged
    assert problem.r_relative == pytest.approx(r)  # the user's r is restored
    assert any(s.startswith("rescale r") for s in switches)
    scale = np.abs(bar_reference).max()
    assert np.abs(problem.u.x.array - bar_reference).max() < 1e-9 * scale
    assert path.steps[-1].max_penetration < 1e-12


@pytest.mark.mpi
def test_auto_converges_on_hertz_at_r_1e10_where_gnrm_diverges():
    scene = cases.hertz_cylinder(0.02)
    _, gnrm, _ = solve(scene, "gnrm", 1e10)
    assert gnrm.status == Status.DIVERGED
    reference, _, _ = solve(scene, "gnrm", 1.0)
    problem, path, _ = solve(scene, "auto", 1e10)
    assert path.converged
    assert np.allclose(problem.lam.x.array, reference.lam.x.array, atol=1e-8 * scene.E)


def test_auto_costs_what_gnrm_costs_where_gnrm_works():
    """Inside the window (1e-2 ... 1 E/h) auto is GNRM; above it, GNRM at 1 E/h."""
    for r in (1e-2, 1.0):
        _, gnrm, _ = solve(BAR, "gnrm", r)
        _, auto, switches = solve(BAR, "auto", r)
        assert gnrm.converged and auto.converged
        assert auto.iterations == gnrm.iterations
        assert switches == []
    for r in (1e2, 1e6):
        _, gnrm, _ = solve(BAR, "gnrm", r)
        _, auto, _ = solve(BAR, "auto", r)
        assert gnrm.converged and auto.iterations <= 1.2 * gnrm.iterations


#: Two cylinders (node-to-segment, h = 0.01, 10 steps): auto's Newton iterations at any r
#: within 1.3 times those at r = 1 E/h (measured 30 at r <= 1, 35-37 above; plain GNRM at
#: 1e2 E/h cycles for 38 iterations in the fifth step: 89 in all).
def test_auto_at_any_r_costs_at_most_1_3_times_its_cost_at_r_1():
    scene = cases.two_cylinders(0.01, push=0.02, steps=10, h_far=0.1)
    counts, forces = {}, {}
    for r in (1e-8, 1.0, 1e2, 1e4, 1e12):
        problem, path, _ = solve(scene, "auto", r, atol=1e-8)
        assert path.converged, r
        counts[r] = path.iterations
        forces[r] = problem.contact_state().contact_force
    assert all(n <= 1.3 * counts[1.0] for n in counts.values()), counts
    assert all(abs(f - forces[1.0]) <= 1e-8 * forces[1.0] for f in forces.values()), forces


def test_a_failing_working_r_is_lowered_and_remembered():
    """GNRM cycling at the working r: auto retries lower before any line search, and the
    later steps start from the r that worked."""
    scene = cases.two_cylinders(0.01, push=0.02, steps=10, h_far=0.1)
    problem = cases.build(scene, 1e2)
    strategy = AutoStrategy(problem, SolverSettings(), tuning=AutoSettings(r_window=(1e-2, 1e2)))
    switches = []
    path = solve_load_path(strategy, 10, max_cutbacks=0,
                           on_iteration=lambda _, result: switches.extend(result.switches))
    assert path.converged
    lowered = [s for s in switches if "lower the working r" in s]
    assert len(lowered) == 1 and not any("line search" in s for s in switches)
    assert strategy.working_r() == pytest.approx(problem.stiffness_scale)


def test_line_search_stage_reaches_the_same_answer(bar_reference):
    problem = cases.build(BAR, 1.0, comm=MPI.COMM_WORLD)
    strategy = AutoStrategy(problem, SolverSettings(atol=scaled_atol(problem)))
    from fenics_contact.solvers.auto import _Tally

    for k in range(1, BAR.solver.steps + 1):
        problem.set_load(k / BAR.solver.steps)
        tally = _Tally()
        status = strategy._newton(strategy._stage_settings(problem.r_absolute), tally,
                                  line_search=True)
        assert status is Status.CONVERGED
    scale = np.abs(bar_reference).max()
    assert np.abs(problem.u.x.array - bar_reference).max() < 1e-9 * scale


def test_gauss_rule_climbs_to_the_users_r_by_continuation():
    problem = cases.build(BAR, 1e4, quadrature="gauss", comm=MPI.COMM_WORLD)
    rungs = AutoStrategy(problem, SolverSettings()).rungs()
    assert rungs[0] == pytest.approx(1e2 * problem.stiffness_scale)
    assert rungs[-1] == pytest.approx(problem.r_absolute) and len(rungs) == 2
    auto, path, switches = solve(BAR, "auto", 1e3, quadrature="gauss")
    assert path.converged and any(s.startswith("continuation") for s in switches)
    gnrm = cases.build(BAR, 1e3, quadrature="gauss", comm=MPI.COMM_WORLD)
    solve_load_path(make_strategy("gnrm", gnrm, SolverSettings(atol=scaled_atol(gnrm),
                                                                 max_iterations=60)),
                    BAR.solver.steps, max_cutbacks=4)
    scale = np.abs(gnrm.u.x.array).max()
    assert np.abs(auto.u.x.array - gnrm.u.x.array).max() < 1e-8 * scale


def test_stopping_test_never_demands_less_than_the_round_off_floor():
    """At r = 1e10 E/h plain GNRM stalls near eps r g_scale ||A||; with the floor in the
    tolerance (and no growth test) it stops there instead of running to the limit."""
    problem = cases.build(BAR, 1e10, comm=MPI.COMM_WORLD)
    floor = residual_floor(problem)
    assert scaled_atol(problem) == pytest.approx(floor)
    assert floor > 1e-8 and floor < 1e-3 * force_scale(problem)
    strict = make_strategy("gnrm", problem, SolverSettings(atol=1e-3 * floor, max_iterations=30,
                                                           divergence_factor=1e300))
    path = solve_load_path(strict, BAR.solver.steps, max_cutbacks=0)
    assert path.status == Status.MAX_ITERATIONS
    _, path, _ = solve(BAR, "gnrm", 1e10, divergence_factor=1e300)
    assert path.converged


def test_auto_reports_residual_progress_through_every_stage():
    """The observer hears every residual of every stage, with iterations counted over the solve."""
    problem = cases.build(BAR, 1e8, relative=True)
    heard = []
    strategy = make_strategy(
        "auto", problem, SolverSettings(atol=scaled_atol(problem), max_iterations=60),
        observer=lambda iterations, residual: heard.append((iterations, residual)),
    )
    problem.set_load(1.0 / BAR.solver.steps)
    result = strategy.solve()
    assert result.converged
    assert [r for _, r in heard] == result.residuals
    counts = [i for i, _ in heard]
    assert counts == sorted(counts) and counts[-1] == result.iterations


def test_auto_fallback_kernels_use_the_configured_linear_solver():
    from fenics_contact.solvers.linear import LinearSolverSettings

    problem = cases.build(BAR, 1.0, relative=True)
    iterative = LinearSolverSettings(kind="iterative")
    strategy = AutoStrategy(problem, SolverSettings(), linear=iterative)
    problem.set_load(1.0 / BAR.solver.steps)
    settings = SolverSettings(atol=scaled_atol(problem))
    from fenics_contact.solvers.auto import _Tally

    assert strategy._penalty_start(settings, _Tally())
    assert strategy.kernel.linear.kind == "iterative"
    assert strategy._penalty.linear.kind == "iterative"
    assert strategy._penalty.ksp.getType() == "gmres"


def test_auto_at_huge_r_under_the_scenes_predictor_gives_the_r_1_answer(tmp_path):
    """The active-set predictor imposes its set for the r auto works at, not the user's.

    At r = 1e12 E/h the set used to be imposed with lam = -r g at the user's
    r (1e15 here): multipliers of r g's round-off, a first residual of 1e12
    that the relative test (1e-10 of it) let pass after one iteration, and
    a Newton polish at the user's r. The two cylinders then read forces up
    to 2.6e-4 from the r = 1 E/h answer with supports 1.2e-8 out of
    balance; a user's grazing mortar pair was accepted with a contact force
    of 0 while its supports carried 0.8. Now each step is the r = 1 answer.
    """
    from pathlib import Path

    from fenics_contact.runner import run_scene
    from fenics_contact.scene.schema import load_scene
    from fenics_contact.scene.variants import with_contact_settings, with_solver

    scene = load_scene(Path(__file__).resolve().parents[1] / "scenes"
                       / "two_cylinders_node_to_segment.toml")
    reference = run_scene(scene, tmp_path / "r1", pictures=False).path.steps
    huge = with_solver(with_contact_settings(scene, r=1e12, relative=True), method="auto")
    steps = run_scene(huge, tmp_path / "huge", pictures=False).path.steps
    assert [s.status for s in steps] == ["converged"] * len(reference)
    for ours, ref in zip(steps, reference, strict=True):
        assert abs(ours.contact_force - ref.contact_force) <= 1e-8 * ref.contact_force
        assert max(abs(f) for f in ours.reaction_total) <= 1e-10


def test_auto_at_a_huge_r_on_a_stiff_soft_patch_test(tmp_path):
    """Blocks of E = 2e6 on E = 200 (matching meshes), r = 1e10 E/h: the working-r
    solves stalled at 1.2e-11 = 0.2 eps E h, the elastic rows' round-off, below atol but
    above auto's own target at the working r (which counted only the contact rows'
    round-off): 794 Newton iterations and a failure. Exact: 0.01 / (1/(2 E1*) + 1/(2 E2*))
    with E* = E / (1 - nu^2) over the width 1 (plane strain, uniaxial)."""
    from pathlib import Path

    from fenics_contact.runner import run_scene
    from fenics_contact.scene.schema import load_scene

    root = Path(__file__).resolve().parents[1]
    text = (root / "scenes" / "block_on_block_node_to_segment.toml").read_text()
    text = (text.replace('"../meshes/', f'"{root / "meshes"}/')
            .replace("n_lower = 11", "n_lower = 8").replace("E = 200.0", "E = 2.0e6", 1)
            .replace('target = "target_face"', 'target = "target_face"\nr = 1e10')
            .replace('method = "gnrm"', 'method = "auto"'))
    path = tmp_path / "stiff_soft.toml"
    path.write_text(text)
    outcome = run_scene(load_scene(path), tmp_path / "out", pictures=False)
    assert outcome.path.converged
    e1, e2 = 2.0e6 / (1 - 0.09), 200.0 / (1 - 0.09)
    exact = 0.01 / (0.5 / e1 + 0.5 / e2)
    assert outcome.path.steps[-1].contact_force == pytest.approx(exact, rel=1e-6)
    assert outcome.path.iterations <= 20
