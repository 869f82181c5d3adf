"""The end-of-run warning for node-to-segment pressures that scatter from node to node."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from mpi4py import MPI

from fenics_contact import load_scene, run_scene
from fenics_contact.scene.checks import SceneWarning
from fenics_contact.scene.pressure_scatter import SCATTER, nodal_scatter

SCENES = Path(__file__).parents[1] / "scenes"


def _run(tmp_path, name: str):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", SceneWarning)
        outcome = run_scene(load_scene(SCENES / name), tmp_path / name, comm=MPI.COMM_SELF,
                            pictures=False)
    assert outcome.path.converged
    said = [str(w.message) for w in caught if "scatter from node to node" in str(w.message)]
    return outcome, said


def test_the_non_matching_patch_test_on_node_to_segment_is_named(tmp_path):
    """Uniform pressure in truth; node-to-segment on 8 against 11 facets scatters it."""
    outcome, said = _run(tmp_path, "block_on_block_node_to_segment.toml")
    scatter, mean = nodal_scatter(outcome.problem.contacts[0])
    assert mean > 0 and len(said) == 1
    assert "[[pair]] 'pair1'" in said[0] and 'Fix: discretisation = "mortar"' in said[0]
    # the resultant is off too (the mortar pair gives the uniaxial force exactly)
    uniaxial = 200.0 / (1 - 0.3**2) * 0.01
    assert abs(outcome.path.contact_force / uniaxial - 1) > 1e-3  # -0.17 % measured
    assert "resultant force may be off by per cents" in said[0]
    assert "right either way" not in said[0]
    median = float(np.median(scatter)) / mean
    assert median > 1.5 * SCATTER  # 0.16 measured
    assert f"by {median:.0%} of their mean" in said[0]
    assert said[0] in outcome.summary["warnings"]  # kept in summary.json too


def test_a_smooth_node_to_segment_profile_is_not(tmp_path):
    """The two cylinders (Hertz) on node-to-segment: the profile bends, it does not scatter."""
    outcome, said = _run(tmp_path, "two_cylinders_node_to_segment.toml")
    scatter, mean = nodal_scatter(outcome.problem.contacts[0])
    assert not said
    assert scatter.size >= 5
    assert float(np.median(scatter)) / mean < 0.6 * SCATTER  # 0.053 measured


def test_rigid_obstacles_are_not_measured(tmp_path):
    _, said = _run(tmp_path, "hertz_cylinder.toml")
    assert not said


def test_a_scattered_tail_is_named_where_the_median_is_not(tmp_path, monkeypatch):
    """A hemisphere on a block (3D, node-to-segment): 17 interior nodes, median scatter
    5.6 % of the mean but 41 % at the 90th percentile, the nodal peak 23 % above Hertz,
    and no warning. A tenth of the nodes above TAIL now names the pair; a tail like the
    shipped hemispheres' (16 %) does not."""
    from fenics_contact.scene import pressure_scatter

    outcome, said = _run(tmp_path, "two_cylinders_node_to_segment.toml")
    assert not said
    scene = load_scene(SCENES / "two_cylinders_node_to_segment.toml")
    tail = np.r_[np.full(14, 0.05), 0.35, 0.45, 0.55]  # median 0.05, 90th percentile 0.39
    for every, named in ((tail, True), (np.r_[np.full(15, 0.05), 0.16, 0.16], False)):
        monkeypatch.setattr(pressure_scatter, "_ratio",
                            lambda contact, e=every: (float(np.median(e)), e, 9.04))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", SceneWarning)
            pressure_scatter.warn_pressure_scatter(scene, outcome.problem)
        texts = [str(w.message) for w in caught]
        assert bool(texts) is named
        if named:
            assert "by 5% of their mean (9.04)" in texts[0]
            assert "39% at the 90th percentile, largest 55%" in texts[0]
