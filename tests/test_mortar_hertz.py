"""Mortar pairs in 2D: two identical cylinders against Hertz, Newton order, r independence."""

from __future__ import annotations

import numpy as np
import pytest
from test_mortar import LOAD_TAG, SUPPORT_TAG, _mesh, _problem, _solve

from mpi4py import MPI

from benchmarks import cases
from fenics_contact.references.hertz import (
    fit_contact_profile,
    half_width,
    interpolation_error,
    peak_pressure,
    pressure_profile,
)


# -- 3. and 4. two cylinders --------------------------------------------------------------
def _cylinders(disc: str, r: float, h: float = 0.01) -> dict:
    md = _mesh(cases.two_cylinders(h, h_far=0.2))
    problem = _problem(md, {LOAD_TAG: (0.0, -0.02), SUPPORT_TAG: (0.0, 0.0)}, disc, r)
    its, residuals = _solve(problem, "gnrm", 6)  # 3 steps diverge at r = 1e2 E/h
    state = problem.contact_state()
    x = np.concatenate(problem.comm.allgather(problem.nodal_coordinates()[:, 0]))
    p = -np.concatenate(problem.comm.allgather(state.pressure))
    P = state.contact_force
    a, p0 = half_width(P, 0.5, 100.0, 0.3), peak_pressure(P, 0.5, 100.0, 0.3)
    hertz = pressure_profile(x, p0, a)

    def l2(where: np.ndarray) -> float:
        return float(np.sqrt(np.sum((p - hertz)[where] ** 2) / np.sum(hertz[where] ** 2)))

    return {"its": its, "residuals": residuals, "force": P, "x": x, "p": p,
            "peak": float(p.max() / p0 - 1), "l2": l2(np.abs(x) < 1.5 * a),
            "l2_inner": l2(np.abs(x) < a - 2 * h), "state": state}


@pytest.fixture(scope="module")
def cylinders() -> dict:
    return {r: _cylinders("mortar", r) for r in (1e-2, 1.0, 1e2)}


def test_mortar_two_cylinders_hertz(cylinders: dict) -> None:
    """Nodal pressure against Hertz at h = 0.01 (a/h ~ 8); node-to-segment for comparison.

    The nodal pressure of a 2D mortar pair is the multiplier field's nodal force per
    tributary length. Measured: mortar peak +0.14 %, L2 over |x| < 1.5 a 3.8 % (the node
    at each edge of the contact zone), L2 over |x| < a - 2 h 0.62 %; node-to-segment
    +2.7 %, 5.6 %, 4.0 %. The multipliers themselves: +0.73 %, 9.7 %, 1.6 %.
    """
    mortar = cylinders[1.0]
    nts = _cylinders("node-to-segment", 1.0)
    print({k: (mortar[k], nts[k]) for k in ("peak", "l2", "l2_inner")})
    assert mortar["state"].max_penetration < 1e-10
    assert abs(mortar["peak"]) < 0.005 and abs(nts["peak"]) > 0.01
    assert mortar["l2_inner"] < 0.01 and nts["l2_inner"] > 0.02
    assert mortar["l2"] < 0.05 < nts["l2"]  # the aim (2 %) is missed at the edges of the zone
    # the active set is the multipliers': the node past the last active one carries a
    # share of its neighbour's force but is open
    state = mortar["state"]
    assert state.active_count == MPI.COMM_WORLD.allreduce(int(np.sum(state.multiplier < 0)))
    assert np.sum(mortar["p"] > 0) > state.active_count


def test_mortar_two_cylinders_quadratic_and_r_independent(cylinders: dict) -> None:
    """Order >= 1.8 over the last Newton iterations; the same answer for r = 1e-2 ... 1e2 E/h."""
    for residuals in cylinders[1.0]["residuals"]:
        r = [v for v in residuals if v > 1e-11]
        if len(r) >= 3:
            a, b, c = r[-3:]
            assert np.log(c / b) / np.log(b / a) >= 1.8, residuals
    ref = cylinders[1.0]
    for r in (1e-2, 1e2):
        assert abs(cylinders[r]["force"] - ref["force"]) <= 1e-8 * ref["force"]
        np.testing.assert_allclose(cylinders[r]["p"], ref["p"], atol=1e-8 * ref["p"].max())


#: Measured in serial (h = 0.01, 6 steps, r = 1 E/h, four slots).
EXPECTED_ITS = [6, 4, 3, 3, 3, 4]
EXPECTED_FORCE = 1.0741917390996716


def test_mortar_two_cylinders_on_the_shipped_mesh_within_two_percent() -> None:
    """h = 0.005 (a/h ~ 16, scenes/two_cylinders.toml): L2 over |x| < 1.5 a below 2 %.

    Measured (6 steps, r = 1 E/h): mortar peak +0.25 %, L2 1.7 %, inner 0.45 %, half-width
    of the fitted ellipse within 1 % of Hertz's; node-to-segment on the same meshes +3.0 %,
    4.1 %, 3.3 %.
    """
    mortar = _cylinders("mortar", 1.0, h=0.005)
    nts = _cylinders("node-to-segment", 1.0, h=0.005)
    print({k: (mortar[k], nts[k]) for k in ("peak", "l2", "l2_inner")})
    assert mortar["l2"] < 0.02 < 0.03 < nts["l2"]
    assert abs(mortar["peak"]) < 0.005 < 0.02 < nts["peak"]
    assert mortar["l2_inner"] < 0.006
    P = mortar["force"]
    fit = fit_contact_profile(mortar["x"], -mortar["p"])
    assert fit.a == pytest.approx(half_width(P, 0.5, 100.0, 0.3), rel=0.01)


def test_the_exact_profile_interpolated_needs_sixteen_nodes_per_half_width() -> None:
    """The exact profile's own P1 interpolant: 3.3 ... 4.1 % at a/h = 8, <= 2 % at a/h = 16.

    Why the shipped two-cylinder mesh resolves the zone with a/h ~ 16 (the square root at
    the edge of the zone is not linear).
    """
    low, high = interpolation_error(8.0)
    assert 0.03 < low < high < 0.045
    low, high = interpolation_error(16.0)
    assert 0.015 < low < high <= 0.0201
    assert interpolation_error(32.0)[1] == pytest.approx(0.5 * interpolation_error(16.0)[1],
                                                         rel=0.05)  # first order in h / a


@pytest.mark.mpi
def test_mortar_two_cylinders_serial_counts() -> None:
    """The serial Newton counts and force; `mpiexec -n 2` must give the same."""
    result = _cylinders("mortar", 1.0)
    assert result["its"] == EXPECTED_ITS
    assert abs(result["force"] - EXPECTED_FORCE) <= 1e-10 * EXPECTED_FORCE


def _pushed(steps: int) -> tuple[float, np.ndarray, list[int]]:
    """Two cylinders (h = 0.02) pushed by 0.02 in ``steps`` equal steps: force, p, iterations."""
    md = _mesh(cases.two_cylinders(0.02, h_far=0.2))
    problem = _problem(md, {LOAD_TAG: (0.0, -0.02), SUPPORT_TAG: (0.0, 0.0)}, "mortar", 1.0)
    its, _ = _solve(problem, "gnrm", steps)
    state = problem.contact_state()
    return state.contact_force, -np.asarray(state.pressure), its


def test_mortar_answer_does_not_depend_on_the_load_path() -> None:
    """The final state is the same whether it is reached in 1 or in 4 load steps (to 1e-8).

    Frictionless and hyperelastic: the equilibrium at the final load is unique, and the
    mortar weighted gaps carry no memory of earlier iterations (no facet hysteresis).
    """
    force_1, p_1, its_1 = _pushed(1)
    force_4, p_4, its_4 = _pushed(4)
    print(force_1, force_4, its_1, its_4)
    assert abs(force_1 - force_4) <= 1e-8 * force_4
    np.testing.assert_allclose(p_1, p_4, atol=1e-8 * p_4.max())
