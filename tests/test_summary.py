"""summary.json describes every body and every contact with its own settings.

A scene of three bodies of different moduli, two pairs (one with mu = 0.2,
one frictionless with an absolute r) and a floor with mu = 0.5 and its own
relative r: each record carries what its block declared and the absolute r
the run used; the top-level single values are the first body's and the
first contact's.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from mpi4py import MPI

from fenics_contact.runner import run_scene
from fenics_contact.scene.schema import scene_from_data

SCENES = Path(__file__).parent.parent / "scenes"


def _mixed_stack() -> dict:
    """stack_3_blocks with moduli 200, 100, 300 and contacts set apart."""
    import tomllib

    data = tomllib.loads((SCENES / "stack_3_blocks.toml").read_text())
    for body, E in zip(data["body"], (200.0, 100.0, 300.0), strict=True):
        body["E"] = E
    top_on_middle, middle_on_bottom = data["pair"]
    top_on_middle.update(mu=0.2, r=2.0)
    middle_on_bottom.update(r=300.0, relative=False)
    data["obstacle"][0].update(mu=0.5, r=0.5)
    return data


@pytest.fixture(scope="module")
def stack(tmp_path_factory):
    out = tmp_path_factory.mktemp("stack")
    scene = scene_from_data(_mixed_stack(), SCENES / "stack_3_blocks.toml")
    outcome = run_scene(scene, out, pictures=False, comm=MPI.COMM_SELF)
    assert outcome.path.status == "converged"
    return outcome, json.loads((out / "summary.json").read_text())


def test_every_body_has_its_own_record(stack):
    _, summary = stack
    assert [(b["name"], b["law"], b["E"], b["nu"]) for b in summary["bodies"]] == [
        ("bottom", "linear", 200.0, 0.3), ("middle", "linear", 100.0, 0.3),
        ("top", "linear", 300.0, 0.3)]
    # the top-level single values: the first body's
    assert (summary["law"], summary["E"], summary["nu"]) == ("linear", 200.0, 0.3)


def test_every_contact_has_its_own_settings(stack):
    outcome, summary = stack
    r_used = {c.name: float(c.r.value) for c in outcome.problem.contacts}
    scale = {c.name: c.stiffness_scale for c in outcome.problem.contacts}
    first, second = summary["pairs"]
    assert {k: first[k] for k in ("name", "striker", "target", "automatic", "r", "relative",
                                  "mu", "quadrature", "discretisation", "self_contact",
                                  "interference_until")} == {
        "name": "top-on-middle", "striker": "top_underside", "target": "middle_topside",
        "automatic": False, "r": 2.0, "relative": True, "mu": 0.2, "quadrature": "nodal",
        "discretisation": "node-to-segment", "self_contact": False, "interference_until": None}
    assert first["r_absolute"] == pytest.approx(2.0 * scale["top-on-middle"], rel=1e-14)
    assert first["r_absolute"] == r_used["top-on-middle"]
    assert (second["r"], second["relative"], second["mu"]) == (300.0, False, None)
    assert second["r_absolute"] == 300.0
    assert second["r_relative"] == pytest.approx(300.0 / scale["middle-on-bottom"], rel=1e-14)
    (floor,) = summary["obstacles"]
    assert {k: floor[k] for k in ("name", "type", "tag", "r", "relative", "mu", "quadrature")} == {
        "name": "floor", "type": "plane", "tag": "floor_face", "r": 0.5, "relative": True,
        "mu": 0.5, "quadrature": "nodal"}
    assert floor["r_absolute"] == pytest.approx(0.5 * scale["floor"], rel=1e-14)
    assert floor["r_relative"] == pytest.approx(0.5, rel=1e-14)
    # only the frictional contacts count stick and slip
    assert "stick_count" in first["steps"][-1] and "stick_count" not in second["steps"][-1]
    # the top-level single values: the first contact's (the first pair)
    assert summary["mu"] == 0.2 and summary["quadrature"] == "nodal"
    assert summary["r_absolute"] == first["r_absolute"]
    assert summary["r_relative"] == pytest.approx(2.0, rel=1e-14)


def test_automatic_pairs_are_listed_with_their_bodies(tmp_path):
    """[pairing] automatic = true: each pair found gets a record as a declared one does."""
    import tomllib

    data = tomllib.loads((SCENES / "stack_3_blocks_automatic.toml").read_text())
    data["pairing"].update(r=3.0)
    scene = scene_from_data(data, SCENES / "stack_3_blocks_automatic.toml")
    outcome = run_scene(scene, tmp_path, pictures=False, comm=MPI.COMM_SELF)
    assert outcome.path.status == "converged"
    summary = json.loads((tmp_path / "summary.json").read_text())
    scale = {c.name: c.stiffness_scale for c in outcome.problem.contacts}
    pairs = {p["name"]: p for p in summary["pairs"]}
    assert sorted(pairs) == ["middle-on-bottom", "top-on-middle"]
    for name, pair in pairs.items():
        assert (pair["striker"], pair["target"]) == tuple(name.split("-on-"))
        assert (pair["automatic"], pair["r"], pair["relative"], pair["mu"]) == (
            True, 3.0, True, None)
        assert pair["r_absolute"] == pytest.approx(3.0 * scale[name], rel=1e-14)
        assert [s["normal_force"] for s in pair["steps"]] == [
            s.contacts[name]["normal_force"] for s in outcome.path.steps]
    assert [o["name"] for o in summary["obstacles"]] == ["floor"]


def test_a_single_body_is_listed_as_body(tmp_path):
    """paper_ex2 ([material], [contact]): one body named "body", one obstacle."""
    import tomllib

    data = tomllib.loads((SCENES / "paper_ex2.toml").read_text())
    data["solver"]["steps"] = 2
    scene = scene_from_data(data, SCENES / "paper_ex2.toml")
    outcome = run_scene(scene, tmp_path, pictures=False, comm=MPI.COMM_SELF)
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["bodies"] == [
        {"name": "body", "tag": None, "law": "svk", "E": 210.0, "nu": 0.3}]
    (obstacle,) = summary["obstacles"]
    assert (obstacle["r"], obstacle["relative"], obstacle["r_absolute"]) == (100.0, False, 100.0)
    assert obstacle["r_relative"] == pytest.approx(outcome.path.r_relative, rel=1e-14)
    assert summary["pairs"] == []
