"""Weak springs that hold a body nothing else holds before the load presses it.

Two blocks stacked between a frictionless floor and a press: nothing holds
them in x, so the scene is refused before any work. ``[[body]] stabilise``
ties each body to where it starts by springs of stiffness stabilise E / L^2
per unit volume (L the body's box diagonal); their force is reported as a
support of its own and warned when it is not small. A round seal that only
friction holds once pressed is the case users meet.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

from fenics_contact.runner import run_scene
from fenics_contact.scene.checks import SceneWarning
from fenics_contact.scene.schema import SceneError, load_scene

ROOT = Path(__file__).resolve().parents[1]
#: Plane strain, free lateral expansion, strain 0.01 over a width of 1.
UNIAXIAL = 200.0 / (1 - 0.3**2) * 0.01

STACK = """
[scene]
name = "stack-between-plates"
dimension = 2

[mesh]
file = "{mesh}"
parameters = {{ n_upper = 8, n_lower = 8 }}

[[body]]
name = "upper"
tag = "striker"
law = "linear"
E = 200.0
nu = 0.3
{stabilise}
[[body]]
name = "lower"
tag = "target"
law = "linear"
E = 200.0
nu = 0.3
{stabilise}
[[pair]]
name = "interface"
striker = "striker_face"
target = "target_face"

[[obstacle]]
name = "floor"
type = "plane"
point = [0.0, 0.0]
normal = [0.0, 1.0]
tag = "bottom"

[[obstacle]]
name = "press"
type = "plane"
point = [0.0, 1.0]
normal = [0.0, -1.0]
motion = [0.0, -0.01]
tag = "top"

[solver]
steps = 2
"""


def _scene(tmp_path, stabilise: str):
    path = tmp_path / "stack.toml"
    path.write_text(STACK.format(mesh=ROOT / "meshes" / "block_on_block.geo",
                                 stabilise=stabilise))
    return load_scene(path)


def test_a_stack_nothing_holds_sideways_is_refused_and_told_of_stabilise(tmp_path):
    from fenics_contact.scene.build import build_problem

    with pytest.raises(SceneError, match="translation in x") as err:
        build_problem(_scene(tmp_path, ""))
    assert "stabilise = 1e-6" in str(err.value)


def test_stabilised_bodies_give_the_uniaxial_force_and_report_their_springs(tmp_path):
    """Springs of 1e-6 E / L^2: the force is the uniaxial one to 1e-6 (2.5e-7 measured)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", SceneWarning)
        outcome = run_scene(_scene(tmp_path, "stabilise = 1e-6"), tmp_path / "out",
                            pictures=False)
    assert outcome.path.converged
    last = outcome.path.steps[-1]
    forces = {name: c["normal_force"] for name, c in last.contacts.items()}
    for name in ("interface", "floor", "press"):
        assert forces[name] == pytest.approx(UNIAXIAL, rel=1e-6)
    springs = [last.reactions[f"stabilise {b}"] for b in ("upper", "lower")]
    assert all(0.0 < abs(f[1]) < 1e-6 * UNIAXIAL for f in springs)
    # the press, the floor and the springs balance
    assert abs(forces["press"] - forces["floor"] - sum(f[1] for f in springs)) < 1e-12


def test_stabilise_key_errors(tmp_path):
    with pytest.raises(SceneError, match="stabilise") as err:
        _scene(tmp_path, "stabilise = 0.1")
    assert "at most 1e-3" in str(err.value)
