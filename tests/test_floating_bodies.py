"""A converged step whose bodies nothing holds is refused, not reported as converged.

The scene: the three blocks of ``stack_3_blocks`` (half model, each block on
the symmetry plane x = 0, free in y) pressed by a rigid ball from above onto
a rigid floor; the lower two blocks are held in y by the contacts alone.
SUA at r = 1e-3 E/h lost every contact in the first step, and the singular
solve threw the stack through the ball: "converged" with a contact force of
1.7e-12 and every gap open (GNRM: 0.7931 on every interface). A state is now
accepted only when each rigid motion of each body is held by a support or
moves a contact node closed in that state (active or touching; a sticking
node holds its slip too).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from dolfinx import mesh

from mpi4py import MPI

from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.friction import FrictionSettings
from fenics_contact.model.materials import material
from fenics_contact.model.obstacles import RigidPlane
from fenics_contact.model.problem import PrescribedDisplacement, one_body_problem
from fenics_contact.model.rigid import AssemblyModes
from fenics_contact.runner import run_scene
from fenics_contact.scene.schema import load_scene
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.stepping import solve_load_path

SCENE = Path(__file__).parent.parent / "scenes" / "stack_3_blocks.toml"
PLATE = '[[dirichlet]]\ntag = "top"\nvalue = ["free", -0.012]\n'
BALL = ('[[obstacle]]\nname = "ball"\ntype = "ball"\ncentre = [0.0, 1.7]\nradius = 0.5\n'
        'motion = [0.0, -0.02]\ntag = "top"\nr = 1e-3\n\n')


def ball_stack(tmp_path: Path, method: str) -> Path:
    """The three-block stack pressed by a ball moving down 0.02, r = 1e-3 E/h everywhere."""
    text = SCENE.read_text()
    assert PLATE in text and "atol = 1e-10" in text
    text = (text.replace(PLATE, "").replace("[[obstacle]]\n", BALL + "[[obstacle]]\n", 1)
            .replace('tag = "floor_face"\n', 'tag = "floor_face"\nr = 1e-3\n')
            .replace('target = "middle_topside"\n', 'target = "middle_topside"\nr = 1e-3\n')
            .replace('target = "bottom_topside"\n', 'target = "bottom_topside"\nr = 1e-3\n')
            .replace('method = "gnrm"', f'method = "{method}"\nmax_cutbacks = 1')
            .replace("atol = 1e-10", "")
            .replace('"../meshes/', f'"{SCENE.parent.parent / "meshes"}/'))
    path = Path(MPI.COMM_WORLD.bcast(str(tmp_path), root=0)) / f"ball_{method}.toml"
    if MPI.COMM_WORLD.rank == 0:
        path.write_text(text)
    MPI.COMM_WORLD.Barrier()
    return path


def _run(tmp_path: Path, method: str):
    path = ball_stack(tmp_path, method)
    return run_scene(load_scene(path), path.parent / f"out_{method}", pictures=False)


@pytest.mark.mpi
def test_sua_that_loses_every_contact_is_refused_naming_the_free_bodies(tmp_path):
    outcome = _run(tmp_path, "sua")
    run = outcome.path
    # before: "converged", contact force 1.7e-12, the stack thrown through the ball
    assert run.status != "converged" and run.steps_completed == 0
    message = run.message
    assert "the residual met its tolerance but the iterate was refused: a rigid motion is " \
           "held by nothing (body 'bottom': translation in y; body 'middle': translation in " \
           "y; body 'top': translation in y)" in message
    # the state left behind is the start, which the contacts hold
    assert np.all(outcome.problem.u.x.array == 0.0)
    assert outcome.problem.unheld_motion(1e-6) == []


@pytest.mark.mpi
def test_held_states_are_accepted_gnrm_and_penalty(tmp_path):
    gnrm = _run(tmp_path, "gnrm")
    assert gnrm.path.converged
    forces = {k: s.contact_force for k, s in gnrm.problem.contact_states().items()}
    assert list(forces) == ["top-on-middle", "middle-on-bottom", "ball", "floor"]
    # each interface passes the ball's force down (node-to-segment: 4e-5 apart)
    for name, force in forces.items():
        assert force == pytest.approx(0.79313, rel=1e-4), name
    # the penalty method holds by its penetrating nodes (0.16 h deep at r = 1e-3 E/h)
    penalty = _run(tmp_path, "penalty")
    assert penalty.path.converged
    forces = {k: s.contact_force for k, s in penalty.problem.contact_states().items()}
    # each interface and the floor pass the ball's force down (before 2026-12-02 the
    # predictor's multiplier stayed in the penalty's reported forces: 0.0091835 in all)
    for name in ("top-on-middle", "middle-on-bottom", "floor"):
        assert forces[name] == pytest.approx(0.0026858, rel=1e-4), name
        assert forces[name] == pytest.approx(forces["floor"], rel=1e-8), name
    assert penalty.path.max_penetration == pytest.approx(0.0158, rel=1e-2)


@pytest.mark.mpi
def test_the_check_reads_the_state_and_puts_u_back(tmp_path):
    problem = _run(tmp_path, "gnrm").problem
    u = problem.u.x.array.copy()
    assert problem.unheld_motion(1e-6) == []
    # every block lifted by 3 with no pressure left: every gap open, the stack floats
    problem.u.x.array.reshape(-1, 2)[:, 1] += 3.0
    for lam in problem.normal_multipliers():
        lam.x.array[:] = 0.0
    lifted = problem.u.x.array.copy()
    assert problem.unheld_motion(1e-6) == [
        ("bottom", "translation in y"), ("middle", "translation in y"),
        ("top", "translation in y")]
    assert np.array_equal(problem.u.x.array, lifted)
    problem.u.x.array[:] = u
    for lam in problem.normal_multipliers():  # the pressures alone hold it: active nodes
        lam.x.array[:] = -1.0
    problem.u.x.array.reshape(-1, 2)[:, 1] += 3.0
    assert problem.unheld_motion(1e-6) == []


def _pressed_block(mu: float | None):
    """A 1 x 0.5 block on a floor, its top pushed down 0.01 and free in x: friction alone
    holds it along the floor."""
    domain = mesh.create_rectangle(MPI.COMM_WORLD, [[0.0, 0.0], [1.0, 0.5]], [8, 4])
    bottom = mesh.locate_entities_boundary(domain, 1, lambda x: np.isclose(x[1], 0.0))
    top = mesh.locate_entities_boundary(domain, 1, lambda x: np.isclose(x[1], 0.5))
    return one_body_problem(
        domain, material("linear", 100.0, 0.3), RigidPlane(domain, (0.0, 0.0), (0.0, 1.0)),
        bottom, ContactSettings(r=1.0), prescribed=[PrescribedDisplacement(top, (None, -0.01))],
        friction=None if mu is None else FrictionSettings(mu))


@pytest.mark.mpi
def test_sticking_friction_holds_and_a_frictionless_floor_does_not():
    sticking = _pressed_block(0.5)
    run = solve_load_path(make_strategy("gnrm", sticking, SolverSettings()), 2, max_cutbacks=1)
    assert run.converged
    state = sticking.contact_state()
    assert state.contact_force == pytest.approx(2.3396291, rel=1e-6)
    assert state.stick_count == 8 and state.slip_count == 1
    # frictionless, nothing holds x (before: "converged", force E/(1 - nu^2) 0.02 = 2.1978)
    sliding = _pressed_block(None)
    run = solve_load_path(make_strategy("gnrm", sliding, SolverSettings()), 2, max_cutbacks=1)
    assert run.status != "converged" and run.steps_completed == 0
    assert "held by nothing (body 'body': translation in x)" in run.message


def test_two_sided_holds_leave_only_the_motion_along_the_contact():
    """A square resting on y = 0, no support: its bottom nodes' gaps (y + u_y)."""
    domain = mesh.create_unit_square(MPI.COMM_SELF, 4, 4)
    cells = np.arange(domain.topology.index_map(2).size_local, dtype=np.int32)
    modes = AssemblyModes(domain, [("square", cells)], [])
    x = domain.geometry.x
    bottom = np.flatnonzero(np.isclose(x[:, 1], 0.0))

    def gaps(u: np.ndarray) -> np.ndarray:
        return x[bottom, 1] + u[bottom, 1]

    # at the start the gaps are closed one way: lifting off is free, and so is the slide
    assert modes.free_motion(gaps) == [("square", "translation in x and translation in y")]
    z = np.zeros((x.shape[0], 2))
    # closed in a state (both ways): only the slide along the floor
    assert modes.free_motion(gaps, z, lambda g: np.ones(g.size, bool)) == [
        ("square", "translation in x")]
    # one node closed, at x = 0.75: the square may also turn about a point above it
    one = np.isclose(x[bottom, 0], 0.75)
    assert modes.free_motion(gaps, z, lambda g: one) == [
        ("square", "translation in x and rotation in the x-y plane about (0.75, 0.5)")]


def test_a_body_held_by_a_mortar_pair_touching_at_a_point_is_held(tmp_path):
    """Two cylinders, the lower one on a rigid floor: only the upper holds it from above.

    A mortar pair's weighted gap at the point where two curved surfaces touch
    is the gap's mean over the node's support, h^2 / 12 R (about 3e-3 h here), not
    0: the start check took the pair for open and refused the lower cylinder
    as free to rise (a user's indenter on a block, 0.014 h, the same). Now the
    pair's touching node counts as closed, and the run converges with the
    floor carrying the pair's force.
    """
    root = Path(__file__).parent.parent
    text = (root / "scenes" / "two_cylinders.toml").read_text()
    bottom = '[[dirichlet]]\ntag = "bottom"\nvalue = [0.0, 0.0]\n'
    assert bottom in text
    text = text.replace(bottom, '[[dirichlet]]\ntag = "bottom"\nvalue = [0.0, "free"]\n\n'
                        '[[obstacle]]\nname = "floor"\ntype = "plane"\npoint = [0.0, -1.0]\n'
                        'normal = [0.0, 1.0]\ntag = "bottom"\n')
    assert "h_contact = 0.005" in text
    text = text.replace("h_contact = 0.005", "h_contact = 0.02").replace("steps = 10",
                                                                         "steps = 2")
    text = text.replace('"../meshes/', f'"{root / "meshes"}/')
    path = tmp_path / "on_floor.toml"
    path.write_text(text)
    outcome = run_scene(load_scene(path), tmp_path / "out", pictures=False)
    assert outcome.path.converged
    forces = {k: s.contact_force for k, s in outcome.problem.contact_states().items()}
    assert forces["floor"] == pytest.approx(forces["arcs"], rel=1e-3)
    assert forces["arcs"] > 0.5
