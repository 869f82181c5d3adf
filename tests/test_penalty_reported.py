"""The penalty method reports the force it transmits, under every predictor.

The penalty method does not solve for the multiplier: lam stays zero and
the written pressure is r min(g, 0). The active-set predictor (the scenes'
default) imposes its choice of contact set through lam; on a penalty run
that lam stayed in the reported pressure min(lam + r g, 0), while the
displacements, solved without it, were right. A neo-Hookean disk squashed
40 % at r = 10 reported a contact force of 180 against a support reaction
of 5.01, a block started 0.01 inside a rigid floor reported 0 (nothing
active) against a reaction of 4.15, and the shipped Hertz cylinder 0.6846
against 0.7425 at step 3. Now the reported force is the reaction.
"""

from __future__ import annotations

import tomllib
import warnings
from pathlib import Path

import numpy as np
import pytest

from fenics_contact import run_scene
from fenics_contact.scene.checks import SceneWarning
from fenics_contact.scene.schema import scene_from_data

SCENES = Path(__file__).parents[1] / "scenes"


def _balance(summary: dict) -> list[tuple[float, float]]:
    """(reported contact force, vertical support reaction) of every load step."""
    return [(s["contact_force"], abs(sum(r[1] for r in s["reactions"].values())))
            for s in summary["steps"]]


@pytest.mark.parametrize("predictor", ["active-set", "extrapolate", "previous"])
def test_penalty_on_the_hertz_cylinder_reports_the_reaction(tmp_path, predictor):
    data = tomllib.loads((SCENES / "hertz_cylinder.toml").read_text())
    data["solver"].update(method="penalty", predictor=predictor)
    outcome = run_scene(scene_from_data(data, SCENES / "hertz_cylinder.toml"), tmp_path,
                        pictures=False)
    assert outcome.path.converged
    steps = _balance(outcome.summary)
    assert len(steps) == 4
    for force, reaction in steps:
        assert force == pytest.approx(reaction, rel=1e-8)
    # the penalty's own softness: a little below GNRM's 1.0445 (docs/benchmarks.md)
    assert steps[-1][0] == pytest.approx(1.0435, rel=1e-3)


def test_penalty_on_a_body_that_starts_inside_a_floor_reports_the_reaction(tmp_path):
    data = {
        "scene": {"name": "block-in-floor", "dimension": 2},
        "mesh": {"generator": "rectangle", "origin": [0.0, -0.01], "size": [1.0, 0.5],
                 "cells": [20, 10]},
        "material": {"law": "linear", "E": 200.0, "nu": 0.3},
        "obstacle": {"type": "plane", "point": [0.0, 0.0], "normal": [0.0, 1.0]},
        "contact": {"tag": "bottom"},
        "dirichlet": [{"tag": "top", "value": [0.0, 0.0]}],
        "solver": {"method": "penalty", "steps": 1},
    }
    with pytest.warns(SceneWarning, match=r"the body starts 0.01 \(0.2 h\) inside the "
                      r"obstacle; the first load step pushes it out"):
        outcome = run_scene(scene_from_data(data, tmp_path / "block.toml"), tmp_path / "run",
                            pictures=False)
    assert outcome.path.converged
    (force, reaction), = _balance(outcome.summary)
    assert reaction > 4.0  # the floor pushes the block 0.01 up against its clamped top
    assert force == pytest.approx(reaction, rel=1e-8)
    assert outcome.summary["steps"][0]["active_count"] == 21
    pressure = outcome.problem.contact_state().pressure
    assert np.all(pressure <= 0.0)


def test_the_penalty_methods_own_penetration_is_not_blamed_on_the_tag(tmp_path):
    """Side nodes carried in beside the tagged bottom are not "outside the tag".

    r = 0.01 E/h lets the bottom sink 0.139 (2.8 h) into the floor, and the
    four side nodes above each corner follow it (the deepest 0.088). Before,
    the run advised adding the sides to the tag, or detect = true; now a node
    counts only when it lies deeper than the tagged nodes themselves.
    """
    data = {
        "scene": {"name": "soft-penalty", "dimension": 2},
        "mesh": {"generator": "rectangle", "origin": [0.0, 0.0], "size": [1.0, 0.5],
                 "cells": [20, 10]},
        "material": {"law": "linear", "E": 200.0, "nu": 0.3},
        "obstacle": {"type": "plane", "point": [0.0, 0.0], "normal": [0.0, 1.0]},
        "contact": {"tag": "bottom", "r": 0.01},
        "dirichlet": [{"tag": "top", "value": [0.0, -0.15]}],
        "solver": {"method": "penalty", "steps": 1},
    }
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        outcome = run_scene(scene_from_data(data, tmp_path / "soft.toml"), tmp_path / "run",
                            pictures=False)
    assert outcome.path.converged
    assert outcome.summary["steps"][0]["max_penetration"] == pytest.approx(0.1386, rel=1e-3)
    assert not any("candidate facets" in str(w.message) for w in seen)
