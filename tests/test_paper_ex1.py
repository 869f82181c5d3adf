"""The paper's Example 1: a striker node on the facet of one SVK quadrilateral.

Checks the node-to-segment gap written in UFL against its closed form, the
exact answer u = 2h, the GNRM and penalty counts of Table 1, the penalty
displacements the geometry was reconstructed from, and the reason GNRM
diverges at r = 10000.
"""

import math

import numpy as np
import pytest

from benchmarks.research.paper import PAPER_E, PAPER_NU, PAPER_PENALTY_U
from benchmarks.research.paper_ex1 import StrikerOnFacet, corner_displacement
from benchmarks.research.study import main, subjects
from fenics_contact.model.contact import ContactSettings
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings, Status
from fenics_contact.solvers.stepping import solve_load_path

EX1 = StrikerOnFacet()
H = EX1.h
#: Corner stiffness Psi''(0) of the unit plane-strain square, 2 x 2 Gauss:
#: ((lambda + 2 mu) + mu) / 3.
LMBDA = PAPER_E * PAPER_NU / ((1 + PAPER_NU) * (1 - 2 * PAPER_NU))
MU = PAPER_E / (2 * (1 + PAPER_NU))
K0 = (LMBDA + 3 * MU) / 3


def solve(method, r):
    problem = EX1.build(ContactSettings(r=r, relative=False))
    strategy = make_strategy(method, problem, SolverSettings(atol=1e-8, max_iterations=500))
    path = solve_load_path(strategy, EX1.steps, max_cutbacks=0)
    return path, problem


def set_corner(problem, u):
    coords = problem.V.tabulate_dof_coordinates()
    corner = np.isclose(coords[:, 0], 1.0) & np.isclose(coords[:, 1], 1.0)
    problem.u.x.array.reshape(-1, 2)[corner, 1] = u
    problem.u.x.scatter_forward()


@pytest.mark.parametrize("u", [0.0, -0.3, -0.5, 0.2])
def test_ufl_node_to_segment_gap_is_the_closed_form(u):
    """g = (h - u/2) / sqrt(1 + u^2) and xi = (1/2 + h u) / (1 + u^2) at full load."""
    problem = EX1.build(ContactSettings(r=1.0, relative=False))
    problem.set_load(1.0)
    set_corner(problem, u)
    state = problem.contact_state()
    assert state.gap[0] == pytest.approx((H - u / 2) / math.sqrt(1 + u * u), abs=1e-14)
    assert problem.contact_point()[0] == pytest.approx((0.5 + H * u) / (1 + u * u), abs=1e-14)


@pytest.mark.parametrize("r", [1.0, 10.0, 100.0, 1000.0])
def test_gnrm_finds_u_equal_2h_in_two_newton_steps(r):
    """Paper: 3 iterations for r = 1 ... 1000, counting the final residual check.

    The first step solves the linearised gap g(0) + g'(0) du = 0; since
    g'' (0) does not enter and the zero set of g is the line u = 2h, it
    lands on u = 2h exactly; the second step sets the multiplier.
    """
    path, problem = solve("gnrm", r)
    assert path.converged
    assert path.iterations == 2
    assert len(path.steps[0].residuals[0]) == 3
    assert corner_displacement(problem) == pytest.approx(2 * H, abs=1e-12)
    state = problem.contact_state()
    assert state.max_penetration < 1e-12
    assert state.contact_force == pytest.approx(60.828932, abs=1e-5)


@pytest.mark.mpi
def test_gnrm_and_penalty_on_any_number_of_ranks():
    """One cell: on two ranks one of them holds no contact element."""
    path, problem = solve("gnrm", 100.0)
    assert path.converged and path.iterations == 2
    assert corner_displacement(problem) == pytest.approx(2 * H, abs=1e-12)
    assert problem.contact_state().contact_force == pytest.approx(60.828932, abs=1e-5)
    path, problem = solve("penalty", 100.0)
    assert path.converged and path.iterations == 4
    assert corner_displacement(problem) == pytest.approx(NUMPY_PENALTY_U[100.0], abs=1e-11)


#: Penalty displacement with 2 x 2 Gauss energy, from the numpy model of
#: benchmarks/paper_ex1_geometry.py (bisection on Psi'(u) + r min(g, 0) g'(u) = 0,
#: g' by complex step): an independent check of the UFL gap and its derivative.
NUMPY_PENALTY_U = {100.0: -0.0987501546771874, 1000.0: -0.38726857774465984}


@pytest.mark.parametrize("r", [100.0, 1000.0])
def test_penalty_displacement_is_the_papers(r):
    path, problem = solve("penalty", r)
    assert path.converged
    u = corner_displacement(problem)
    assert u == pytest.approx(NUMPY_PENALTY_U[r], abs=1e-11)
    # the paper prints three digits: ours rounds to them exactly
    assert float(f"{u:.3g}") == PAPER_PENALTY_U[r]


def test_penalty_counts_and_cycling_at_large_r():
    """Newton steps 2, 3, 4, 4 (paper 3, 4, 5, 5 with the final check) and cycling at 1e4."""
    counts = []
    for r in (1.0, 10.0, 100.0, 1000.0):
        path, _ = solve("penalty", r)
        assert path.converged
        counts.append(path.iterations)
    assert counts == [2, 3, 4, 4]
    path, _ = solve("penalty", 1e4)
    assert path.status == Status.CYCLING


def test_penalty_tangent_is_consistent():
    """Quadratic convergence of the penalty Newton needs the facet-rotation terms."""
    path, _ = solve("penalty", 1000.0)
    res = path.steps[0].residuals[0]
    rates = [math.log(res[k + 1]) / math.log(res[k]) for k in range(2, len(res) - 1)]
    assert min(rates) > 1.9


def test_gnrm_diverges_above_the_critical_r():
    """Paper: divergence at r = 10000.

    From (0, 0) the first GNRM step lands on u = 2h with the multiplier
    lam_1 = 4h (Psi''(0) - r h^2): the facet-rotation term min(lam + r g, 0) g''
    of the tangent grows with r and makes lam_1 tensile for r > Psi''(0) / h^2
    = 1938.5; contact is then released and Newton diverges.
    """
    r_star = K0 / H**2
    assert r_star == pytest.approx(1938.46, abs=0.01)
    problem = EX1.build(ContactSettings(r=1e4, relative=False))
    strategy = make_strategy("gnrm", problem, SolverSettings(atol=1e-8))
    problem.set_load(1.0)
    strategy.kernel.assemble_residual()
    assert strategy.kernel.newton_step()
    assert corner_displacement(problem) == pytest.approx(2 * H, abs=1e-12)
    assert problem.lam.x.array[0] == pytest.approx(4 * H * (K0 - 1e4 * H**2), rel=1e-10)
    assert solve("gnrm", 1e4)[0].status == Status.DIVERGED
    assert solve("gnrm", 0.98 * r_star)[0].converged
    assert solve("gnrm", 1.02 * r_star)[0].status == Status.DIVERGED


def test_bad_target_or_striker_is_refused_before_any_work():
    from dolfinx import mesh

    from mpi4py import MPI

    from benchmarks.research.striker import StrikerOnFacetProblem
    from fenics_contact.model.materials import SaintVenantKirchhoff

    domain = mesh.create_unit_square(MPI.COMM_WORLD, 1, 1, mesh.CellType.quadrilateral)
    top = mesh.locate_entities_boundary(domain, 1, lambda x: np.isclose(x[1], 1.0))
    both = mesh.locate_entities_boundary(
        domain, 1, lambda x: np.isclose(x[0], 1.0) | np.isclose(x[1], 1.0)
    )
    law = SaintVenantKirchhoff(PAPER_E, PAPER_NU)
    settings = ContactSettings(r=1.0, relative=False)
    with pytest.raises(ValueError, match="exactly one facet"):
        StrikerOnFacetProblem(domain, law, both, (0.5, 1.0), (0.0, H), settings)
    with pytest.raises(ValueError, match="striker_motion"):
        StrikerOnFacetProblem(domain, law, top, (0.5, 1.0), (0.0, H, 0.0), settings)


def test_the_paper_examples_keep_their_names():
    """Example 1 is the one custom problem; its wedge analog and Example 2 are scenes."""
    from fenics_contact import Scene

    known = subjects()
    assert isinstance(known["paper-ex1"].case, StrikerOnFacet)
    assert isinstance(known["paper-ex1-wedge"].case, Scene)
    assert isinstance(known["paper-ex2"].case, Scene)


def test_study_prints_ours_beside_the_paper_and_the_wedge(tmp_path, capsys):
    code = main(
        ["paper-ex1", "--methods", "gnrm", "--r", "100,10000", "--beside",
         "paper-ex1-wedge", "--out", str(tmp_path)]
    )
    assert code == 0
    printed = capsys.readouterr().out
    assert "| GNRM | paper-ex1 | 2 | divergence |" in printed
    assert "| GNRM | paper | 3 | divergence |" in printed
    assert "| GNRM | paper-ex1-wedge | 2 | 2 |" in printed
