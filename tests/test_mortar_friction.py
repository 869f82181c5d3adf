"""Coulomb friction on 2D mortar pairs: the sliding blocks of test_pair_friction.py, mortar.

A 0.6-wide upper block (striker, 6 divisions) is pressed 0.01 onto a
1-wide lower block (target, 9 divisions: non-matching) in 4 steps, then
slid 0.04 in 6; mu = 0.3, r_t capped at 2 E/L as for node-to-segment.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from mpi4py import MPI

from benchmarks import cases
from benchmarks.cases import PRESS_SLIDE_PAIR
from fenics_contact.model.friction import SLIP, STICK
from fenics_contact.scene.build import build_mesh, build_two_body_problem
from fenics_contact.scene.variants import with_contact_settings
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.stepping import solve_load_path

MU = 0.3
STEPS = 10
PRESS_STEPS = 4
#: Serial reference (GNRM, r = 1 E/h): iterations, normal and tangential forces per step.
SERIAL_ITERATIONS = [4, 2, 2, 2, 3, 4, 5, 3, 3, 3]
SERIAL_NORMAL_FORCES = [0.40449367165469996, 0.8092422321018584, 1.2142408925987644,
                        1.61948485334182, 1.6122957689678001, 1.59544787786957,
                        1.5909993864080847, 1.5871927328137598, 1.583531528600672,
                        1.579854410619976]
SERIAL_TANGENTIAL_FORCES = [0.00241933947338749, 0.00483840045152276,
                            0.007277902267140075, 0.009756872095820756,
                            0.24722567277164048, 0.47611305157204936, 0.47727671548700146,
                            0.47613577233506044, 0.4750389384792678, 0.4739377988663167]
#: Node states per step along x (0 open, 1 stick, 2 slip): every node sticks while
#: pressing, one slips at the first shear step, one sticks at the second, all slip from
#: step 7 on.
SERIAL_NODE_STATES = ["1111111"] * 4 + ["1111121", "1222222"] + ["2222222"] * 4


def mortar_blocks(mu: float | None = MU, r: float = 1.0):
    """The sliding blocks with a mortar pair; ``mu = None``: frictionless."""
    scene = with_contact_settings(cases.sliding_blocks(mu, path=PRESS_SLIDE_PAIR), r,
                                  relative=True)
    scene = dataclasses.replace(scene, pairs=tuple(
        dataclasses.replace(p, discretisation="mortar") for p in scene.pairs))
    body = build_mesh(scene)
    return build_two_body_problem(scene, body), body


def solve(r: float = 1.0, mu: float | None = MU, method: str = "gnrm"):
    problem, body = mortar_blocks(mu, r)
    strategy = make_strategy(method, problem,
                             SolverSettings(atol=1e-8, rtol=1e-10, max_iterations=50))
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
def test_mortar_sliding_blocks_obey_coulomb(gnrm_run):
    """Pressing sticks far below mu N; at full slip F_t = mu N to 1e-6, node by node too."""
    _, _, run, states = gnrm_run
    assert run.converged
    for step in run.steps:
        assert step.tangential_force <= MU * step.contact_force * (1 + 1e-10)
    for step in run.steps[:PRESS_STEPS]:  # pressing: F_t / (mu N) measured 2.0 %, all stick
        assert step.tangential_force < 0.025 * MU * step.contact_force
        assert step.stick_count >= step.active_count - 2
    for step, state in zip(run.steps, states, strict=True):  # no gross slip below mu N
        if state.tangential_magnitude < MU * step.contact_force * (1 - 1e-6):
            assert step.stick_count > 0
            sticks = state.node_state == STICK
            assert np.all(np.abs(state.tangential_traction[sticks, 0])
                          < state.coulomb_limit[sticks])
    final = run.steps[-1]
    assert final.slip_count == final.active_count > 0 and final.stick_count == 0
    state = states[-1]
    # in each node's own frame (the tangents of the target facet it projects on); the
    # resultant of the frames, tilted with the dented lower face, is 3.9e-5 lower
    assert state.tangential_magnitude == pytest.approx(MU * state.contact_force, rel=1e-8)
    assert final.tangential_force == pytest.approx(MU * final.contact_force, rel=1e-4)
    tau = _gathered(np.abs(state.tangential_traction[:, 0]))
    limit = _gathered(state.coulomb_limit)
    node_state = _gathered(state.node_state)
    np.testing.assert_allclose(tau[node_state == SLIP], limit[node_state == SLIP], rtol=1e-10)
    assert np.all(tau[node_state == STICK] <= limit[node_state == STICK])


@pytest.mark.mpi
def test_mortar_friction_balance_and_target_force(gnrm_run):
    """Top and bottom reactions balance; the force handed to the target is the top's."""
    problem, body, _, _ = gnrm_run
    top = problem.reaction(body.facet_tags.find(body.names["top"]))
    bottom = problem.reaction(body.facet_tags.find(body.names["bottom"]))
    scale = abs(top[1])
    np.testing.assert_allclose(top + bottom, 0.0, atol=1e-10 * scale)
    f = problem.target_force()
    n = problem.V.dofmap.index_map.size_local
    total = problem.comm.allreduce(f.x.array[: 2 * n].reshape(-1, 2).sum(axis=0), op=MPI.SUM)
    np.testing.assert_allclose(total, top, atol=1e-10 * scale)


@pytest.mark.mpi
def test_mortar_friction_parallel_matches_serial(gnrm_run):
    """Newton counts, stick/slip states and forces of every step on 1 and 2 ranks (1e-10).

    Every sliding step after the first starts with all nodes exactly on the
    Coulomb circle (zero slip increment, |lam_t| = mu |p| to round-off): the
    margin of :func:`~fenics_contact.model.friction.sticks` makes them slip
    there whatever the round-off; without it the counts of steps 7-10 were
    4, 5, 5, 5 serial and 5, 6, 5, 4 on 2 ranks.
    """
    problem, _, run, states = gnrm_run
    assert [s.iterations for s in run.steps] == SERIAL_ITERATIONS
    x = _gathered(problem.nodal_coordinates()[:, 0])
    patterns = ["".join(str(v) for v in _gathered(state.node_state)[np.argsort(x)])
                for state in states]
    assert patterns == SERIAL_NODE_STATES
    assert [s.stick_count + s.slip_count for s in run.steps] == [7] * STEPS
    np.testing.assert_allclose([s.contact_force for s in run.steps], SERIAL_NORMAL_FORCES,
                               rtol=1e-10, atol=0)
    np.testing.assert_allclose([s.tangential_force for s in run.steps],
                               SERIAL_TANGENTIAL_FORCES, rtol=1e-10, atol=0)


def test_mortar_mu_zero_reproduces_frictionless():
    p0, _, run0, _ = solve(mu=None)
    p1, _, run1, _ = solve(mu=0.0)
    assert run0.converged and run1.converged
    assert [s.iterations for s in run1.steps] == [s.iterations for s in run0.steps]
    assert np.max(np.abs(p1.u.x.array - p0.u.x.array)) < 1e-12
    assert run1.steps[-1].tangential_force == 0.0


def _order(residuals: list[float]) -> float:
    r = [x for x in residuals if x > 0]
    a, b, c = r[-3:]
    return np.log(c / b) / np.log(b / a)


def test_mortar_friction_answer_does_not_depend_on_r(gnrm_run):
    """GNRM at r = 1e-2 and 10 E/h, and auto at 1e2 E/h, give the r = 1 answer to 1e-8.

    Plain GNRM cycles in a sliding step from r = 30 E/h on (step 9) and diverges at
    1e2 E/h (step 10): auto works at r <= 1 E/h there.
    """
    reference, _, ref_run, _ = gnrm_run
    u_ref = reference.u.x.array
    scale = np.max(np.abs(u_ref))
    for r, method in ((1e-2, "gnrm"), (10.0, "gnrm"), (1e2, "auto")):
        problem, _, run, _ = solve(r=r, method=method)
        assert run.converged, r
        assert np.max(np.abs(problem.u.x.array - u_ref)) < 1e-8 * scale, r
        final = run.steps[-1]
        assert final.tangential_force == pytest.approx(ref_run.steps[-1].tangential_force,
                                                       rel=1e-8), r
        assert final.contact_force == pytest.approx(ref_run.steps[-1].contact_force,
                                                    rel=1e-8), r
    for step in ref_run.steps:
        if len(step.residuals[-1]) >= 4:
            assert _order(step.residuals[-1]) > 1.3, (step.step, step.residuals[-1])


def test_mortar_scene_takes_mu(tmp_path):
    """A mortar [[pair]] with mu loads (it was refused while mortar was frictionless)."""
    from pathlib import Path

    from fenics_contact.scene.schema import load_scene

    root = Path(__file__).resolve().parents[1]
    text = (root / "scenes" / "two_cylinders.toml").read_text()
    path = tmp_path / "mortar_mu.toml"
    path.write_text(text.replace('discretisation = "mortar"', 'discretisation = "mortar"\nmu = 0.2')
                    .replace("../meshes", str(root / "meshes")))
    pair = load_scene(path).pairs[0]
    assert pair.discretisation == "mortar" and pair.mu == 0.2


def test_mortar_cattaneo_mindlin_coarse_non_matching(tmp_path):
    """Cattaneo-Mindlin, mortar, non-matching arcs (ratio 1.37), coarse h = 0.006, 6 steps.

    Measured: Q/(mu P) = 0.23, 0.45, 0.67, 0.87; stick half-width errors
    -2.1, +0.2, -2.2, -8.8 % of c (node spacing at the edge 3.4 ... 8.3 %);
    traction L2 errors (the nodal force per tributary length of the multiplier
    field) 12.4, 6.8, 4.4, 3.3 %. With the slip weighted over the segments
    instead of measured at each node's projection: -2.1, -3.8, -2.3, -9.0 %
    and 22, 11, 5.6, 3.3 % (the stick edge a node spacing inside; the
    bounds below fail there). The shipped mesh (h = 0.003, 12 steps;
    benchmarks/validation/cattaneo_mortar.py) is within 3.7 % in c.
    """
    from benchmarks.validation.cattaneo import solve_cattaneo_mindlin
    from benchmarks.validation.cattaneo_mortar import mortar_scene
    from fenics_contact.scene.schema import load_scene

    run = solve_cattaneo_mindlin(load_scene(mortar_scene(tmp_path, 0.006, 1.37, 6)))
    ratios = [z.load_ratio for z in run.zones]
    assert len(ratios) == 4 and 0.2 < ratios[0] < 0.26 and 0.84 < ratios[-1] < 0.9
    for zone in run.zones:
        assert zone.stick_nodes > 0 and zone.slip_nodes > 0
        assert abs(zone.c_error) < 0.1, zone
    assert abs(run.zones[1].c_error) < 0.01  # within a quarter of the node spacing (4 %)
    assert run.zones[0].traction_error < 0.15 and run.zones[1].traction_error < 0.08
    assert run.zones[-1].traction_error < 0.04
    assert run.zones[-2].traction_error < 0.05
