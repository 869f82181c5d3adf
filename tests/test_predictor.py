"""The extrapolating load-step predictor and the 2D Hertz Newton-count target.

Issue 6 case: half-cylinder R = 1, E = 200, nu = 0.3, small strain, top moved
down 0.02 in 10 steps, h = 0.008 at contact (3814 displacement DOFs), GNRM
nodal. Target: <= 23 Newton iterations in total, the same for every r from
1e-2 to 1e6 (relative to E/h). Measured: 19 (4 3 2 2 2 1 1 1 1 2) with the
predictor, 25 without.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import fenics_contact  # noqa: F401  (before dolfinx)
from benchmarks import cases
from fenics_contact.scene.variants import with_mesh_parameters
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.predictor import ActiveSetPredicted, Extrapolated
from fenics_contact.solvers.stepping import solve_load_path

CYLINDER = cases.hertz_cylinder(0.008, push=0.02, fine_radius=0.22)


def hertz_path(r: float, predictor: bool) -> tuple:
    problem = cases.build(CYLINDER, r, relative=True, quadrature="nodal")
    strategy = make_strategy("gnrm", problem, SolverSettings(atol=1e-8))
    if predictor:
        strategy = Extrapolated(strategy)
    return problem, solve_load_path(strategy, 10)


def test_hertz_2d_newton_target_for_every_r() -> None:
    counts = {}
    for r in (1e-2, 1.0, 1e2, 1e6):
        problem, path = hertz_path(r, predictor=True)
        assert path.converged, (r, path.status)
        assert problem.V.dofmap.index_map.size_global * 2 == pytest.approx(3800, rel=0.05)
        counts[r] = [s.iterations for s in path.steps]
    totals = {r: sum(c) for r, c in counts.items()}
    assert max(totals.values()) <= 23, totals
    assert len({tuple(c) for c in counts.values()}) == 1, counts


def test_predictor_changes_the_work_not_the_answer() -> None:
    plain, path_plain = hertz_path(1.0, predictor=False)
    predicted, path_predicted = hertz_path(1.0, predictor=True)
    assert path_predicted.iterations < path_plain.iterations
    scale = np.abs(plain.u.x.array).max()
    assert np.abs(predicted.u.x.array - plain.u.x.array).max() < 1e-9 * scale
    assert [s.active_count for s in path_plain.steps] == [
        s.active_count for s in path_predicted.steps
    ]


def test_predictor_survives_cutbacks_and_outside_changes() -> None:
    scene = cases.bar_on_cradle()
    reference = cases.build(scene, 1.0)
    solve_load_path(make_strategy("gnrm", reference, SolverSettings()), scene.solver.steps)
    problem = cases.build(scene, 1.0)
    strategy = Extrapolated(make_strategy("gnrm", problem, SolverSettings(max_iterations=5)))
    path = solve_load_path(strategy, 1, max_cutbacks=6)
    assert path.converged and path.steps[0].cutbacks >= 1
    scale = np.abs(reference.u.x.array).max()
    assert np.abs(problem.u.x.array - reference.u.x.array).max() < 1e-8 * scale
    # fields changed behind the predictor's back: it forgets its history
    problem.u.x.array[:] = 0.0
    assert not strategy.predict()


# -- the active-set predictor (issue 21) ----------------------------------------------
# Measured (10 steps, GNRM nodal, r = 1 E/h): medium mesh 19 -> 18 Newton iterations
# (4 2 1 1 1 2 2 2 2 1), fine mesh (h = 0.004) 29 -> 18 (6 2 1 1 1 1 1 1 2 2); two cylinders
# (node-to-segment) step 1 5 -> 4, 27 iterations in total either way.

FINE = cases.hertz_cylinder(0.004, push=0.02, fine_radius=0.22)


def predicted_path(scene, r: float, predictor: str) -> tuple:
    problem = cases.build(scene, r, relative=True, quadrature="nodal")
    strategy = make_strategy("gnrm", problem, SolverSettings(atol=1e-8), predictor=predictor)
    return problem, solve_load_path(strategy, 10)


def test_active_set_predictor_on_the_fine_hertz_mesh() -> None:
    extrapolated, path_e = predicted_path(FINE, 1.0, "extrapolate")
    predicted, path_p = predicted_path(FINE, 1.0, "active-set")
    assert path_e.converged and path_p.converged
    assert path_e.iterations == 29, [s.iterations for s in path_e.steps]
    assert path_p.iterations <= 18, [s.iterations for s in path_p.steps]
    # steps 3-8: the predicted set is the converged one (one Newton iteration each)
    assert [s.iterations for s in path_p.steps[2:8]] == [1] * 6
    scale = np.abs(extrapolated.u.x.array).max()
    assert np.abs(predicted.u.x.array - extrapolated.u.x.array).max() < 1e-9 * scale
    assert [s.active_count for s in path_e.steps] == [s.active_count for s in path_p.steps]


def test_active_set_predictor_medium_mesh_for_every_r() -> None:
    counts = {}
    for r in (1e-2, 1.0, 1e6):
        _, path = predicted_path(CYLINDER, r, "active-set")
        assert path.converged, (r, path.status)
        counts[r] = [s.iterations for s in path.steps]
    assert len({tuple(c) for c in counts.values()}) == 1, counts
    assert sum(counts[1.0]) <= 18, counts


def test_active_set_predictor_first_step_of_two_cylinders() -> None:
    """Touching nodes start in contact: step 1 takes 4 iterations (5 from an empty set)."""
    from fenics_contact.scene.build import build_problem
    from fenics_contact.scene.schema import load_scene

    scene = with_mesh_parameters(load_scene(Path(__file__).parent.parent / "scenes"
                                            / "two_cylinders_node_to_segment.toml"),
                                 h_contact=0.01)  # issue 21's case
    runs = {}
    for predictor in ("extrapolate", "active-set"):
        problem = build_problem(scene)
        strategy = make_strategy("gnrm", problem, scene.solver, predictor=predictor)
        path = solve_load_path(strategy, scene.solver.steps)
        assert path.converged
        runs[predictor] = (problem, path)
    (plain, path_e), (predicted, path_p) = runs["extrapolate"], runs["active-set"]
    assert path_e.steps[0].iterations == 5
    assert path_p.steps[0].iterations <= 4
    assert path_p.iterations <= 27, [s.iterations for s in path_p.steps]
    scale = np.abs(plain.u.x.array).max()
    assert np.abs(predicted.u.x.array - plain.u.x.array).max() < 1e-8 * scale


def test_active_set_predictor_first_step_of_two_cylinders_on_mortar() -> None:
    """The touching node's weighted gap is 1e-3 h, not 0: it still starts in contact.

    Measured (the mortar scene at h = 0.01, 10 steps): step 1 6 -> 4 iterations,
    26 in all against node-to-segment's 27 with the same predictor (29 with
    the extrapolation alone).
    """
    from fenics_contact.scene.build import build_problem
    from fenics_contact.scene.schema import load_scene

    scene = with_mesh_parameters(load_scene(Path(__file__).parent.parent / "scenes"
                                            / "two_cylinders.toml"),
                                 h_contact=0.01)  # issue 21's case
    problem = build_problem(scene)
    strategy = make_strategy("gnrm", problem, scene.solver, predictor="active-set")
    path = solve_load_path(strategy, scene.solver.steps)
    assert path.converged
    assert path.steps[0].iterations <= 4
    assert path.iterations <= 27, [s.iterations for s in path.steps]


def test_active_set_predictor_resumed_history_has_no_gaps() -> None:
    """A history set from outside drops the gaps: the next step decides by the extrapolation."""
    problem = cases.build(CYLINDER, 1.0, relative=True, quadrature="nodal")
    strategy = make_strategy("gnrm", problem, SolverSettings(atol=1e-8), predictor="active-set")
    assert isinstance(strategy, ActiveSetPredicted)
    solve_load_path(strategy, 10)
    strategy.history = strategy.history
    problem.set_load(1.0)
    assert strategy.predict()
    assert strategy.inner.solve().converged


def test_active_set_predictor_round_off_pressure_is_an_open_node() -> None:
    """A node that lifted off with lam = -1e-96 left from its iterations stays open.

    Such a node once counted as in contact and was pulled back onto the
    target from afar (the shipped ironing scene diverged). The same state
    with the round-off pressure removed gives the same guess.
    """
    problem = cases.build(CYLINDER, 1.0, relative=True, quadrature="nodal")
    strategy = make_strategy("gnrm", problem, SolverSettings(atol=1e-8), predictor="active-set")
    assert solve_load_path(strategy, 10, last_step=5).status == "partial"
    contact = problem.contacts[0]
    g = contact.surface.nodal(contact._gap_form)
    lam = contact.lam.x.array
    far = int(np.argmax(np.where(lam[:g.size] == 0.0, g, -np.inf)))
    assert g[far] > contact.surface.h
    guesses = []
    for value in (0.0, -1e-96):
        lam[far] = value
        t, u, lam_n = strategy.history[-1]
        lam_n[far] = value
        strategy._history[-1] = (t, u, lam_n)
        problem.set_load(0.6)
        assert strategy.predict()
        guesses.append(contact.lam.x.array.copy())
        g_pred = contact.surface.nodal(contact._gap_form)
        assert guesses[-1][far] + float(contact.r.value) * g_pred[far] > 0.0  # open
        problem.u.x.array[:] = u  # back to the last converged state
        contact.lam.x.array[:] = lam_n
        problem.set_load(t)
    assert np.array_equal(guesses[0][:g.size][np.arange(g.size) != far],
                          guesses[1][:g.size][np.arange(g.size) != far])
