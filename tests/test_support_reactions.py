"""Support reactions in summary.json: every support's force per step, by its scene tag.

Checked by equilibrium: the reactions of the supports balance each other and
the contact force (block on block: a flat interface, the normal force is the
resultant), step by step.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from fenics_contact import load_scene, run_scene

SCENES = Path(__file__).parents[1] / "scenes"


def test_block_on_block_reactions_balance_the_contact_force(tmp_path):
    scene = load_scene(SCENES / "block_on_block.toml")
    run_scene(scene, tmp_path, pictures=False)
    summary = json.loads((tmp_path / "summary.json").read_text())
    steps = summary["steps"]
    assert len(steps) == scene.solver.steps
    for step in steps:
        reactions = step["reactions"]
        assert set(reactions) == {"bottom", "symmetry", "top"}
        total = np.sum([reactions[name] for name in reactions], axis=0)
        force = step["contact_force"]
        assert force > 0.0
        assert np.all(np.abs(total) < 1e-10 * force)  # the bodies are in equilibrium
        assert reactions["top"][1] == pytest.approx(-force, rel=1e-10)
        assert reactions["bottom"][1] == pytest.approx(force, rel=1e-10)
        assert reactions["top"][0] == 0.0  # a free component

