"""The extrapolating load-step predictor and the 2D Hertz Newton-count target.

Issue 6 case: half-cylinder R = 1, E = 200, nu = 0.3, small strain, top moved
down 0.02 in 10 steps, h = 0.008 at contact (3814 displacement DOFs), GNRM
nodal. Target: <= 23 Newton iterations in total, the same for every r from
1e-2 to 1e6 (relative to E/h). Measured: 19 (4 3 2 2 2 1 1 1 1 2) with the
predictor, 25 without.
"""

from __future__ import annotations

import numpy as np
import pytest

import fenics_contact  # noqa: F401  (before dolfinx)
from benchmarks import cases
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.predictor import Extrapolated
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
