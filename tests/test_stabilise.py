"""Weak springs that hold a body nothing else holds before the load presses it.

Two blocks stacked between a frictionless floor and a press: nothing holds
them in x, so the scene is refused before any work. ``[[body]] stabilise``
ties each body to where it starts by springs of stiffness stabilise E / L^2
per unit volume (L the body's box diagonal); their force is reported as a
support of its own and warned when it is not small. A round seal that only
friction holds once pressed is the case users meet.
"""

from __future__ import annotations

import re
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


CLAMP_GEO = """
a = 0.5; b = 0.5; H = 1.0; np = 4; nj = 5;
Geometry.AutoCoherence = 0;
Point(1) = {0,0,0}; Point(2) = {a,0,0}; Point(3) = {a,H,0}; Point(4) = {0,H,0};
Line(1) = {1,2}; Line(2) = {2,3}; Line(3) = {3,4}; Line(4) = {4,1};
Curve Loop(1) = {1,2,3,4}; Plane Surface(1) = {1};
Point(11) = {a,0,0}; Point(12) = {a+b,0,0}; Point(13) = {a+b,H,0}; Point(14) = {a,H,0};
Line(11) = {11,12}; Line(12) = {12,13}; Line(13) = {13,14}; Line(14) = {14,11};
Curve Loop(11) = {11,12,13,14}; Plane Surface(11) = {11};
Transfinite Curve{1,3} = 3; Transfinite Curve{2,4} = np+1;
Transfinite Curve{11,13} = 3; Transfinite Curve{12,14} = nj+1;
Transfinite Surface{1}; Transfinite Surface{11};
Physical Surface("plug", 1) = {1};
Physical Surface("jaw", 2) = {11};
Physical Curve("plug_axis", 11) = {4};
Physical Curve("plug_flank", 12) = {2};
Physical Curve("plug_top", 13) = {3};
Physical Curve("jaw_face", 21) = {14};
Physical Curve("jaw_back", 22) = {12};
Physical Curve("jaw_bottom", 23) = {11};
"""

CLAMP = """
[scene]
name = "clamp"
dimension = 2

[mesh]
file = "clamp.geo"

[[body]]
name = "plug"
tag = "plug"
law = "linear"
E = 200.0
nu = 0.3
stabilise = 1e-6

[[body]]
name = "jaw"
tag = "jaw"
law = "linear"
E = 200.0
nu = 0.3

[[pair]]
name = "grip"
striker = "jaw_face"
target = "plug_flank"
mu = 0.3

[[dirichlet]]
tag = "plug_axis"
value = [0.0, "free"]

[[dirichlet]]
tag = "jaw_back"
value = [-0.005, "free"]

[[dirichlet]]
tag = "jaw_bottom"
value = ["free", 0.0]

[[traction]]
tag = "plug_top"
value = [0.0, 0.4]

[solver]
steps = 4
max_cutbacks = 1
"""


def test_a_plug_only_springs_hold_is_refused_not_converged(tmp_path, capsys):
    """A plug pulled off its jaw by the first Newton iteration: friction carries nothing.

    Before, every step converged with contact force 0, the springs holding
    the whole pull 0.2 (the plug moved by thousands of its sizes), exit 0
    and a warning of "3019765539.78 %" of a contact force of ~0.
    """
    import json

    from fenics_contact.cli import main

    (tmp_path / "clamp.geo").write_text(CLAMP_GEO)
    (tmp_path / "clamp.toml").write_text(CLAMP)
    out = tmp_path / "out"
    assert main(["run", str(tmp_path / "clamp.toml"), "--out", str(out), "--quiet"]) == 1
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "held_by_springs"
    assert summary["steps_completed"] == 0
    failed = summary["steps"][-1]
    assert failed["status"] == "held_by_springs" and failed["cutbacks"] == 1
    message = failed["message"]
    assert "springs of body 'plug', not the contacts or the supports, hold it" in message
    assert "100.0% of the load (above 0.01)" in message
    moved, size = re.search(r"moved by ([\d.e+-]+), its size being ([\d.e+-]+)",
                            message).groups()
    assert float(moved) > 10 * float(size) and float(size) == pytest.approx(5**0.5 / 2, rel=1e-3)
    assert "smaller first load steps" in message and "a support" in message
    assert "load step 1 of 4 was refused (held by springs" in capsys.readouterr().err


def test_spring_share_is_of_the_load_and_never_above_one(tmp_path):
    """The share is measured against tractions, supports and contacts (at most 100 %)."""
    from fenics_contact.model.springs import spring_loads
    from fenics_contact.scene.build import build_problem

    (tmp_path / "clamp.geo").write_text(CLAMP_GEO)
    (tmp_path / "clamp.toml").write_text(CLAMP)
    problem = build_problem(load_scene(tmp_path / "clamp.toml"))
    problem.set_load(1.0)
    problem.u.x.array[:] = 0.0
    assert [s.share for s in spring_loads(problem)] == [0.0]
    problem.u.x.array.reshape(-1, 2)[:, 1] = 1.0  # every node lifted by 1
    (springs,) = spring_loads(problem)
    k = 1e-6 * 200.0 / (5**0.5 / 2) ** 2  # stabilise E / L^2 over the plug's 0.5 x 1
    assert springs.force == pytest.approx(k * 0.5, rel=1e-12)
    assert springs.moved == pytest.approx(1.0) and springs.size == pytest.approx(5**0.5 / 2)
    # the jaw's strain energy loads its supports; the traction's resultant is 0.4 * 0.5
    assert 0.0 < springs.share <= springs.force / 0.2
