"""The public API: every advertised name resolves, and the README's Python example runs."""

from __future__ import annotations

import pytest

import fenics_contact
from fenics_contact.references.measure import measure_hertz


@pytest.mark.parametrize("name", fenics_contact.__all__)
def test_public_name_resolves(name):
    assert getattr(fenics_contact, name) is not None


def test_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'nonsense'"):
        fenics_contact.nonsense  # noqa: B018


def test_readme_python_example_matches_hertz_and_the_command_line(tmp_path):
    """load_scene, build_problem, scene_strategy, solve_load_path on the shipped Hertz scene.

    The scene's own strategy: the iterations and the force of ``fenics-contact run``.
    """
    from pathlib import Path

    from fenics_contact import build_problem, load_scene, run_scene, scene_strategy, solve_load_path

    scene = load_scene(Path(__file__).parents[1] / "scenes" / "hertz_cylinder.toml")
    problem = build_problem(scene)
    strategy = scene_strategy(scene, problem)
    record = solve_load_path(strategy, scene.solver.steps)
    assert record.converged and record.method == scene.solver.method
    assert record.steps_completed == scene.solver.steps
    assert record.max_penetration < 1e-12
    # the same geometry as the hertz_cylinder validation case: Hertz to mesh accuracy
    comparison = measure_hertz(problem, 1.0, 200.0, 0.3)
    assert abs(comparison.a_error) < 0.01 and abs(comparison.p0_error) < 0.01
    # the command line's run of the scene: the same Newton iterations and force
    cli = run_scene(scene, tmp_path / "out", pictures=False).path
    assert [s.iterations for s in record.steps] == [s.iterations for s in cli.steps]
    assert record.contact_force == pytest.approx(cli.contact_force, rel=1e-12)
    # the support's reaction carries the contact force (a flat obstacle: normal = resultant)
    (top,) = problem.support_reactions().values()
    assert top[1] == pytest.approx(-record.contact_force, rel=1e-10)
    assert abs(top[0]) < 1e-10 * record.contact_force


SI_BLOCK = """
[scene]
name = "si-block"
dimension = 2
[mesh]
generator = "rectangle"
size = [2.0, 1.0]
cells = [8, 4]
[material]
law = "neo-hookean"
E = 2.1e11
nu = 0.3
[[dirichlet]]
tag = "top"
value = ["free", -1e-3]
[[dirichlet]]
tag = "left"
value = [0.0, "free"]
[obstacle]
type = "plane"
point = [0.0, 0.0]
normal = [0.0, 1.0]
[contact]
tag = "bottom"
[solver]
method = "gnrm"
steps = 2
"""


def test_python_route_uses_the_runs_default_atol(tmp_path):
    """A scene without atol, steel in Pa: scene_strategy and run_scene stop alike.

    The run raised the left-out atol to 1e-12 E h^(d-1) and converged in 3
    iterations (F = 4.619e8); the Python route kept 1e-8, below the round-off
    of these forces, and cycled for 187 iterations.
    """
    from fenics_contact import build_problem, load_scene, run_scene, scene_strategy, solve_load_path

    path = tmp_path / "si.toml"
    path.write_text(SI_BLOCK)
    scene = load_scene(path)
    assert not scene.solver.atol_given
    problem = build_problem(scene)
    strategy = scene_strategy(scene, problem)
    assert strategy.settings.atol > 1e-8
    record = solve_load_path(strategy, scene.solver.steps)
    cli = run_scene(scene, tmp_path / "out", pictures=False).path
    assert record.converged and cli.converged
    assert [s.iterations for s in record.steps] == [s.iterations for s in cli.steps]
    assert record.contact_force == cli.contact_force
