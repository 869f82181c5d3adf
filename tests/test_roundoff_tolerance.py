"""An atol below the round-off of a scene's forces is warned before the solve and named after it.

The complementarity rows r g A are formed from coordinates: their round-off
is eps r g_scale ||A|| (r ~ E/h), so an absolute atol that suits E = 200
lies below it for steel in Pa, and Newton stalls above it until it fails.
"""

from __future__ import annotations

import warnings

import pytest

from fenics_contact import build_problem, load_scene, scene_strategy, solve_load_path
from fenics_contact.cli import main
from fenics_contact.scene.checks import SceneWarning
from fenics_contact.solvers.diagnostics import ROUNDOFF_STALL, roundoff_stall
from fenics_contact.solvers.stepping import RAISE_TOLERANCE

BLOCK = """
[scene]
name = "block"
dimension = 2
[mesh]
generator = "rectangle"
size = [2.0, 1.0]
cells = [8, 4]
[material]
law = "neo-hookean"
E = {E}
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
[[dirichlet]]
tag = "top"
value = ["free", -1e-3]
[solver]
steps = 1
max_cutbacks = 0
max_iterations = 30
{atol}
"""


def _scene(tmp_path, E: float, atol: str = "atol = 1e-8"):
    path = tmp_path / "block.toml"
    path.write_text(BLOCK.format(E=E, atol=atol))
    return path


def _warned(path) -> list[str]:
    scene = load_scene(path)
    problem = build_problem(scene)
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always", SceneWarning)
        scene_strategy(scene, problem)
    return [str(w.message) for w in seen if issubclass(w.category, SceneWarning)]


def test_an_atol_below_round_off_is_warned_before_the_solve(tmp_path):
    (said,) = [m for m in _warned(_scene(tmp_path, 2.1e11)) if "round-off" in m]
    assert "atol = 1e-08 lies below the round-off" in said
    assert "Raise atol to about 0.05" in said  # the default: 1e-12 E h^(d-1), h = 0.25
    assert "leave it out" in said


@pytest.mark.parametrize("E, atol", [(200.0, "atol = 1e-8"), (2.1e11, "")])
def test_no_round_off_warning_where_atol_is_above_it(tmp_path, E, atol):
    assert not [m for m in _warned(_scene(tmp_path, E, atol)) if "round-off" in m]


def test_a_stall_at_round_off_is_named_with_the_atol_to_use(tmp_path, capsys):
    """Steel in Pa (E h^(d-1) = 5e10), atol = 1e-8, no rtol: stalled at 1e-5-6e-5, cycling.

    The failure says first that the residual stalled at round-off and which
    atol ends it; the CLI's advice is then only that atol, not another method.
    """
    path = _scene(tmp_path, 2.1e11, "atol = 1e-8\nrtol = 0.0")
    scene = load_scene(path)
    problem = build_problem(scene)
    record = solve_load_path(scene_strategy(scene, problem), scene.solver.steps,
                             max_cutbacks=scene.solver.max_cutbacks)
    assert record.status == "cycling"
    assert record.steps[-1].message.startswith(
        "cycling at load factor 1 after 1 attempt, no cut-back; the residual stalls at")
    assert ROUNDOFF_STALL in record.message
    assert record.message.endswith(f"{RAISE_TOLERANCE} 0.05")  # not where it is set
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--no-pictures"]) == 1
    err = capsys.readouterr().err
    assert "first a larger [solver] atol" in err and 'method = "auto"' not in err
    assert "(or leave atol out of the scene: the default follows E)" in err


def test_a_left_out_atol_converges_where_the_given_one_stalls(tmp_path):
    scene = load_scene(_scene(tmp_path, 2e9, atol=""))
    problem = build_problem(scene)
    record = solve_load_path(scene_strategy(scene, problem), scene.solver.steps,
                             max_cutbacks=scene.solver.max_cutbacks)
    assert record.converged and record.iterations <= 5


def test_round_off_stall_needs_a_flat_residual_below_the_floor():
    flat = [1.0, 1e-3, 4e-10, 5e-10, 3e-10, 6e-10, 4e-10, 5e-10, 4e-10, 3e-10, 5e-10]
    assert roundoff_stall(flat, 1e-8) == pytest.approx(4.5e-10)
    assert roundoff_stall(flat, 5e-10) is None  # above the floor: not round-off
    falling = [1.0, 1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10]
    assert roundoff_stall(falling, 1.0) is None  # still falling
    assert roundoff_stall(flat[:8], 1e-8) is None  # too few iterations to tell
