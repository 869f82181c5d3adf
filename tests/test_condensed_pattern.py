"""The condensed two-body matrix: open nodes left out exactly, the pattern kept across moves.

Two cylinders (node-to-segment, h = 0.02, 3 GNRM steps, r = 1 E/h) at their
converged state: about a third of the striker nodes are open far from the
other cylinder, so the selection P leaves them out (their residual and
tangent do not depend on the target); P also holds explicit zeros for the
vertices of the facets around each node's facet, so a move to one of them
changes values only. The pair's terms are integrated only over the facets
of coupled nodes, exactly, and a Newton step closes only such nodes.
"""

from __future__ import annotations

import numpy as np
import pytest
from tangent_check import condensed_tangent_errors

from benchmarks import cases
from fenics_contact.model.pairs import DeformablePair, _closest
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings


@pytest.fixture(scope="module")
def solved():
    problem = cases.build(cases.two_cylinders(0.02, push=0.02), 1.0)
    strategy = make_strategy("gnrm", problem, SolverSettings())
    for i in (1, 2, 3):
        problem.set_load(i / 3)
        assert strategy.solve().converged
    pair = next(c.pair for c in problem.contacts if isinstance(getattr(c, "pair", None),
                                                               DeformablePair))
    return problem, strategy.kernel, pair


def _condensed(kernel) -> tuple[np.ndarray, np.ndarray]:
    """b and the dense A of the kernel at the current state (serial)."""
    kernel._pull()
    kernel._assemble_b()
    kernel._assemble_A()
    b = kernel.b.getArray().copy()
    indptr, indices, values = kernel.A.getValuesCSR()
    n = kernel.A.getSize()[0]
    dense = np.zeros((n, n))
    rows = np.repeat(np.arange(n), np.diff(indptr))
    dense[rows, indices] = values
    return b, dense


def test_open_nodes_are_left_out_exactly(solved) -> None:
    _, kernel, pair = solved
    coupled = pair._coupled.copy()
    assert 0 < coupled.sum() < coupled.size  # some nodes are left out
    b_pruned, A_pruned = _condensed(kernel)
    multiplier = pair.multiplier
    try:
        pair.multiplier = None  # every node condensed
        pair._coupled = pair.coupled(pair.target_displacements())
        pair.version += 1
        assert pair._coupled.all()
        b_all, A_all = _condensed(kernel)
    finally:
        pair.multiplier = multiplier
        pair._coupled = coupled
        pair.version += 1
    np.testing.assert_allclose(b_pruned, b_all, rtol=0, atol=1e-14 * np.abs(b_all).max())
    np.testing.assert_allclose(A_pruned, A_all, rtol=0, atol=1e-12 * np.abs(A_all).max())


def test_pair_integrated_only_where_it_can_act(solved) -> None:
    problem, kernel, pair = solved
    kernel._limit_forms()  # the pair's own limit (a test above condensed every node)
    (limit,) = kernel._limits
    striker = pair.surface.facets
    assert 0 < limit.facets.size < striker.size  # 28 of 38
    contact = next(c for c in problem.contacts if getattr(c, "pair", None) is pair)
    pressed = pair.multiplier() < 0.0  # serial: every node is owned
    assert pressed.sum() >= 3
    cells = pair.W.dofmap.list
    touching = pair._cell_facet[: cells.shape[0]][pressed[cells].any(axis=1)]
    assert np.isin(touching, limit.facets).all()
    assert set(limit.ids) == set(contact.own_ids)

    # the extended matrix holds every facet's entries (P^T A P reuses its symbolic
    # product: entries a later, wider assembly added would be left out of it)
    used = kernel.A_ext.getInfo()["nz_used"]
    kernel._assemble_ext_jacobian(kernel._J_all)  # every facet: no entry may be new
    assert kernel.A_ext.getInfo()["nz_used"] == used

    b_limited, A_limited = _condensed(kernel)
    limited = kernel.F_ext, kernel.J_ext
    try:
        kernel.F_ext, kernel.J_ext = kernel._F_all, kernel._J_all  # every striker facet
        b_all, A_all = _condensed(kernel)
    finally:
        kernel.F_ext, kernel.J_ext = limited
    assert kernel.F_ext is limited[0]  # the limits held: the whole forms were used above
    np.testing.assert_allclose(b_limited, b_all, rtol=0, atol=1e-13 * np.abs(b_all).max())
    np.testing.assert_allclose(A_limited, A_all, rtol=0, atol=1e-13 * np.abs(A_all).max())


def test_a_step_sets_in_contact_only_nodes_the_pair_couples(solved) -> None:
    """The exact contact set may close only nodes whose terms the kernel integrates."""
    problem, _, pair = solved
    contact = next(c for c in problem.contacts if getattr(c, "pair", None) is pair)
    gaps = contact.surface.nodal(contact._gap_form)
    allowed = contact.may_close(gaps)
    assert allowed.shape == gaps.shape
    assert 0 < allowed.sum() < allowed.size
    lam_of_w = contact._lam_of_w[: pair.n_owned]
    np.testing.assert_array_equal(allowed[lam_of_w], pair._coupled)
    # the open nodes left out are more than a facet size away; those near all count
    assert np.all(allowed[gaps < 0.5 * pair._size])


def test_tangent_with_open_nodes_left_out(solved) -> None:
    problem, _, pair = solved
    u = problem.u.x.array.copy()
    rng = np.random.default_rng(3)
    problem.u.x.array[:] += 1e-4 * rng.standard_normal(u.size)  # off equilibrium
    problem.u.x.scatter_forward()
    try:
        errors = condensed_tangent_errors(problem, rng)
        assert 0 < pair._coupled.sum() < pair._coupled.size
    finally:
        problem.u.x.array[:] = u
        problem.u.x.scatter_forward()
    assert min(errors) < 1e-6, errors


def test_a_move_to_a_neighbouring_facet_keeps_the_pattern(solved) -> None:
    _, kernel, pair = solved
    kernel._pull()
    kernel._assemble_b()
    kernel._assemble_A()
    matrix = kernel.A
    node = int(np.flatnonzero(pair._coupled)[0])
    facet = int(pair.assignment[node])
    fv = pair.facet_vertex
    neighbour = next(f for f in range(fv.shape[0])
                     if f != facet and np.intersect1d(fv[f], fv[facet]).size)
    far = next(f for f in range(fv.shape[0])
               if not np.intersect1d(fv[f], fv[facet]).size
               and not any(np.intersect1d(fv[g], fv[f]).size
                           for g in range(fv.shape[0]) if np.intersect1d(fv[g], fv[facet]).size))
    try:
        pair.assignment[node] = neighbour
        pair.version += 1
        kernel._refresh()
        kernel._assemble_A()
        assert kernel.A is matrix  # values only: the matrix, its solver and hierarchy kept
        pair.assignment[node] = far
        pair.version += 1
        kernel._refresh()
        assert kernel.A is None  # a coupling nobody could reach: a new pattern
        kernel._assemble_A()
    finally:
        pair.assignment[node] = facet
        pair.version += 1
        kernel._refresh()
        kernel._assemble_A()


def test_the_skin_searches_every_node_that_may_be_near(solved) -> None:
    """Nodes not searched again are far from the target and far in front of their facet."""
    *_, pair = solved
    n = pair.n_owned
    points = pair.striker_positions()
    current = (pair.X_vertices + pair.target_displacements())[pair.facet_vertex]
    fresh = _closest(current, points, pair._size, pair.assignment)
    assert pair.searched < points.shape[0]  # the last search skipped some nodes
    differs = np.flatnonzero(pair.assignment[:n] != fresh.facet[:n])
    near = fresh.distance[:n] < 2.0 * pair._size
    assert not np.any(near[differs])  # every node near the target has its closest facet
    gap = pair._plane_gaps(points[differs], current[pair.assignment[differs]])
    assert np.all(gap > pair._size)  # and the others are open at any r
