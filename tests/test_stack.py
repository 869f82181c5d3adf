"""Three blocks stacked on a rigid floor and pressed from above (two pairs and an obstacle).

The blocks are alike and slide freely on a symmetry plane, so the exact
answer is uniaxial stress: every interface carries E / (1 - nu^2) * strain
* W. The lower two blocks are held by nothing but the contacts they start
in; the scene check accepts that (each rigid motion of theirs closes some
contact) and refuses the stack without its floor.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mpi4py import MPI

from fenics_contact.runner import run_scene
from fenics_contact.scene.build import build_problem
from fenics_contact.scene.schema import SceneError, load_scene

SCENE = Path(__file__).parent.parent / "scenes" / "stack_3_blocks.toml"
E, NU, STRAIN = 200.0, 0.3, 0.012 / 1.2
EXACT = E / (1 - NU**2) * STRAIN  # per unit thickness, W = 1


def variant(tmp_path: Path, old: str, new: str) -> Path:
    text = SCENE.read_text()
    assert old in text
    path = Path(MPI.COMM_WORLD.bcast(str(tmp_path), root=0)) / "stack.toml"
    if MPI.COMM_WORLD.rank == 0:
        path.write_text(text.replace(old, new).replace(
            '"../meshes/', f'"{SCENE.parent.parent / "meshes"}/'))
    MPI.COMM_WORLD.Barrier()
    return path


@pytest.mark.mpi
def test_every_interface_carries_the_applied_force_with_a_uniform_pressure(tmp_path):
    out = Path(MPI.COMM_WORLD.bcast(str(tmp_path), root=0)) / "out"
    outcome = run_scene(load_scene(SCENE), out, pictures=False)
    assert outcome.path.converged
    states = outcome.problem.contact_states()
    assert list(states) == ["top-on-middle", "middle-on-bottom", "floor"]
    for name, state in states.items():
        assert state.contact_force == pytest.approx(EXACT, rel=1e-10), name
        pressure = np.concatenate(MPI.COMM_WORLD.allgather(state.pressure))
        assert pressure.size == 11 and np.allclose(pressure, -EXACT, rtol=1e-9), name
        assert state.max_penetration < 1e-12, name
    # the force each striker hands to its target's vertices, summed over the two pairs
    # (before 2026-12-02 the written field held the first pair's only: 0 on the bottom block)
    problem = outcome.problem
    force = problem.target_force().x.array.reshape(-1, 2)
    owned = problem.V.dofmap.index_map.size_local
    for body, expected in (("bottom", -EXACT), ("middle", -EXACT), ("top", 0.0)):
        tag = next(b.tag for b in problem.solid.bodies if b.name == body)
        dofs = np.unique(problem.V.dofmap.list[problem.solid.cell_tags.find(tag)].ravel())
        total = MPI.COMM_WORLD.allreduce(force[dofs[dofs < owned]].sum(axis=0))
        assert total == pytest.approx([0.0, expected], abs=1e-9), body


def test_non_matching_interfaces_pass_the_load_down(tmp_path):
    """10, 7 and 5 divisions: node-to-segment is not exact here, the balance is."""
    path = variant(tmp_path, "n_bottom = 10, n_middle = 10, n_top = 10",
                   "n_bottom = 10, n_middle = 7, n_top = 5")
    outcome = run_scene(load_scene(path), tmp_path / "out", comm=MPI.COMM_SELF, pictures=False)
    assert outcome.path.converged
    problem = outcome.problem
    top = problem.solid.prescribed[1].facets
    floor = problem.contact_states()["floor"].contact_force
    # the floor is flat and rigid: its force is vertical and balances the press
    assert -problem.reaction(top)[1] == pytest.approx(floor, rel=1e-10)
    # node-to-segment on non-matching interfaces (measured 0.52 % below the exact value)
    assert floor == pytest.approx(EXACT, rel=1e-2)


def test_a_stack_without_its_floor_is_refused_naming_the_free_block(tmp_path):
    text = SCENE.read_text()
    floor = text[text.index("[[obstacle]]"):text.index("[[dirichlet]]")]
    path = variant(tmp_path, floor, "")
    with pytest.raises(SceneError, match=r"\[\[body\]\] 'bottom' can move rigidly "
                       r"\(translation in y\): no \[\[dirichlet\]\] condition holds that motion"):
        build_problem(load_scene(path), MPI.COMM_SELF)


def test_a_floor_that_the_stack_does_not_touch_is_named(tmp_path):
    """The floor 0.1 below the bottom block: the refusal names the contact open everywhere."""
    path = variant(tmp_path, "point = [0.0, 0.0]", "point = [0.0, -0.1]")
    with pytest.raises(SceneError, match=r"\[\[body\]\] 'bottom' can move rigidly .*the "
                       r"contacts do not hold it at the start \(open everywhere at the start: "
                       r"'floor'\)"):
        build_problem(load_scene(path), MPI.COMM_SELF)


def test_the_block_left_free_is_the_one_named(tmp_path):
    """The symmetry plane kept on the lower and upper blocks only: the middle block, held
    in y by its neighbours, slides in x (before, the message named the bottom block)."""
    path = variant(tmp_path, '[[dirichlet]]\ntag = "symmetry"\nvalue = [0.0, "free"]\n',
                   '[[dirichlet]]\ntag = "symmetry"\ny = [0.0, 0.4]\nvalue = [0.0, "free"]\n'
                   '[[dirichlet]]\ntag = "symmetry"\ny = [0.8, 1.2]\nvalue = [0.0, "free"]\n')
    with pytest.raises(SceneError, match=r"\[\[body\]\] 'middle' can move rigidly "
                       r"\(translation in x\).*on a face of 'middle'"):
        build_problem(load_scene(path), MPI.COMM_SELF)


def test_every_single_free_motion_is_named(tmp_path):
    """The half tube between its plates without its cut: free to slide in x and to turn.

    Both are named; before, one mix of them was (a rotation about (0, -2)).
    """
    from mpi4py import MPI

    from fenics_contact.scene.build import build_problem
    from fenics_contact.scene.schema import SceneError, load_scene

    shipped = Path(__file__).parent.parent / "scenes" / "tube_crush.toml"
    text = shipped.read_text().replace('"../meshes/', f'"{shipped.parent.parent / "meshes"}/')
    path = tmp_path / "tube.toml"
    path.write_text(text.replace('[[dirichlet]]\ntag = "cut"\nvalue = [0.0, "free"]\n', ""))
    with pytest.raises(SceneError, match=r"'tube' can move rigidly \(translation in x and "
                       r"rotation in the x-y plane about \(0, 0\)\)"):
        build_problem(load_scene(path), MPI.COMM_SELF)


def _pressed_by_a_traction(tmp_path, traction: str, symmetry: bool = True):
    """block_on_block with its top pushed by a traction instead of a displacement."""
    from fenics_contact.scene.schema import load_scene

    shipped = Path(__file__).parent.parent / "scenes" / "block_on_block.toml"
    text = shipped.read_text().replace('"../meshes/', f'"{shipped.parent.parent / "meshes"}/')
    text = text.replace('[[dirichlet]]\ntag = "top"\nvalue = ["free", -0.01]\n',
                        f'[[traction]]\ntag = "top"\nvalue = {traction}\n')
    if not symmetry:
        text = text.replace('[[dirichlet]]\ntag = "symmetry"\nvalue = [0.0, "free"]\n', "")
    path = tmp_path / "pushed.toml"
    path.write_text(text + "\n[output]\npictures = false\n")
    return load_scene(path)


def test_a_body_pressed_on_its_partner_by_a_traction_is_held(tmp_path):
    """Force control: the load presses the upper block into the contact that holds it.

    Before, the scene was refused ("can move rigidly (translation in y)"):
    the contact touching at load 0 holds nothing before it is pressed. The
    pressure on the interface is the traction, 2.0 over the width 1.
    """
    from mpi4py import MPI

    from fenics_contact import run_scene

    scene = _pressed_by_a_traction(tmp_path, "[0.0, -2.0]")
    outcome = run_scene(scene, tmp_path / "out", comm=MPI.COMM_SELF)
    assert outcome.path.converged
    assert outcome.path.steps[-1].contact_force == pytest.approx(2.0, rel=1e-10)


@pytest.mark.parametrize(("traction", "symmetry", "free"), [
    ("[0.0, 2.0]", True, "translation in y"),   # pulled off its partner
    ("[0.0, -2.0]", False, "translation in x"),  # pressed, but free to slide sideways
])
def test_a_traction_that_does_not_press_a_body_home_holds_nothing(tmp_path, traction,
                                                                   symmetry, free):
    from mpi4py import MPI

    from fenics_contact.scene.build import build_problem
    from fenics_contact.scene.schema import SceneError

    scene = _pressed_by_a_traction(tmp_path, traction, symmetry)
    with pytest.raises(SceneError, match=rf"can move rigidly .*{free}"):
        build_problem(scene, MPI.COMM_SELF)


def test_a_block_pressed_on_a_rigid_floor_by_a_traction_is_held(tmp_path):
    """One body on a rigid plane, force control: refused before, the floor takes 5 x 1."""
    from mpi4py import MPI

    from fenics_contact import run_scene
    from fenics_contact.scene.schema import load_scene

    path = tmp_path / "floor.toml"
    path.write_text("""[scene]
name = "pressed"
dimension = 2
[mesh]
generator = "rectangle"
origin = [0.0, 0.0]
size = [1.0, 0.5]
cells = [10, 5]
[material]
law = "neo-hookean"
E = 100.0
nu = 0.3
[obstacle]
type = "plane"
point = [0.0, 0.0]
normal = [0.0, 1.0]
[contact]
tag = "bottom"
[[dirichlet]]
tag = "left"
value = [0.0, "free"]
[[traction]]
tag = "top"
value = [0.0, -5.0]
[solver]
method = "gnrm"
steps = 2
[output]
pictures = false
""")
    outcome = run_scene(load_scene(path), tmp_path / "out", comm=MPI.COMM_SELF)
    assert outcome.path.converged
    assert outcome.path.steps[-1].contact_force == pytest.approx(5.0, rel=1e-10)
