"""The status tests of the convergence monitor, on constructed sequences."""

import math

from fenics_contact.solvers.diagnostics import ConvergenceMonitor, SolverSettings, Status


def feed(monitor, values, states=None):
    states = states or [None] * len(values)
    status = None
    for v, s in zip(values, states, strict=True):
        status = monitor.check(v, s)
        if status is not None:
            return status
    return status


def test_converged_when_below_absolute_or_relative_tolerance():
    monitor = ConvergenceMonitor(SolverSettings(atol=1e-8))
    assert feed(monitor, [1.0, 1e-3, 1e-9]) == Status.CONVERGED
    m = ConvergenceMonitor(SolverSettings(atol=1e-20, rtol=1e-6))
    assert feed(m, [100.0, 1e-2, 1e-5]) == Status.CONVERGED
    assert m.iterations == 2


def test_nan_and_growth_are_divergence():
    assert feed(ConvergenceMonitor(SolverSettings()), [1.0, math.nan]) == Status.DIVERGED
    m = ConvergenceMonitor(SolverSettings(divergence_factor=1e3))
    assert feed(m, [1.0, 10.0, 2e3]) == Status.DIVERGED


def test_alternating_active_sets_without_progress_are_cycling():
    settings = SolverSettings(cycle_window=6, max_iterations=100)
    values = [1.0] + [0.5, 0.7] * 10
    states = ["x"] + ["A", "B"] * 10
    m = ConvergenceMonitor(settings)
    assert feed(m, values, states) == Status.CYCLING
    assert m.iterations < 12


def test_a_two_cycle_within_one_active_set_is_cycling():
    """The sliding blocks at mu = 10, first reversed step: residuals 0.161, 0.0628, 0.161, ...

    with one active pattern throughout (every node in the same state and
    slip direction); `auto` spent 100 iterations in each of two such
    cycles (206 in the step) before they were found, 33 after.
    """
    settings = SolverSettings(cycle_window=6, max_iterations=100)
    values = [0.0176] + [0.161243, 0.062768] * 10
    m = ConvergenceMonitor(settings)
    assert feed(m, values, ["x"] + ["A"] * 20) == Status.CYCLING
    assert m.iterations < 12
    # one pattern and a residual that keeps falling, however slowly: not cycling
    steady = [0.9**k for k in range(40)]
    limited = ConvergenceMonitor(SolverSettings(cycle_window=6, max_iterations=30))
    assert feed(limited, steady, ["A"] * 40) == Status.MAX_ITERATIONS


def test_slow_but_steady_progress_is_not_cycling():
    settings = SolverSettings(cycle_window=6, max_iterations=30)
    values = [0.9**k for k in range(40)]
    states = ["A", "B"] * 20
    assert feed(ConvergenceMonitor(settings), values, states) == Status.MAX_ITERATIONS


def test_iteration_limit():
    m = ConvergenceMonitor(SolverSettings(max_iterations=3))
    assert feed(m, [1.0, 0.9, 0.8, 0.7, 0.6]) == Status.MAX_ITERATIONS
    assert m.iterations == 3


def test_a_node_inside_its_own_neighbourhood_is_told_what_helps():
    """Lowering the neighbourhood is advised only where it is above one facet size."""
    from types import SimpleNamespace

    from fenics_contact.solvers.diagnostics import _inside_target_cause

    def cause(neighbourhood: float) -> str:
        pair = SimpleNamespace(neighbourhood=neighbourhood,
                               inside_own_neighbourhood=lambda depth: True)
        return _inside_target_cause(SimpleNamespace(pair=pair), 1e-3)

    assert "lower [[pair]] neighbourhood (e.g. 1)" in cause(3.0)
    folded = cause(1.0)
    assert "lower [[pair]] neighbourhood" not in folded
    assert "folds onto itself within about one facet size" in folded
    assert "tag the surface on either side of the fold apart" in folded


def test_a_two_cycle_whose_low_level_drifts_is_cycling():
    """A 3D frictional mortar pair at r = 10 E/h: 1.24e-2 / 1.41e-3, the low side 1 % lower
    a cycle. A new minimum kept appearing, so 48 iterations passed before the step escaped
    by itself; a zigzag of two levels that barely move is a 2-cycle."""
    values = [0.3] + [v for k in range(30) for v in (1.24e-2, 1.41e-3 * 0.99**k)]
    m = ConvergenceMonitor(SolverSettings(cycle_window=12, max_iterations=100))
    assert feed(m, values) == Status.CYCLING
    assert m.iterations <= 14
    # a zigzag that makes progress is not one
    falling = [0.3] + [v for k in range(30) for v in (1.24e-2 * 0.7**k, 1.41e-3 * 0.7**k)]
    m = ConvergenceMonitor(SolverSettings(cycle_window=12, max_iterations=40))
    assert feed(m, falling) == Status.MAX_ITERATIONS


def test_a_mortar_node_inside_but_within_reach_is_not_said_to_be_past_the_search():
    """A crushed ring's fold (0.0179 inside, reach 0.059): no facet it may pair with."""
    from types import SimpleNamespace

    from fenics_contact.model.mortar import MortarContact
    from fenics_contact.solvers.diagnostics import _inside_target_cause

    contact = MortarContact.__new__(MortarContact)
    contact.mortar = SimpleNamespace(reach=0.059)
    near = _inside_target_cause(contact, 3e-4, 0.0179)
    assert "finds no target facet it may pair with" in near
    assert "deeper than its segment search reaches" not in near
    assert "deeper than its segment search reaches" in _inside_target_cause(contact, 3e-4, 0.1)
