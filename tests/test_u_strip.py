"""A U-shaped strip folded shut (``scenes/u_strip.toml``): self-contact of two faces of one body.

The upper arm's corner meets the lower arm while the push holds that corner:
the push's reaction must carry the contact force there. Before, the
reactions were the strain energy's forces alone, and the push read -0.2218
against the base's 2.3956 (the corner's contact force left out). The lower
arm's face (the target, coarser) is not held out of the upper arm's: one of
its nodes lies 1.5 % of h behind it, and the run says so.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from mpi4py import MPI

from fenics_contact import load_scene, run_scene
from fenics_contact.scene.checks import SceneWarning

ROOT = Path(__file__).parents[1]


@pytest.mark.mpi
def test_the_supports_balance_when_a_held_node_is_in_contact(tmp_path_factory):
    comm = MPI.COMM_WORLD
    out = Path(comm.bcast(str(tmp_path_factory.mktemp("u")) if comm.rank == 0 else None))
    with pytest.warns(SceneWarning) as seen:
        outcome = run_scene(load_scene(ROOT / "scenes" / "u_strip.toml"), out / "run",
                            pictures=False)
    assert outcome.path.converged
    comm.barrier()
    steps = json.loads((out / "run" / "summary.json").read_text())["steps"]
    last = steps[-1]
    assert last["contact_force"] == pytest.approx(2.39574, rel=1e-4)
    for step in steps:  # one body, self-contact: the two supports balance
        base, push = step["reactions"]["bottom"][1], step["reactions"]["tip"][1]
        assert base + push == pytest.approx(0.0, abs=1e-8)  # the residual tolerance
    assert last["reactions"]["tip"][1] == pytest.approx(-2.39561, rel=1e-4)
    behind = [str(w.message) for w in seen if "behind the striker surface" in str(w.message)]
    assert len(behind) == 1
    depth = float(re.search(r"lies ([0-9.e-]+) \(", behind[0]).group(1))
    assert depth == pytest.approx(7.27e-4, rel=0.02)
    assert "striker = target: every node is held" in behind[0]


def test_a_failed_step_records_the_converged_state_it_stops_in(tmp_path):
    """A step that fails after a cut-back converged: its record (load factor, reactions)
    is the converged sub-step's, at its own load, and the supports balance. Before, the
    failed attempt's load stayed set and the reactions fell back to the strain energy's
    forces (the held corner's contact left out)."""
    from fenics_contact import build_problem, scene_strategy, solve_load_path
    from fenics_contact.solvers.base import SolveResult
    from fenics_contact.solvers.diagnostics import Status

    scene = load_scene(ROOT / "scenes" / "u_strip.toml")
    problem = build_problem(scene, MPI.COMM_SELF)
    strategy = scene_strategy(scene, problem)
    solve = strategy.solve

    def failing_at_the_end() -> SolveResult:
        result = solve()  # iterates: u and the solver's last residual move on
        if problem.load_factor > 0.99:  # the last step (0.8 -> 1) stops at 0.975
            return SolveResult(Status.CYCLING, result.iterations, 0, result.linear_solves,
                               result.residuals)
        return result

    strategy.solve = failing_at_the_end
    record = solve_load_path(strategy, scene.solver.steps, max_cutbacks=3)
    failed = record.steps[-1]
    assert (failed.status, failed.load_factor) == ("cycling", pytest.approx(0.975))
    assert problem.load_factor == pytest.approx(0.975)
    push = problem.support_reactions()["tip"]
    assert abs(push[1]) > 1.0  # the corner in contact holds the push
    total = problem.support_total()
    assert max(abs(v) for v in total) < 1e-8 * abs(push[1])
