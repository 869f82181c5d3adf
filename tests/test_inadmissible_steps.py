"""Newton steps and predictions that turn an element inside out are shortened or dropped.

Near a fold that closes (a crushed tube's inner wall on fine meshes) a full
Newton step, or the extrapolated start of a load step, can turn elements
inside out: det F <= 0, where the neo-Hookean energy's log J is NaN and the
step used to fail outright. The Newton loop now takes such a step back by
halves (from the same direction) and the predictor falls back to the last
converged state. On the 24-layer tube the closing step then converges (42
Newton iterations, one cut-back) where it failed after four cut-backs
(docs/contacts.md).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import fenics_contact  # noqa: F401  (before dolfinx)
from benchmarks import cases
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.base import SHORTENINGS, _shorten_to_finite
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.predictor import Extrapolated
from fenics_contact.solvers.stepping import solve_load_path


class _Line:
    """A one-unknown kernel after the full step x = x0 - dx (x0 = 0, dx = 1)."""

    def __init__(self) -> None:
        self.x, self.dx = -1.0, 1.0

    def take_back(self, fraction: float) -> None:
        self.x += fraction * self.dx


@pytest.mark.parametrize(("admissible", "x_end"), [(0.2, -0.125), (0.6, -0.5), (2.0, -1.0)])
def test_a_step_with_a_non_finite_residual_is_halved_until_finite(admissible, x_end) -> None:
    kernel = _Line()
    norm = _shorten_to_finite(kernel, lambda: math.nan if -kernel.x > admissible else -kernel.x)
    assert kernel.x == pytest.approx(x_end)
    assert norm == pytest.approx(-x_end)


def test_the_shortening_stops_after_its_halvings() -> None:
    kernel = _Line()
    norm = _shorten_to_finite(kernel, lambda: math.nan)
    assert math.isnan(norm)
    assert kernel.x == pytest.approx(-0.5**SHORTENINGS)


def test_an_extrapolation_that_inverts_an_element_is_not_used() -> None:
    scene = cases.bar_on_cradle()
    problem = cases.build(scene, 1.0)
    strategy = Extrapolated(make_strategy("gnrm", problem, SolverSettings()))
    assert solve_load_path(strategy, 2).converged
    (t0, u0, lam0), (t1, u1, lam1) = strategy.history
    problem.set_load(t1 + (t1 - t0))
    # a sound history: the extrapolation is used
    assert strategy.predict()
    assert np.abs(problem.u.x.array - (2 * u1 - u0)).max() < 1e-14
    # a history whose extrapolation turns elements inside out: the last converged state
    problem.u.x.array[:] = u1
    strategy._set_multipliers(lam1)
    rough = np.random.default_rng(0).uniform(-1.0, 1.0, u1.shape)
    size = float(np.ptp(problem.domain.geometry.x, axis=0).max())
    strategy.history = [(t0, u1 + 0.5 * size * rough, lam0), (t1, u1, lam1)]
    assert not strategy.predict()
    assert np.array_equal(problem.u.x.array, u1)
    assert problem.min_det_F().value > 0.0
