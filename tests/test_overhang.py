"""A node-to-segment striker that runs on past the end of its target is named after the run.

``scenes/bridge.toml``: a bridge across two supports. Its pairs strike with
the underside over each support: no warning, and the same force as the
automatic pairing (whose targets are the supports' whole boundaries). With
the strikers running on over the gap, node-to-segment holds four nodes per
side level with the support's top: the force comes out high, and the run
names those nodes.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from fenics_contact import load_scene, run_scene
from fenics_contact.scene.checks import SceneWarning
from fenics_contact.scene.overhang import warn_overhanging_pairs

ROOT = Path(__file__).parents[1]
TEXT = (ROOT / "scenes" / "bridge.toml").read_text().replace('"../meshes/', f'"{ROOT}/meshes/')


def _run(tmp_path: Path, name: str, text: str):
    scene_file = tmp_path / f"{name}.toml"
    scene_file.write_text(text)
    scene = load_scene(scene_file)
    outcome = run_scene(scene, tmp_path / name, pictures=False)
    assert outcome.path.converged
    summary = json.loads((tmp_path / name / "summary.json").read_text())
    return scene, outcome, summary["steps"][-1]


def test_strikers_over_their_supports_match_automatic_pairing(tmp_path):
    scene, outcome, last = _run(tmp_path, "declared", TEXT)
    assert warn_overhanging_pairs(scene, outcome.problem) == 0
    reactions = last["reactions"]
    load = -reactions["bridge_top"][1]
    assert sum(r[1] for r in reactions.values()) == pytest.approx(0.0, abs=1e-12 * load)
    # two equal supports: each carries half the load (the meshes are not mirrored)
    assert reactions["left_base"][1] == pytest.approx(load / 2, rel=0.01)
    automatic = TEXT[:TEXT.index("[[pair]]")] + "[pairing]\nautomatic = true\n\n" + \
        TEXT[TEXT.index("[[dirichlet]]"):]
    _, _, auto = _run(tmp_path, "automatic", automatic)
    assert auto["contact_force"] == pytest.approx(last["contact_force"], rel=1e-6)


def test_strikers_past_their_targets_are_named(tmp_path):
    _, _, right = _run(tmp_path, "declared", TEXT)
    long = TEXT.replace('striker = "bridge_over_left"', 'striker = "bridge_under_left"') \
        .replace('striker = "bridge_over_right"', 'striker = "bridge_under_right"')
    with pytest.warns(SceneWarning, match=r"'on-(left|right)': 4 striker node\(s\) in contact "
                                          r"lie past the free edge of the target surface") as seen:
        _, _, wrong = _run(tmp_path, "long", long)
    assert sum("past the free edge" in str(w.message) for w in seen) == 2  # one per pair
    assert wrong["contact_force"] > 1.15 * right["contact_force"]  # measured +19 %
    assert np.isclose(wrong["reactions"]["left_base"][1] + wrong["reactions"]["right_base"][1],
                      -wrong["reactions"]["bridge_top"][1], rtol=1e-10)
