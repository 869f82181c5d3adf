"""Coulomb friction between two deformable bodies (node-to-segment): sliding blocks.

A narrower upper block (striker, 6 divisions) is pressed onto a lower block
(target, 9 divisions: non-matching) by its top face, then slid sideways
past the point of sliding; the lower block's bottom is clamped.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from mpi4py import MPI

from benchmarks import cases
from benchmarks.cases import PRESS_SLIDE_PAIR
from fenics_contact import build_problem, scene_from_data
from fenics_contact.model.friction import SLIP, STICK
from fenics_contact.scene.build import build_mesh, build_two_body_problem
from fenics_contact.scene.variants import with_contact_settings
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.stepping import solve_load_path

MU = 0.3
STEPS = 10
#: Press 0.01 over load factors 0 ... 0.4 (4 steps), then slide 0.04.
PATH = PRESS_SLIDE_PAIR
PRESS_STEPS = 4
#: Serial reference (GNRM, r = 1 E/h, r_t = 2 E/L): iterations per step and final forces.
SERIAL_ITERATIONS = [4, 2, 3, 2, 2, 4, 4, 3, 3, 3]
SERIAL_NORMAL_FORCE = 1.5910981934863453
SERIAL_TANGENTIAL_FORCE = 0.4773198325213958


def blocks(mu: float | None = MU, r: float = 1.0):
    """The sliding blocks and their mesh (with the facet tags); ``mu = None``: frictionless."""
    scene = with_contact_settings(cases.sliding_blocks(mu, path=PATH), r, relative=True)
    body = build_mesh(scene)
    return build_two_body_problem(scene, body), body


def solve(method: str = "gnrm", r: float = 1.0, mu: float | None = MU, max_iterations=50):
    """Run the load path; returns the problem, facet tags, record and nodal states per step."""
    problem, body = blocks(mu, r)
    strategy = make_strategy(
        method, problem, SolverSettings(atol=1e-8, rtol=1e-10, max_iterations=max_iterations)
    )
    states = []
    run = solve_load_path(strategy, STEPS, max_cutbacks=0,
                          on_step=lambda _: states.append(problem.contact_state()))
    return problem, body, run, states


@pytest.fixture(scope="module")
def gnrm_run():
    return solve()


def _gathered(values: np.ndarray) -> np.ndarray:
    return np.concatenate(MPI.COMM_WORLD.allgather(values))


@pytest.mark.mpi
def test_sliding_blocks_obey_coulomb(gnrm_run):
    problem, _, run, _ = gnrm_run
    assert run.converged
    steps = run.steps
    for step in steps:  # never more than mu N
        assert step.tangential_force <= MU * step.contact_force * (1 + 1e-12)
    for step in steps[:PRESS_STEPS]:  # pressing: the tangential force stays far below mu N
        assert step.tangential_force < 0.02 * MU * step.contact_force
        assert step.stick_count >= step.active_count - 1
    final = steps[-1]
    assert final.slip_count == final.active_count == 7
    state = problem.contact_state()
    # in each node's own frame the tangential force is mu N to 1e-8 once all nodes slip
    assert state.tangential_magnitude == pytest.approx(MU * state.contact_force, rel=1e-8)
    # node by node: |tau| <= mu p where it sticks, = mu p where it slips
    tau = _gathered(np.abs(state.tangential_traction[:, 0]))
    limit = _gathered(state.coulomb_limit)
    node_state = _gathered(state.node_state)
    slips = node_state == SLIP
    assert slips.sum() == 7
    np.testing.assert_allclose(tau[slips], limit[slips], rtol=1e-10, atol=0)
    assert np.all(tau[node_state == STICK] <= limit[node_state == STICK])


@pytest.mark.mpi
def test_stick_below_mu_n(gnrm_run):
    """The first shear step: every active node sticks, |tau| < mu p node by node."""
    _, _, run, states = gnrm_run
    step, state = run.steps[PRESS_STEPS], states[PRESS_STEPS]
    assert step.slip_count == 0 and step.stick_count == step.active_count == 7
    # measured: 0.51 mu N
    assert 0.3 < step.tangential_force / (MU * step.contact_force) < 0.8
    tau = np.abs(state.tangential_traction[:, 0])
    assert np.all(tau < state.coulomb_limit)


@pytest.mark.mpi
def test_parallel_matches_serial_iterations_and_forces(gnrm_run):
    _, _, run, _ = gnrm_run
    assert [s.iterations for s in run.steps] == SERIAL_ITERATIONS
    final = run.steps[-1]
    assert final.contact_force == pytest.approx(SERIAL_NORMAL_FORCE, rel=1e-10)
    assert final.tangential_force == pytest.approx(SERIAL_TANGENTIAL_FORCE, rel=1e-10)


def test_mu_zero_reproduces_frictionless_exactly():
    p0, _, run0, _ = solve(mu=None)
    p1, _, run1, _ = solve(mu=0.0)
    assert run0.converged and run1.converged
    assert [s.iterations for s in run1.steps] == [s.iterations for s in run0.steps]
    assert np.max(np.abs(p1.u.x.array - p0.u.x.array)) < 1e-12
    assert run1.steps[-1].contact_force == pytest.approx(run0.steps[-1].contact_force, rel=1e-12)
    assert run1.steps[-1].tangential_force == 0.0
    assert np.all(p1.lam_t.x.array == 0.0)


def test_gnrm_answer_does_not_depend_on_r(gnrm_run):
    reference, _, _, _ = gnrm_run
    u_ref = reference.u.x.array
    scale = np.max(np.abs(u_ref))
    for r in (1e-2, 1e2):  # measured also at 0.1 and 10 E/h (docs/friction.md)
        problem, _, run, _ = solve(r=r)
        assert run.converged, r
        assert np.max(np.abs(problem.u.x.array - u_ref)) < 1e-8 * scale, r
        final = run.steps[-1]
        assert final.tangential_force == pytest.approx(SERIAL_TANGENTIAL_FORCE, rel=1e-8), r
        assert final.contact_force == pytest.approx(SERIAL_NORMAL_FORCE, rel=1e-8), r
        # the cost against the frictionless pair at the same r: at most 1.5x in all and
        # 2x + 1 per step (r = 1e-2, step 8: 5 against 2, a change of the stick set)
        _, _, frictionless, _ = solve(r=r, mu=None)
        for with_mu, without in zip(run.steps, frictionless.steps, strict=True):
            assert with_mu.iterations <= 2 * without.iterations + 1, (r, with_mu.step)
        assert (sum(s.iterations for s in run.steps)
                <= 1.5 * sum(s.iterations for s in frictionless.steps)), r


@pytest.mark.mpi
def test_target_reaction_equals_striker_reaction(gnrm_run):
    """Friction reaches the target: its contact force balances the striker's support."""
    problem, body, _, _ = gnrm_run
    top = problem.reaction(body.facet_tags.find(body.names["top"]))
    bottom = problem.reaction(body.facet_tags.find(body.names["bottom"]))
    scale = SERIAL_NORMAL_FORCE
    np.testing.assert_allclose(top + bottom, 0.0, atol=1e-10 * scale)
    assert top[0] > 0.25 * scale  # the support drags the striker against friction
    f = problem.target_force()
    n = problem.V.dofmap.index_map.size_local
    total = problem.comm.allreduce(f.x.array[: 2 * n].reshape(-1, 2).sum(axis=0), op=MPI.SUM)
    np.testing.assert_allclose(total, top, atol=1e-10 * scale)


@pytest.mark.parametrize(("method", "iterations"), [("nua", 400), ("penalty", 50), ("auto", 50)])
def test_other_strategies(gnrm_run, method: str, iterations: int):
    """Nested Uzawa and auto give the GNRM answer; penalty slides at mu times its own N."""
    reference, _, _, _ = gnrm_run
    problem, _, run, states = solve(method, max_iterations=iterations)
    assert run.converged
    final = states[-1]
    assert final.slip_count == final.active_count == 7
    assert final.tangential_magnitude == pytest.approx(MU * final.contact_force, rel=1e-8)
    u_ref = reference.u.x.array
    if method == "nua":  # linear tangential Uzawa: measured 245-300 iterations while sticking
        assert np.max(np.abs(problem.u.x.array - u_ref)) < 1e-6 * np.max(np.abs(u_ref))
    elif method == "auto":
        assert [s.iterations for s in run.steps] == SERIAL_ITERATIONS
        assert np.max(np.abs(problem.u.x.array - u_ref)) < 1e-10 * np.max(np.abs(u_ref))


def test_scene_pair_takes_mu(tmp_path):
    from fenics_contact.scene.schema import SceneError, load_scene

    root = Path(__file__).resolve().parents[1]
    scene = load_scene(root / "scenes" / "ironing_friction.toml")
    assert scene.pairs[0].mu == 0.3 and scene.contact.mu == 0.3
    assert {"tangential_traction", "slip", "stick_slip"} <= set(scene.fields)
    text = (root / "scenes" / "ironing_friction.toml").read_text()
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace("mu = 0.3", "mu = -0.1").replace("../meshes",
                                                                 str(root / "meshes")))
    with pytest.raises(SceneError, match=r"\[\[pair\]\].*mu.*-0.1.*>= 0"):
        load_scene(bad)
    plain = tmp_path / "plain.toml"
    plain.write_text((root / "scenes" / "ironing.toml").read_text().replace(
        "[solver]", '[output]\nfields = ["slip"]\n[solver]').replace("../meshes",
                                                                     str(root / "meshes")))
    with pytest.raises(SceneError,
                       match=r"friction fields need \[\[pair\]\] or \[\[obstacle\]\] mu"):
        load_scene(plain)
    assert dataclasses.replace(scene.pairs[0], mu=None).mu is None


def test_ironing_friction_scene_writes_friction_output(tmp_path):
    """A short, coarse ironing_friction run: friction fields, forces and counts per step.

    Node-to-segment here: the shipped scene's mortar pair with friction on neo-Hookean
    bodies compiles for about 3 minutes on an empty cache (mortar friction is tested in
    tests/test_mortar_friction.py, the shipped scene in benchmarks/validation/).
    """
    import json

    from fenics_contact.runner import run_scene
    from fenics_contact.scene.schema import load_scene

    root = Path(__file__).resolve().parents[1]
    scene = load_scene(root / "scenes" / "ironing_friction.toml")
    path = ((0.0, 0.0, 0.0), (0.5, 0.0, -0.06), (1.0, 0.24, -0.06))
    scene = dataclasses.replace(
        scene,
        pairs=tuple(dataclasses.replace(p, discretisation="node-to-segment")
                    for p in scene.pairs),
        mesh=dataclasses.replace(scene.mesh, parameters={"h_indenter": 0.08, "h_block": 0.12}),
        dirichlet=(scene.dirichlet[0], dataclasses.replace(scene.dirichlet[1], path=path)),
        solver=dataclasses.replace(scene.solver, steps=6),
    )
    outcome = run_scene(scene, tmp_path, pictures=True)
    assert outcome.path.converged
    summary = json.loads((tmp_path / "summary.json").read_text())
    last = summary["steps"][-1]
    assert summary["pairs"][0]["mu"] == 0.3
    assert summary["pairs"][0]["steps"][-1]["slip_count"] == last["slip_count"]
    assert last["slip_count"] > 0 and last["stick_count"] == 0
    # every node slips: the friction resultant is mu times the normal one (2D)
    state = outcome.problem.contact_state()
    assert state.tangential_magnitude == pytest.approx(0.3 * state.contact_force, rel=1e-8)
    assert last["tangential_force"] == pytest.approx(state.tangential_force, rel=1e-12)
    index = (tmp_path / "solution.xdmf").read_text()
    step = sorted((tmp_path / "solution").glob("*.xdmf"))[-1].read_text()
    assert "Time" in index
    for name in ("tangential_traction", "slip", "stick_slip", "target_contact_force"):
        assert f'Name="{name}"' in step, name
    assert (tmp_path / "friction.png").stat().st_size > 0


@pytest.mark.slow
def test_hemispheres_slide_in_3d():
    """3D (barycentric slip, two tangents): press two hemispheres, slide sideways.

    No symmetry plane: a sticking node on a plane that fixes one displacement
    component leaves that tangential multiplier component undetermined
    (singular Jacobian). Slow only through the first FFCx compilation.
    """
    root = Path(__file__).resolve().parents[1]
    law = {"law": "linear", "E": 200.0, "nu": 0.3}
    scene = scene_from_data({
        "scene": {"name": "hemispheres-slide", "dimension": 3},
        "mesh": {"file": str(root / "meshes" / "two_hemispheres.geo"),
                 "parameters": {"h_contact": 0.08}},
        "body": [{"name": "upper", "tag": "striker", **law},
                 {"name": "lower", "tag": "target", **law}],
        "pair": [{"name": "pair", "striker": "striker_cap", "target": "target_cap",
                  "r": 1.0, "mu": MU, "discretisation": "node-to-segment"}],
        "dirichlet": [{"tag": "top", "path": [[0.0, 0.0, 0.0, 0.0], [0.5, 0.0, 0.0, -0.02],
                                              [1.0, 0.0, 0.02, -0.02]]},
                      {"tag": "bottom", "value": [0.0, 0.0, 0.0]}],
        "solver": {"steps": 8},
    }, root / "scenes" / "hemispheres_slide.toml")
    problem = build_problem(scene, MPI.COMM_WORLD)
    strategy = make_strategy("gnrm", problem, SolverSettings(atol=1e-8, rtol=1e-10))
    run = solve_load_path(strategy, 8, max_cutbacks=0)
    assert run.converged
    assert max(s.iterations for s in run.steps) <= 6  # measured 4, 3, 3, 2, 4, 5, 5, 4
    final = run.steps[-1]
    assert final.slip_count == final.active_count == 4
    state = problem.contact_state()
    assert state.tangential_magnitude == pytest.approx(MU * state.contact_force, rel=1e-8)
