"""The iterative linear solver (GMRES, Schur field split, GAMG) gives the MUMPS answer.

Same Newton counts, displacement equal to a tight tolerance, on the 3D
indentation ladder problem at a small size, for the saddle-point (GNRM) and
the single-block (penalty) systems; and the kernel's time accounts add up.
"""

from __future__ import annotations

import numpy as np
import pytest

from mpi4py import MPI

import fenics_contact  # noqa: F401  (before dolfinx)
from benchmarks import cases
from benchmarks.cases import cells_for_dofs
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.linear import LinearSolverSettings, rigid_body_modes
from fenics_contact.solvers.predictor import Extrapolated
from fenics_contact.solvers.stepping import solve_load_path

NEWTON = SolverSettings(atol=1e-12, rtol=1e-10, max_iterations=30)


def solve(kind: str, method: str = "gnrm", comm: MPI.Comm = MPI.COMM_WORLD, n: int = 6) -> tuple:
    problem = cases.build(
        cases.block_indentation(n, depth=0.03, candidate_width=0.5), 1.0, comm=comm
    )
    strategy = make_strategy(method, problem, NEWTON)
    strategy.kernel.set_linear_solver(LinearSolverSettings(kind=kind))
    path = solve_load_path(Extrapolated(strategy), 2, max_cutbacks=0)
    return problem, path, strategy.kernel


def test_cells_for_dofs() -> None:
    assert cells_for_dofs(1e6) == 68
    assert 3 * (cells_for_dofs(1e4) + 1) ** 3 == pytest.approx(1e4, rel=0.05)


def test_rigid_body_modes_are_orthonormal() -> None:
    problem = cases.build(cases.block_indentation(4, candidate_width=0.6))
    basis = rigid_body_modes(problem.V).getVecs()
    gram = np.array([[a.dot(b) for b in basis] for a in basis])
    assert gram.shape == (6, 6)
    assert np.allclose(gram, np.eye(6), atol=1e-12)


@pytest.mark.parametrize("method", ["gnrm", "penalty"])
def test_iterative_solver_reproduces_mumps(method: str) -> None:
    direct, path_d, kernel_d = solve("direct", method)
    iterative, path_i, kernel_i = solve("iterative", method)
    assert path_d.converged and path_i.converged
    assert [s.iterations for s in path_i.steps] == [s.iterations for s in path_d.steps]
    assert [s.active_count for s in path_i.steps] == [s.active_count for s in path_d.steps]
    ud, ui = direct.u.x.array, iterative.u.x.array
    assert np.abs(ui - ud).max() <= 1e-9 * np.abs(ud).max()
    assert path_i.steps[-1].contact_force == pytest.approx(path_d.steps[-1].contact_force,
                                                          rel=1e-9)
    assert kernel_i.timings.krylov_iterations > 0
    assert kernel_d.timings.krylov_iterations == 0


def test_kernel_accounts_add_up() -> None:
    _, path, kernel = solve("direct")
    t = kernel.timings
    assert t.linear_solves == t.jacobians == path.linear_solves == path.iterations
    assert t.residuals == path.iterations + len(path.steps)
    assert min(t.compile_s, t.residual_s, t.jacobian_s, t.setup_s, t.solve_s) > 0
    # the totals are sums of the disjoint phase accounts (a bookkeeping identity;
    # how the phases compare with wall time is measured in benchmarks/validation/hertz2d.py)
    accounted = t.residual_s + t.jacobian_s + t.setup_s + t.solve_s
    assert t.assembly_s + t.linear_s == pytest.approx(accounted, rel=1e-12)


def test_stopwatch_measures_and_differences_subtract() -> None:
    import time

    from fenics_contact.solvers.timing import KernelTimings, stopwatch

    t = KernelTimings(residual_s=1.0, linear_solves=2)
    before = t.snapshot()
    with stopwatch(t, "solve_s"):
        time.sleep(0.05)
    assert 0.05 <= t.solve_s < 0.5
    delta = t.since(before)
    assert delta.residual_s == 0.0 and delta.linear_solves == 0
    assert delta.solve_s == t.solve_s
    assert t.to_dict()["linear_s"] == t.setup_s + t.solve_s


@pytest.mark.mpi
def test_parallel_iterative_run_matches_serial() -> None:
    """On 2 ranks under `make test`: the same Newton counts and answer as on one."""
    results = {}
    for name, comm in (("world", MPI.COMM_WORLD), ("self", MPI.COMM_SELF)):
        problem, path, _ = solve("iterative", comm=comm)
        assert path.converged
        results[name] = (
            [s.iterations for s in path.steps],
            [s.active_count for s in path.steps],
            path.steps[-1].contact_force,
            problem.u.x.petsc_vec.norm(),
        )
    world, serial = results["world"], results["self"]
    assert world[0] == serial[0]
    assert world[1] == serial[1]
    assert world[2] == pytest.approx(serial[2], rel=1e-9)
    assert world[3] == pytest.approx(serial[3], rel=1e-9)


@pytest.mark.parametrize("release", ["destroy", "collect"])
def test_solver_options_leave_with_their_kernel(release: str) -> None:
    """The field-split defaults a kernel puts into PETSc's database go when the kernel goes.

    (Before, every iterative kernel left its prefixed options behind, and the
    test run ended with PETSc's "options you set that were not used".)
    """
    import gc

    from petsc4py import PETSc

    from fenics_contact.solvers.condensed import kernel_for

    problem = cases.build(cases.block_indentation(4), 1.0, comm=MPI.COMM_WORLD)
    kernel = kernel_for(problem.augmented_system(), LinearSolverSettings(kind="iterative"))
    prefix = kernel._prefix
    mine = [k for k in PETSc.Options().getAll() if k.startswith(prefix)]
    assert any("fieldsplit_u_pc_type" in k for k in mine)
    # switching solvers drops the old defaults (else they would win over the new ones)
    kernel.set_linear_solver(LinearSolverSettings(kind="iterative", amg_threshold=0.05))
    assert PETSc.Options().getReal(f"{prefix}fieldsplit_u_pc_gamg_threshold") == 0.05
    if release == "destroy":
        kernel.destroy()
    else:
        del kernel
        gc.collect()
    assert [k for k in PETSc.Options().getAll() if k.startswith(prefix)] == []


def test_a_failed_factorisation_does_not_poison_the_next_solve() -> None:
    """A zero pivot fails one solve; the next, on a sound matrix, must factorise afresh.

    MUMPS skips every numeric factorisation after one that failed, so a kept
    solver would stop every cut-back attempt of the load step at its first
    iteration (INFOG(1) = -3).
    """
    problem = cases.build(cases.block_indentation(3, depth=0.03, candidate_width=0.5), 1.0)
    kernel = make_strategy("gnrm", problem, NEWTON).kernel
    problem.set_load(0.5)
    kernel.assemble_residual()
    kernel._assemble_A()
    assert kernel._linear_solve() and kernel.ksp.getConvergedReason() > 0
    kernel.A.zeroRows([0], diag=0.0)  # a zero row: the factorisation fails
    assert not kernel._linear_solve()
    kernel._assemble_A()  # the sound matrix again
    assert kernel._linear_solve() and kernel.ksp.getConvergedReason() > 0
    assert np.all(np.isfinite(kernel.dx.getArray()))
