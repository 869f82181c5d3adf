"""A cylinder squeezed between two rigid plates presses a second cylinder beside it.

Two obstacles and one node-to-segment pair among two bodies
(``scenes/cylinder_between_plates.toml``, run as shipped: h = 0.005 at the
contacts). The load is small (a/R ~ 0.057, linear law), so each plate
contact is Hertz line contact of a cylinder on a rigid plane; the forces on
each body balance to round-off.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mpi4py import MPI

from fenics_contact.references.hertz import (
    fit_contact_profile,
    hertz_line_contact,
    relative_error,
)
from fenics_contact.runner import run_scene
from fenics_contact.scene.schema import load_scene

SCENE = Path(__file__).parent.parent / "scenes" / "cylinder_between_plates.toml"
R, E, NU = 1.0, 200.0, 0.3


@pytest.fixture(scope="module")
def squeezed(tmp_path_factory):
    scene = load_scene(SCENE)
    outcome = run_scene(scene, tmp_path_factory.mktemp("cbp") / "out", comm=MPI.COMM_SELF,
                        pictures=False)
    return scene, outcome


def _axis_facets(problem, scene, name: str) -> np.ndarray:
    """Facets of the [[dirichlet]] on ``name`` (the solid keeps the scene's order)."""
    index = [d.tag for d in scene.dirichlet].index(name)
    return problem.solid.prescribed[index].facets


def test_every_force_on_each_cylinder_balances(squeezed):
    """Left: both plates, the pair and the axis; right: the pair and its axis (to 1e-10)."""
    scene, outcome = squeezed
    assert outcome.path.converged
    problem = outcome.problem
    states = problem.contact_states()
    assert list(states) == ["side", "floor", "press"]
    side = problem.contacts[0]
    n = problem.V.dofmap.index_map.size_local
    on_target = side.target_force().x.array[: 2 * n].reshape(-1, 2).sum(axis=0)
    right_axis = problem.reaction(_axis_facets(problem, scene, "right_axis"))
    left_axis = problem.reaction(_axis_facets(problem, scene, "left_axis"))
    floor, press = states["floor"].contact_force, states["press"].contact_force
    scale = press
    # right cylinder: held along its diameter, pushed by the left one (+x)
    assert on_target[0] > 0.04 * press
    assert np.allclose(right_axis + on_target, 0.0, rtol=0, atol=1e-10 * scale)
    # left cylinder: ux = 0 on its diameter (x reaction only), plates (y), the pair
    assert abs(left_axis[0] - on_target[0]) <= 1e-10 * scale
    assert abs(floor - press - on_target[1]) <= 1e-10 * scale
    # the pair's normal force is the push the right cylinder takes (facet tilt aside)
    assert states["side"].contact_force == pytest.approx(np.hypot(*on_target), rel=1e-3)
    assert states["side"].active_count >= 3 and states["side"].max_penetration < 1e-12


@pytest.mark.parametrize("plate", ["floor", "press"])
def test_each_plate_contact_is_hertz_line_contact(squeezed, plate):
    """Fitted half-width and peak within 2 % of Hertz (measured -0.42 % and +0.20 %)."""
    _, outcome = squeezed
    contact = next(c for c in outcome.problem.contacts if c.name == plate)
    state = contact.contact_state()
    x = contact.nodal_coordinates()[:, 0]
    fit = fit_contact_profile(x, state.pressure)
    hertz = hertz_line_contact(state.contact_force, R, E, NU)
    assert 0.04 < hertz.a / R < 0.08 and fit.n_contact >= 15
    assert abs(relative_error(fit.a, hertz.a)) < 0.02
    assert abs(relative_error(fit.p0, hertz.p0)) < 0.02
    assert abs(relative_error(fit.nodal_peak, hertz.p0)) < 0.02
    assert state.max_penetration < 1e-12
    # the test can fail: the same pressures against twice the load miss by far
    wrong = hertz_line_contact(2 * state.contact_force, R, E, NU)
    assert abs(relative_error(fit.a, wrong.a)) > 0.2


def test_the_pair_is_reported(squeezed):
    """summary.json lists the pair with its force at every step, growing with the press."""
    _, outcome = squeezed
    (pair,) = outcome.summary["pairs"]
    assert (pair["name"], pair["striker"], pair["target"]) == ("side", "left_side", "right_side")
    forces = [s["normal_force"] for s in pair["steps"]]
    assert len(forces) == 3 and 0 < forces[0] < forces[1] < forces[2]
    last = outcome.summary["steps"][-1]["contacts"]
    assert last["side"]["normal_force"] == pytest.approx(forces[-1], rel=1e-12)
    assert last["side"]["active_count"] >= 3
    assert set(last) == {"side", "floor", "press"}
