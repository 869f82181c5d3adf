"""Scenes with several rigid obstacles: [[obstacle]] blocks, each with its own contact.

The shipped ``block_floor_wall`` scene presses a block onto a floor (mu =
0.5 in the test's variant, frictionless as shipped) by its clamped top; the
block bulges into a wall with friction (mu = 0.2). The checks are the
balance of every force on the body, each contact's own record and fields,
and the Signorini and Coulomb conditions of each contact.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from mpi4py import MPI

from fenics_contact.runner import run_scene
from fenics_contact.scene.build import tagged_facets
from fenics_contact.scene.schema import SceneError, load_scene

SCENE = Path(__file__).parent.parent / "scenes" / "block_floor_wall.toml"
HEAD = SCENE.read_text().split("\n[[obstacle]]\n")[0]
FLOOR = """
[[obstacle]]
name = "floor"
type = "plane"
point = [0.0, 0.0]
normal = [0.0, 1.0]
tag = "bottom"
"""
WALL = """
[[obstacle]]
name = "wall"
type = "plane"
point = [1.03, 0.0]
normal = [-1.0, 0.0]
tag = "right"
mu = 0.2
"""


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "scene.toml"
    path.write_text(text)
    return path


def test_each_obstacle_block_is_read_with_its_contact():
    scene = load_scene(SCENE)
    assert [o.name for o in scene.obstacles] == ["floor", "wall"]
    floor, wall = scene.obstacles
    assert (floor.contact.tag, floor.contact.mu, wall.contact.tag, wall.contact.mu) == (
        "bottom", None, "right", 0.2)
    assert wall.obstacle.point == (1.03, 0.0) and wall.obstacle.normal == (-1.0, 0.0)
    assert scene.obstacle == floor.obstacle and scene.contact == floor.contact
    assert scene.frictional and "stick_slip" in scene.fields


def test_a_single_obstacle_scene_is_one_entry_named_obstacle():
    scene = load_scene(SCENE.parent / "hertz_cylinder.toml")
    assert [o.name for o in scene.obstacles] == ["obstacle"]
    assert scene.obstacles[0].contact == scene.contact


@pytest.mark.parametrize(("text", "message"), [
    (FLOOR + WALL + "\n[contact]\ntag = 'bottom'\n",
     "[contact] goes with a single [obstacle]; with [[obstacle]] blocks give each block its own "
     "contact keys"),
    (FLOOR + FLOOR, "[[obstacle]] names ['floor', 'floor'] repeat"),
    (FLOOR.replace('tag = "bottom"', 'tag = "bottom"\nmue = 0.3'),
     "unknown key 'mue' at [obstacle 'floor']"),
    (FLOOR.replace('tag = "bottom"', 'detect = true\ntag = "bottom"'),
     "[obstacle 'floor'] needs either 'tag'"),
    (FLOOR.replace('tag = "bottom"', 'tag = "bottom"\nr = -1.0'), "[obstacle 'floor'] r = -1.0"),
    (FLOOR.replace('point = [0.0, 0.0]', 'point = [0.0]'), "[obstacle 'floor'] point"),
])
def test_bad_obstacle_blocks_are_named_with_the_fix(tmp_path, text, message):
    with pytest.raises(SceneError) as caught:
        load_scene(write(tmp_path, HEAD + text))
    assert message in str(caught.value)


def test_an_unknown_facet_tag_names_the_obstacle(tmp_path):
    from fenics_contact.scene.build import build_problem

    scene = load_scene(write(tmp_path, HEAD + FLOOR + WALL.replace('"right"', '"rigth"')))
    with pytest.raises(SceneError, match="\\[obstacle 'wall'\\] tag = 'rigth' is not a facet tag"):
        build_problem(scene, MPI.COMM_SELF)


@pytest.fixture(scope="module", params=[None, 0.5], ids=["shipped", "floor-mu0.5"])
def pressed(tmp_path_factory, request):
    """The scene solved as shipped and with friction on the floor too: outcome and folder."""
    folder = tmp_path_factory.mktemp("floor_wall")
    path = folder / "scene.toml"
    floor = FLOOR if request.param is None else FLOOR.replace(
        'tag = "bottom"', f'tag = "bottom"\nmu = {request.param}')
    path.write_text(HEAD + floor + WALL)
    out = folder / "out"
    return run_scene(load_scene(path), out, comm=MPI.COMM_SELF, pictures=False), out


def test_every_force_on_the_block_balances(pressed):
    """Support reaction + both normal forces + both frictions = 0 (measured 1e-13 and 7e-16).

    The bottom right corner is on both surfaces (one shared node): as shipped
    it is pressed on the floor and slides on the wall, whose friction holds it
    vertically like the floor's normal does. Two equal constraint rows: the
    solve sets one aside (null-pivot detection) and converges in 31 Newton
    iterations over 10 steps; without it the first step touching the wall
    diverged with residuals of 1e16.
    """
    outcome, _ = pressed
    problem = outcome.problem
    assert outcome.path.converged
    assert problem.shared_contact_nodes == 1
    assert sum(s.iterations for s in outcome.path.steps) <= 45  # measured 31 and 41
    floor, wall = problem.contacts
    # the support's force at the clamped top plus each contact's force on the block
    from fenics_contact.scene.build import build_mesh

    top = tagged_facets(build_mesh(load_scene(SCENE), MPI.COMM_SELF), load_scene(SCENE),
                        "dirichlet 1", "top")
    reaction = problem.reaction(top)
    states = problem.contact_states()
    on_block = (states["floor"].contact_force * np.array([0.0, 1.0])
                + states["wall"].contact_force * np.array([-1.0, 0.0])
                - wall.friction.tangential_force_vector()[:2])
    if floor.friction is not None:
        on_block -= floor.friction.tangential_force_vector()[:2]
    scale = np.linalg.norm(reaction)
    assert scale > 200.0  # 269 and 330 per unit thickness
    assert np.linalg.norm(reaction + on_block) < 1e-10 * scale


def test_each_contact_has_its_record_and_meets_its_conditions(pressed):
    outcome, out = pressed
    summary = json.loads((out / "summary.json").read_text())
    floor, wall = summary["obstacles"]
    assert (floor["name"], wall["name"], wall["mu"]) == ("floor", "wall", 0.2)
    last = outcome.path.steps[-1]
    assert floor["steps"][-1]["normal_force"] == last.contacts["floor"]["normal_force"]
    assert last.contact_force == pytest.approx(
        floor["steps"][-1]["normal_force"] + wall["steps"][-1]["normal_force"], rel=1e-14)
    # the wall is reached only in the second half of the load path
    touching = [s["active_count"] for s in wall["steps"]]
    assert touching[0] == 0 and touching[-1] > 5
    for contact in (floor, wall):
        assert contact["steps"][-1]["max_penetration"] < 1e-10
    # the block slides down the wall: every pressed node slips there, F_t = mu N
    assert wall["steps"][-1]["stick_count"] == 0
    assert wall["steps"][-1]["tangential_force"] == pytest.approx(
        0.2 * wall["steps"][-1]["normal_force"], rel=1e-8)
    violations = outcome.problem.coulomb_violations()
    assert max(violations) < 1e-8


def test_the_fields_carry_both_contacts(pressed):
    """Pressure on the bottom and on the touching part of the right side; slip at the wall."""
    from fenics_contact.output.render import _read_step, _step_file

    outcome, out = pressed
    grid = _read_step(_step_file(out, None)[0])
    x, y = grid.points[:, 0], grid.points[:, 1]
    p = grid.point_data["contact_pressure"]
    state = grid.point_data["stick_slip"]
    traction = grid.point_data["tangential_traction"]
    bottom, right = np.isclose(y, 0.0), np.isclose(x, 1.0) & ~np.isclose(y, 0.0)
    assert np.all(p[~(bottom | np.isclose(x, 1.0))] == 0.0)  # off both surfaces
    assert np.all(p[bottom] > 0.0)  # the whole bottom presses on the floor
    if outcome.problem.contacts[0].friction is None:  # frictionless: pressed nodes slide
        assert np.all(state[bottom & ~np.isclose(x, 1.0)] == 2)
    pressed_wall = right & (p > 0.0)
    wall = outcome.problem.contacts[1]
    at_corner = np.isclose(wall.nodal_coordinates()[:, 1], 0.0) & wall.contact_state().active
    assert pressed_wall.sum() + at_corner.sum() == (
        outcome.path.steps[-1].contacts["wall"]["active_count"])
    assert np.all(state[pressed_wall] == 2)  # sliding down the wall
    # on the wall the friction on the body is vertical, upward, mu |p| at every pressed node
    assert np.allclose(traction[pressed_wall, 0], 0.0, atol=1e-10)
    assert np.allclose(traction[pressed_wall, 1], 0.2 * p[pressed_wall], rtol=1e-6)


@pytest.mark.mpi
def test_the_shipped_scene_gives_the_serial_forces_on_any_number_of_processes(tmp_path):
    """Serial: floor 262.8430, wall 25.08151 (normal), wall friction 5.016302 = 0.2 N."""
    out = Path(MPI.COMM_WORLD.bcast(str(tmp_path), root=0)) / "out"
    outcome = run_scene(load_scene(SCENE), out, pictures=False)
    assert outcome.path.converged and outcome.problem.shared_contact_nodes == 1
    last = outcome.path.steps[-1].contacts
    assert last["floor"]["normal_force"] == pytest.approx(262.8429772261589, rel=1e-8)
    assert last["wall"]["normal_force"] == pytest.approx(25.08151225633743, rel=1e-8)
    assert last["wall"]["tangential_force"] == pytest.approx(
        0.2 * last["wall"]["normal_force"], rel=1e-8)
    assert (last["floor"]["active_count"], last["wall"]["active_count"]) == (17, 14)


SQUEEZED = """
[scene]
name = "squeezed"
dimension = 2

[mesh]
generator = "rectangle"
size = [1.0, 1.0]
cells = [6, 6]

[material]
law = "linear"
E = 210.0
nu = 0.3

[[dirichlet]]
tag = "left"
value = [0.0, "free"]

[[obstacle]]
name = "floor"
type = "plane"
point = [0.0, 0.0]
normal = [0.0, 1.0]
tag = "bottom"

[[obstacle]]
name = "plate"
type = "plane"
point = [0.0, 1.0]
normal = [0.0, -1.0]
motion = [0.0, -0.01]
tag = "top"
r = 100.0

[solver]
steps = 4
"""


def test_a_body_held_only_by_the_plates_it_touches_is_accepted_and_exact(tmp_path):
    """Nothing but the two plates holds the block vertically: each closes when it moves."""
    outcome = run_scene(load_scene(write(tmp_path, SQUEEZED)), tmp_path / "out",
                        comm=MPI.COMM_SELF, pictures=False)
    assert outcome.path.converged
    exact = 210.0 / (1 - 0.3**2) * 0.01
    for name, state in outcome.problem.contact_states().items():
        assert state.contact_force == pytest.approx(exact, rel=1e-9), name
        assert np.allclose(state.pressure, -exact, rtol=1e-9), name


def test_a_body_that_one_plate_touches_is_refused(tmp_path):
    """Without the floor the plate pushes the block away: nothing holds it."""
    text = SQUEEZED[:SQUEEZED.index('[[obstacle]]\nname = "floor"')] + SQUEEZED[
        SQUEEZED.index('[[obstacle]]\nname = "plate"'):]
    from fenics_contact.scene.build import build_problem

    with pytest.raises(SceneError, match=r"leave rigid motions of the body free \(translation "
                       r"in y\); contact does not hold them"):
        build_problem(load_scene(write(tmp_path, text)), MPI.COMM_SELF)
