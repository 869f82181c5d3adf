"""Load stepping: cut-back on failure, and failed paths keep their completed steps."""

import json

import numpy as np

from mpi4py import MPI

from benchmarks import cases
from fenics_contact.output.io import write_json
from fenics_contact.output.xdmf import StepWriter
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings, Status
from fenics_contact.solvers.stepping import solve_load_path


def test_one_big_step_is_cut_back_and_reaches_the_ten_step_answer():
    scene = cases.bar_on_cradle()
    reference = cases.build(scene, 1.0)
    solve_load_path(make_strategy("gnrm", reference, SolverSettings()), scene.solver.steps)
    problem = cases.build(scene, 1.0)
    # The whole load at once needs 7 iterations: 5 forces cut-backs.
    strategy = make_strategy("gnrm", problem, SolverSettings(max_iterations=5))
    path = solve_load_path(strategy, 1, max_cutbacks=6)
    assert path.converged
    assert path.steps[0].cutbacks >= 1
    scale = np.abs(reference.u.x.array).max()
    assert np.abs(problem.u.x.array - reference.u.x.array).max() < 1e-8 * scale


def test_failed_path_reports_status_and_keeps_completed_steps(tmp_path):
    scene = cases.bar_on_cradle()
    problem = cases.build(scene, 10.0, relative=False)
    # Simultaneous Uzawa at r = 10 needs about 35 iterations a step until all
    # seven nodes close at step 6, which takes several hundred.
    strategy = make_strategy("sua", problem, SolverSettings(max_iterations=100))
    writer = StepWriter(problem, tmp_path / "solution.xdmf")
    written = []

    def keep(step):
        writer.write(step.load_factor)
        written.append(step.step)
        write_json(tmp_path / "steps.json", written)

    path = solve_load_path(strategy, scene.solver.steps, max_cutbacks=0, on_step=keep)
    writer.close()
    assert path.status == Status.MAX_ITERATIONS
    assert len(path.steps) == len(written) + 1
    assert written and written == list(range(1, len(written) + 1))
    assert json.loads((tmp_path / "steps.json").read_text()) == written
    xdmf = (tmp_path / "solution.xdmf").read_text()
    if MPI.COMM_WORLD.rank == 0:
        assert xdmf.count('<Attribute Name="displacement"') == len(written)


def test_a_nan_residual_is_not_read_as_one_that_met_its_tolerance():
    """A solve whose last residual is NaN diverged: no "the residual met its tolerance"."""
    from types import SimpleNamespace

    from fenics_contact.solvers.base import SolveResult
    from fenics_contact.solvers.stepping import refusal

    strategy = SimpleNamespace(settings=SolverSettings(atol=1e-8), problem=None)
    nan = SolveResult(Status.DIVERGED, 2, 0, 2, [34.1, 20.5, float("nan")])
    assert refusal(strategy, nan) is None
    above = SolveResult(Status.DIVERGED, 2, 0, 2, [34.1, 20.5])
    assert refusal(strategy, above) is None


def test_a_step_whose_residual_is_nan_from_the_start_says_so():
    """Every attempt's first residual NaN: the message says no Newton step could be taken."""
    from fenics_contact.solvers.stepping import StepRecord, _failure_message

    record = StepRecord(step=1, load_factor=0.0, status=Status.DIVERGED, cutbacks=1,
                        residuals=[[float("nan")], [float("nan")]])
    message = _failure_message(record, 0.125)
    assert message.startswith("diverged at load factor 0.125 after 2 attempts")
    assert "NaN or infinite at its first evaluation in every attempt" in message
    record.residuals = [[float("nan")], [3.0, float("nan")]]  # one attempt got going
    assert "NaN" not in _failure_message(record, 0.125)


def test_a_step_whose_first_linear_solve_always_fails_says_so():
    """Diverged with one finite residual per attempt: the first linear solve failed each
    time (a user's 2D mortar slide stopped so, and the advice to cut steps did nothing)."""
    from fenics_contact.solvers.stepping import StepRecord, _failure_message

    record = StepRecord(step=10, load_factor=0.45, status=Status.DIVERGED, cutbacks=2,
                        residuals=[[132.07], [0.21], [0.0999]])
    message = _failure_message(record, 0.4531)
    assert "in every attempt the linear solve of the first Newton step failed" in message
    assert "smaller steps do not change" in message
    record.residuals = [[132.07], [0.21, 0.01, 0.5]]  # one attempt took Newton steps
    assert "linear solve" not in _failure_message(record, 0.4531)
