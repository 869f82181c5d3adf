"""A load step that carries a small rigid ball into a body is refused, not "converged".

A ball's gap |x - c| - R is positive on both sides: pressed 0.15 in one step
(its radius 0.1, the block's top at 0.5, the centre from 0.6 to 0.45), the
first iterate put the ball's centre inside the block, and Newton settled on
a state with the ball half through the top: "converged", contact force
2.93. The iterate is now refused and the cut-backs find the answer of eight
steps, 15.2005.
"""

from __future__ import annotations

import numpy as np
import pytest

from mpi4py import MPI

from fenics_contact import load_scene, run_scene
from fenics_contact.model.passage import points_inside

SCENE = """[scene]
name = "ball"
dimension = 2
[mesh]
generator = "rectangle"
origin = [0.0, 0.0]
size = [1.0, 0.5]
cells = [20, 10]
[material]
law = "neo-hookean"
E = 100.0
nu = 0.3
[obstacle]
type = "ball"
centre = [0.5, 0.6]
radius = 0.1
motion = [0.0, -0.15]
[contact]
tag = "top"
[[dirichlet]]
tag = "bottom"
value = [0.0, 0.0]
[solver]
method = "gnrm"
steps = {steps}
[output]
pictures = false
"""


def _run(tmp_path, steps: int):
    path = tmp_path / f"ball{steps}.toml"
    path.write_text(SCENE.replace("{steps}", str(steps)))
    outcome = run_scene(load_scene(path), tmp_path / f"out{steps}", comm=MPI.COMM_SELF)
    assert outcome.path.converged
    return outcome


def test_one_step_through_a_small_ball_gives_the_answer_of_eight(tmp_path):
    one, eight = _run(tmp_path, 1), _run(tmp_path, 8)
    force = one.path.steps[-1].contact_force
    assert force == pytest.approx(eight.path.steps[-1].contact_force, rel=1e-6)
    assert force > 15.0  # 15.2005; the ball half through the top read 2.93
    assert one.path.steps[-1].cutbacks >= 1
    assert one.problem.balls_passed_through() == []


def test_a_point_inside_the_deformed_body_is_found(tmp_path):
    outcome = _run(tmp_path, 8)
    problem = outcome.problem
    # the ball's centre sits above the dent; the block's middle is inside
    points = np.array([[0.5, 0.45], [0.5, 0.25], [2.0, 0.25]])
    assert points_inside(problem.V, problem.u, points).tolist() == [False, True, False]
