"""Interference fits: surfaces meshed inside each other, resolved along the load path.

``scenes/shrink_fit.toml``: a ring (b = 1, c = 2) shrunk onto a disk of
radius b + 0.01, a quarter of each, plane strain, equal linear materials,
non-matching rims (80 and 61 arcs), mortar. Lame's fit pressure is
p = E delta (c^2 - b^2) / (2 (1 - nu^2) b c^2) = 0.82418; with
``interference_until = 1`` the overlap allowed at load factor t is
(1 - t) delta, so the problem being linear, every step carries t p.
Measured: the mean nodal pressure 0.3929 % above Lame (the polygons'
chords), each step t times the last to 6.5e-6 (the gaps follow the
deformed geometry), the same final state as the
overlap resolved at once (4e-12). Node-to-segment starts 0.06 deep, 2.3
to 3 facet sizes: -0.019 %; mortar is refused there (its segment search
does not reach).
"""

from __future__ import annotations

import dataclasses
import tomllib
from pathlib import Path

import numpy as np
import pytest

from fenics_contact import build_problem, scene_strategy, solve_load_path
from fenics_contact.scene.checks import SceneWarning
from fenics_contact.scene.schema import scene_from_data
from fenics_contact.scene.spec import SceneError

SCENE = Path(__file__).parents[1] / "scenes" / "shrink_fit.toml"
E, NU, B, C = 200.0, 0.3, 1.0, 2.0


def _lame(delta: float) -> float:
    """Plane-strain fit pressure of equal materials (stress)."""
    return E * delta * (C**2 - B**2) / (2 * (1 - NU**2) * B * C**2)


def _scene(**pair):
    data = tomllib.loads(SCENE.read_text())
    data["pair"][0].update(pair)
    for key in [k for k, v in pair.items() if v is None]:
        del data["pair"][0][key]
    delta = pair.pop("delta", None)
    if delta is not None:
        data["mesh"]["parameters"]["delta"] = delta
        del data["pair"][0]["delta"]
    return scene_from_data(data, SCENE)


def _mean_pressures(scene) -> tuple[list[float], np.ndarray]:
    """(mean nodal pressure of each load step, the last step's nodal pressures)."""
    problem = build_problem(scene)
    means = []

    def measured(step) -> None:
        p = -np.concatenate(problem.comm.allgather(problem.contact_state().pressure))
        means.append(float(np.mean(p)))

    path = solve_load_path(scene_strategy(scene, problem), scene.solver.steps, on_step=measured)
    assert path.converged
    return means, -problem.contact_state().pressure


@pytest.mark.mpi
def test_a_shrink_fit_carries_lames_pressure_in_proportion_at_every_step():
    means, last = _mean_pressures(_scene())
    p = _lame(0.01)
    assert means[-1] == pytest.approx(p, rel=5e-3)  # measured +0.39 % (chords)
    for t, mean in zip((0.25, 0.5, 0.75, 1.0), means, strict=True):
        assert mean == pytest.approx(t * means[-1], rel=1e-4)  # the moving geometry: 6.5e-6
    assert np.all(last > 0.9 * p) and np.all(last < 1.1 * p)  # every node carries it
    with pytest.warns(SceneWarning, match="the first load step pushes them apart"):
        once, _ = _mean_pressures(_scene(interference_until=None))  # resolved at once
    assert once[-1] == pytest.approx(means[-1], rel=1e-9)
    assert once[0] == pytest.approx(means[-1], rel=1e-9)  # the first step already


def test_node_to_segment_fits_start_deeper_than_a_facet():
    means, _ = _mean_pressures(_scene(delta=0.06, discretisation="node-to-segment"))
    assert means[-1] == pytest.approx(_lame(0.06), rel=1e-3)  # measured -0.019 %
    with pytest.raises(SceneError, match=r"more than the striker facet size .*give the pair "
                       r"interference_until"):
        build_problem(_scene(delta=0.06, discretisation="node-to-segment",
                             interference_until=None))


def test_a_mortar_fit_deeper_than_its_search_reaches_is_refused():
    with pytest.raises(SceneError, match=r"start 0.06 inside each other .*deeper than a mortar "
                       r"interference fit may start \(0.0386.*discretisation = "
                       r"\"node-to-segment\""):
        build_problem(_scene(delta=0.06))


def test_a_fit_key_on_surfaces_that_start_apart_is_named():
    """A clearance of 0.01 instead of an interference: the key does nothing, and says so."""
    with pytest.warns(SceneWarning, match=r"\[\[pair\]\] 'fit' gives interference_until, "
                      r"but its surfaces start apart"):
        build_problem(_scene(delta=-0.01))


def test_friction_waits_for_the_fit_to_close():
    """mu = 0.3 on the fit: off while it closes (the same state as frictionless), on after.

    The closing motion is normal to the rims, but across faceted surfaces it
    reads as slip: a user's frictional fit came out asymmetric by 4 % between
    the two cuts, 82 of 122 nodes slipping. Friction now acts from the
    assembled state.
    """
    means, last = _mean_pressures(_scene(mu=0.3, interference_until=0.5,
                                         discretisation="node-to-segment"))
    plain, plain_last = _mean_pressures(_scene(interference_until=0.5,
                                               discretisation="node-to-segment"))
    assert means == pytest.approx(plain, rel=1e-9)
    assert np.allclose(last, plain_last, rtol=1e-6)  # Newton tolerance (1e-8 measured)


def test_a_frictional_fit_whose_steps_jump_past_its_end_is_warned():
    """interference_until = 0.5 in 3 steps: the second one closes the fit with friction on."""
    scene = _scene(mu=0.3, interference_until=0.5, discretisation="node-to-segment")
    scene = dataclasses.replace(scene, solver=dataclasses.replace(scene.solver, steps=3))
    with pytest.warns(SceneWarning, match=r"no load step ends at interference_until = 0.5 "
                      r"\(the steps end at 0.3333, 0.6667, 1\)"):
        build_problem(scene)


@pytest.mark.parametrize("value", [0.0, 1.5, "soon"])
def test_interference_until_is_a_load_factor(value):
    with pytest.raises(SceneError, match=r"interference_until = "):
        _scene(interference_until=value)
