"""Three blocks in a column on a rigid floor, 3D quarter model, pairs found automatically.

``scenes/three_blocks_3d.toml`` ([pairing] automatic = true) against the
same scene with the two interfaces declared by hand ([[pair]] blocks, the
upper block striking): the same contacts, forces to 1e-8 (the aim was 2 %; measured
equal to 1e-12), and every block in balance: the press's reaction is the
vertical force each interface hands down and the floor's force.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

from mpi4py import MPI

from fenics_contact.runner import run_scene
from fenics_contact.scene.schema import load_scene, scene_from_data

SCENE = Path(__file__).parent.parent / "scenes" / "three_blocks_3d.toml"
HAND = [  # node-to-segment, as the automatic pairs are
    {"name": "top-on-middle", "striker": "top_underside", "target": "middle_topside",
     "discretisation": "node-to-segment"},
    {"name": "middle-on-bottom", "striker": "middle_underside", "target": "bottom_topside",
     "discretisation": "node-to-segment"},
]


def test_automatic_pairs_match_the_declared_ones_and_every_block_balances(tmp_path):
    data = tomllib.loads(SCENE.read_text())
    data.pop("pairing")
    data["pair"] = HAND
    runs = {}
    for name, scene in (("auto", load_scene(SCENE)), ("hand", scene_from_data(data, SCENE))):
        outcome = run_scene(scene, tmp_path / name, comm=MPI.COMM_SELF, pictures=False)
        assert outcome.path.converged, name
        runs[name] = outcome.problem
    auto, hand = (runs[k].contact_states() for k in ("auto", "hand"))
    assert sorted(auto) == sorted(hand) == ["floor", "middle-on-bottom", "top-on-middle"]
    for name, state in hand.items():
        assert auto[name].contact_force == pytest.approx(state.contact_force, rel=1e-8), name
        assert auto[name].active_count == state.active_count, name
        # measured alike, by closest point over the target surface (7.7e-6 at the top
        # block's edge over the middle one, a node held past a facet's end)
        assert auto[name].max_penetration == pytest.approx(state.max_penetration, rel=1e-3,
                                                            abs=1e-12), name
        h = next(c for c in runs["hand"].contacts if c.name == name).surface.h
        assert auto[name].max_penetration < 1e-3 * h, name
    problem = runs["auto"]
    press = -problem.reaction(problem.solid.prescribed[2].facets)[2]
    assert press > 0.2
    assert auto["floor"].contact_force == pytest.approx(press, rel=1e-10)
    # each interface hands the press's vertical force down (the force the striker puts on
    # the target's vertices); its normal force differs by the tilt of the facets (< 1e-4)
    for name in ("top-on-middle", "middle-on-bottom"):
        contact = next(c for c in problem.contacts if c.name == name)
        down = -contact.target_force().x.array.reshape(-1, 3)[:, 2].sum()
        assert down == pytest.approx(press, rel=1e-10), name
        assert auto[name].contact_force == pytest.approx(press, rel=1e-4), name


def test_active_set_predictor_on_automatic_pairs(tmp_path):
    """Nodes that find their facet during a step (their gap drops from the lift) stay open.

    The gaps' edge rule once read such a drop as a closing edge, closed nodes
    5 facet sizes apart and made step 2 diverge at every cut-back.
    """
    data = tomllib.loads(SCENE.read_text())
    outcomes = {}
    for predictor in ("extrapolate", "active-set"):
        data["solver"]["predictor"] = predictor
        scene = scene_from_data(data, SCENE)
        outcome = run_scene(scene, tmp_path / predictor, comm=MPI.COMM_SELF, pictures=False)
        assert outcome.path.converged, predictor
        assert outcome.path.cutbacks == 0, predictor
        outcomes[predictor] = outcome
    counts = {k: [s.iterations for s in o.path.steps] for k, o in outcomes.items()}
    assert sum(counts["active-set"]) <= sum(counts["extrapolate"]), counts
    forces = {k: o.problem.contact_states() for k, o in outcomes.items()}
    for name, state in forces["extrapolate"].items():
        assert forces["active-set"][name].contact_force == pytest.approx(state.contact_force,
                                                                         rel=1e-8), name
