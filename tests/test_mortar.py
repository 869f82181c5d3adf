"""Mortar (segment-to-segment) pairs in 2D: patch test, tangent, strategies, scenes.

Two cylinders against Hertz: tests/test_mortar_hertz.py.

Every problem uses four slots so that one set of compiled forms serves the
whole file (the first compilation of the mortar forms takes about a minute).
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from dolfinx import fem

from mpi4py import MPI

from benchmarks import cases
from fenics_contact.model.body import Body, PrescribedDisplacement, Solid
from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.materials import material
from fenics_contact.model.mortar import MortarContact
from fenics_contact.model.pairs import NodeToSegmentContact
from fenics_contact.model.problem import ContactProblem
from fenics_contact.scene.build import build_mesh
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings

SLOTS = 4
ROOT = Path(__file__).resolve().parents[1]
LAW = material("linear", 200.0, 0.3)
#: Uniaxial plane strain, total height 1, pressed by 0.01.
PATCH_PRESSURE = -200.0 / (1 - 0.3**2) * 0.01


#: Tags of meshes/block_on_block.geo and meshes/two_cylinders.geo: cells striker 1, target
#: 2; facets top 2, striker face 3, target face 4, bottom 5, symmetry 6.
STRIKER_TAG, TARGET_TAG = 1, 2
LOAD_TAG, STRIKER_FACE_TAG, TARGET_FACE_TAG, SUPPORT_TAG, SYMMETRY_TAG = 2, 3, 4, 5, 6


def _mesh(scene):
    """The scene's mesh with its cell and facet tags (``mesh``, ``cell_tags``, ``facet_tags``)."""
    body = build_mesh(scene, MPI.COMM_WORLD)
    return SimpleNamespace(mesh=body.domain, cell_tags=body.cell_tags, facet_tags=body.facet_tags)


def _problem(md, fixed: dict, disc: str, r: float = 1.0) -> ContactProblem:
    ft = md.facet_tags
    bodies = [Body("upper", STRIKER_TAG, LAW), Body("lower", TARGET_TAG, LAW)]
    prescribed = [PrescribedDisplacement(ft.find(t), v) for t, v in fixed.items()]
    solid = Solid(md.mesh, bodies, md.cell_tags, prescribed=prescribed)
    args = (ft.find(STRIKER_FACE_TAG), ft.find(TARGET_FACE_TAG), ContactSettings(r=r))
    contact = (MortarContact(*args, slots=SLOTS) if disc == "mortar"
               else NodeToSegmentContact(*args))
    return ContactProblem(solid, [contact])


BLOCKS = {LOAD_TAG: (None, -0.01), SUPPORT_TAG: (None, 0.0), SYMMETRY_TAG: (0.0, None)}


def _blocks(n_upper: int, n_lower: int, disc: str, r: float = 1.0):
    md = _mesh(cases.block_on_block(n_upper, n_lower))
    return _problem(md, BLOCKS, disc, r), md.facet_tags


def _solve(problem, method: str, steps: int) -> tuple[list[int], list[list[float]]]:
    strategy = make_strategy(method, problem, SolverSettings())
    its, residuals = [], []
    for i in range(1, steps + 1):
        problem.set_load(i / steps)
        result = strategy.solve()
        assert result.converged, (method, i, result.status)
        its.append(result.iterations)
        residuals.append(list(result.residuals))
    return its, residuals


def _spread(problem, p: np.ndarray) -> float:
    lo = problem.comm.allreduce(float(np.min(p, initial=np.inf)), op=MPI.MIN)
    hi = problem.comm.allreduce(float(np.max(p, initial=-np.inf)), op=MPI.MAX)
    return (hi - lo) / abs(PATCH_PRESSURE)


# -- 1. patch test on non-matching meshes --------------------------------------------------
@pytest.mark.mpi
@pytest.mark.parametrize(("n_upper", "n_lower"), [(8, 11), (7, 5)])
def test_mortar_patch_non_matching(n_upper: int, n_lower: int) -> None:
    """Uniform nodal pressure to 1e-8 and force balance to 1e-10; NTS spreads on the same mesh."""
    problem, ft = _blocks(n_upper, n_lower, "mortar")
    _solve(problem, "gnrm", 2)
    state = problem.contact_state()
    np.testing.assert_allclose(state.pressure, PATCH_PRESSURE, rtol=1e-8)
    top = problem.reaction(ft.find(LOAD_TAG))[1]
    bottom = problem.reaction(ft.find(SUPPORT_TAG))[1]
    assert abs(top + bottom) <= 1e-10 * state.contact_force
    assert abs(-top - state.contact_force) <= 1e-10 * state.contact_force
    assert state.max_penetration <= 1e-12
    f = problem.target_force()
    n = problem.V.dofmap.index_map.size_local
    total = problem.comm.allreduce(f.x.array[: 2 * n].reshape(-1, 2).sum(axis=0), op=MPI.SUM)
    assert abs(total[1] + state.contact_force) <= 1e-10 * state.contact_force
    nts, _ = _blocks(n_upper, n_lower, "node-to-segment")
    _solve(nts, "gnrm", 2)
    assert _spread(nts, nts.contact_state().pressure) > 0.05


@pytest.mark.parametrize(("method", "r"), [("penalty", 1.0), ("nua", 1.0), ("auto", 1.0),
                                           ("sua", 0.1)])
def test_mortar_strategies(method: str, r: float) -> None:
    """Every strategy on the mortar patch test (SUA at r = 0.1 E/h as on NTS pairs)."""
    problem, _ = _blocks(8, 11, "mortar", r)
    if method == "sua":
        strategy = make_strategy("sua", problem, SolverSettings(max_iterations=200))
        for i in (1, 2):
            problem.set_load(i / 2)
            assert strategy.solve().converged
    else:
        _solve(problem, method, 2)
    state = problem.contact_state()
    if method == "penalty":  # uniform penetration p / r
        assert 1e-4 < state.max_penetration < 1e-2
        assert _spread(problem, state.pressure) < 1e-8
    else:
        np.testing.assert_allclose(state.pressure, PATCH_PRESSURE, rtol=1e-8)


# -- 2. the tangent against finite differences ------------------------------------------------
def _sheared(problem) -> None:
    """Shift and bend the striker so its nodes straddle target vertices; random lam < 0."""
    V, u = problem.V, problem.u
    md_tags = problem.solid.cell_tags
    tdim = problem.domain.topology.dim
    dofs = fem.locate_dofs_topological(V, tdim, md_tags.find(STRIKER_TAG))
    x = V.tabulate_dof_coordinates()
    values = u.x.array.reshape(-1, 2)
    for d in dofs:
        X = x[d]
        values[d] = (0.031 + 0.02 * X[1] + 0.01 * X[0] ** 2,
                     -0.003 + 0.004 * np.sin(3.0 * X[0]) - 0.002 * (X[1] - 0.5))
    u.x.scatter_forward()
    rng = np.random.default_rng(3)
    lam = problem.contact.lam
    lam.x.array[:] = -rng.uniform(0.5, 3.0, lam.x.array.size)
    lam.x.scatter_forward()


def test_mortar_tangent_finite_differences() -> None:
    """J du against central differences of the condensed residual (segments, sliding offsets)."""
    from tangent_check import condensed_tangent_errors

    problem, _ = _blocks(5, 7, "mortar", r=1.0)
    _sheared(problem)
    errors = condensed_tangent_errors(problem, np.random.default_rng(7))
    gaps = problem.contact_state().gap
    assert np.sum(gaps < 0) >= 2 and np.sum(gaps > 0) >= 1  # both sides of the kink
    print("tangent relative errors", errors)
    assert min(errors) < 1e-6, errors


# -- scenes -------------------------------------------------------------------------------------
def _scene_text(edit) -> str:
    """The node-to-segment patch-test scene without its discretisation key, edited."""
    text = (ROOT / "scenes" / "block_on_block_node_to_segment.toml").read_text()
    text = text.replace('discretisation = "node-to-segment"\n', "")
    return edit(text).replace("../meshes", str(ROOT / "meshes"))


def test_mortar_scene_key_errors(tmp_path) -> None:
    from fenics_contact.scene.schema import SceneError, load_scene

    for value, message in (('"segment"', "discretisation = 'segment'"),):
        path = tmp_path / "bad.toml"
        path.write_text(_scene_text(lambda s, v=value: s.replace(
            'target = "target_face"', f'target = "target_face"\ndiscretisation = {v}')))
        with pytest.raises(SceneError, match="discretisation") as err:
            load_scene(path)
        assert message in str(err.value)
        assert "node-to-segment" in str(err.value)


def test_a_pair_between_bodies_is_mortar_unless_it_says_otherwise(tmp_path) -> None:
    """The default discretisation: mortar between bodies (slots allowed without the key),
    node-to-segment for self-contact and when named."""
    from fenics_contact.scene.schema import load_scene
    from fenics_contact.scene.spec import PairSpec

    for edit, expected in (("", "mortar"), ("\nslots = 6", "mortar"),
                           ('\ndiscretisation = "node-to-segment"', "node-to-segment")):
        path = tmp_path / "default.toml"
        path.write_text(_scene_text(lambda s, e=edit: s.replace(
            'target = "target_face"', f'target = "target_face"{e}')))
        assert load_scene(path).pairs[0].discretisation == expected, edit
    assert PairSpec("p", "a", "b").discretisation == "mortar"
    assert PairSpec("p", "a", "a", self_contact=True).discretisation == "node-to-segment"


def test_mortar_scene_runs_end_to_end(tmp_path) -> None:
    """`fenics-contact run` on a mortar scene: converged, XDMF and summary.json written."""
    import json

    from fenics_contact.cli import main

    out = tmp_path / "run"
    scene = ROOT / "scenes" / "block_on_block.toml"
    assert main(["run", str(scene), "--out", str(out), "--quiet"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "converged"
    assert summary["steps_completed"] == summary["load_steps"] == 2
    assert (out / "solution.xdmf").is_file()
    assert (out / "solution" / "step_0002.h5").stat().st_size > 0
    assert abs(summary["steps"][-1]["contact_force"] + PATCH_PRESSURE) < 1e-10
    from fenics_contact.scene.schema import load_scene

    assert load_scene(ROOT / "scenes" / "two_cylinders.toml").pairs[0].discretisation \
        == "mortar"


def test_mortar_weighted_gap_of_a_tilted_target() -> None:
    """G_j is the hat-weighted mean of the gap: k x_j inside, k (x_j -+ h/3) at the ends.

    The target's top is tilted to y = H - k x (u_y = -k x on the lower block);
    the striker is untouched, so its normal is (0, -1) and g(x) = k x.
    """
    problem, _ = _blocks(5, 7, "mortar")
    V, u = problem.V, problem.u
    tdim = problem.domain.topology.dim
    dofs = fem.locate_dofs_topological(V, tdim, problem.solid.cell_tags.find(TARGET_TAG))
    k = 0.01
    u.x.array.reshape(-1, 2)[dofs, 1] = -k * V.tabulate_dof_coordinates()[dofs, 0]
    u.x.scatter_forward()
    state = problem.contact_state()
    x = problem.nodal_coordinates()[:, 0]
    h = 1.0 / 5
    expected = k * np.where(x < 1e-12, h / 3, np.where(x > 1 - 1e-12, 1 - h / 3, x))
    np.testing.assert_allclose(state.gap, expected, rtol=1e-12, atol=1e-15)


def test_mortar_sliding_across_target_vertices() -> None:
    """A 0.6-wide block pressed, then slid 0.15 (1.35 target facets) frictionless, 10 steps.

    Measured: 4, 3, 3, ... Newton iterations (3 per sliding step), reactions
    balanced to 1e-15, horizontal reaction at most 0.3 % of the vertical one.
    """
    from fenics_contact.model.body import PathDisplacement

    md = _mesh(cases.block_on_block(6, 9, upper_width=0.6))
    ft = md.facet_tags
    bodies = [Body("upper", STRIKER_TAG, LAW), Body("lower", TARGET_TAG, LAW)]
    path = ((0.0, 0.0, 0.0), (0.4, 0.0, -0.01), (1.0, 0.15, -0.01))
    prescribed = [PrescribedDisplacement(ft.find(SUPPORT_TAG), (0.0, 0.0)),
                  PathDisplacement(ft.find(LOAD_TAG), (None, None), path=path)]
    solid = Solid(md.mesh, bodies, md.cell_tags, prescribed=prescribed)
    contact = MortarContact(ft.find(STRIKER_FACE_TAG), ft.find(TARGET_FACE_TAG),
                            ContactSettings(r=1.0), slots=SLOTS)
    problem = ContactProblem(solid, [contact])
    its, _ = _solve(problem, "gnrm", 10)
    assert max(its) <= 4 and its[4:] == [3] * 6, its
    assert contact.mortar.version >= 5  # the slots changed while sliding
    top = problem.reaction(ft.find(LOAD_TAG))
    bottom = problem.reaction(ft.find(SUPPORT_TAG))
    assert np.all(np.abs(top + bottom) <= 1e-12)
    assert abs(top[0]) <= 0.005 * abs(top[1])
    assert abs(-top[1] - problem.contact_state().contact_force) <= 1e-3 * abs(top[1])


def test_a_striker_pushed_through_the_target_in_one_step_is_refused_then_cut_back(tmp_path):
    """2D mortar: the upper block pushed 0.3 (60 % of the lower one) in one load step.

    The first Newton iterate puts the striker face deeper than the segment
    search reaches: its nodes have no segment and would count as open, and
    the step used to 'converge' with no contact force. The depth measured by
    closest point refuses that iterate; after a cut-back the answer is the
    plane-strain one, E / (1 - nu^2) x 0.3 over the unit width.
    """
    from fenics_contact.runner import run_scene
    from fenics_contact.scene.schema import load_scene

    shipped = Path(__file__).parents[1] / "scenes" / "block_on_block.toml"
    text = shipped.read_text().replace('"../meshes/', f'"{shipped.parents[1]}/meshes/')
    # from the last state and with the sign rule: the active-set default starts the
    # touching face in contact, and the exact contact set holds every node within the
    # prescribed push on the target from the first iterate; both keep that iterate out
    # of the target (one step, no cut-back), which this test is not about
    text = text.replace('value = ["free", -0.01]', 'value = ["free", -0.3]').replace(
        "steps = 2", 'steps = 1\npredictor = "previous"\ncontact_set = "sign"')
    scene = tmp_path / "deep.toml"
    scene.write_text(text)
    outcome = run_scene(load_scene(scene), tmp_path / "out", comm=MPI.COMM_SELF, pictures=False)
    assert outcome.path.converged
    step = outcome.path.steps[-1]
    assert step.cutbacks >= 1
    assert step.contact_force == pytest.approx(200.0 / (1 - 0.3**2) * 0.3, rel=1e-6)


def test_a_striker_node_past_the_segment_search_is_named_as_a_mortar_one() -> None:
    """The surface check's refusal speaks of the mortar pair, not of a node-to-segment vertex.

    The upper block moved 0.3 down (2.4 h, past the reach 2 h = 0.25): every
    striker node has lost its segments and its weighted gap reads open.
    """
    from fenics_contact.solvers.diagnostics import signorini_admissibility

    problem, _ = _blocks(8, 11, "mortar")
    V = problem.V
    upper = problem.solid.cell_tags.find(STRIKER_TAG)
    blocks = np.unique(V.dofmap.list[upper].reshape(-1))
    problem.u.x.array.reshape(-1, 2)[blocks, 1] = -0.3
    problem.u.x.scatter_forward()
    state = problem.contact_state()
    assert state.constraint_penetration == 0.0  # the weighted gaps see nothing
    assert state.max_penetration == pytest.approx(0.3, rel=1e-12)
    message = signorini_admissibility(problem, SolverSettings())()
    assert message.startswith("penetration into the target surface 0.3 > surface_tol * h")
    assert "mortar pair has passed through the target deeper than its segment search" in message
    assert "concave vertex" not in message


def test_stability_grid_mortar_case_at_huge_r() -> None:
    """The mortar group of the stability grid: auto at r = 1e12 E/h meets GNRM at r = 1.

    GNRM and penalty diverge there (docs/two_bodies.md, mortar groups);
    auto must converge to the reference answer of GNRM at r = 1 E/h.
    """
    from benchmarks.robustness.stability_grid import full_grid
    from fenics_contact.sweeps.stability import run_case, select

    groups = {c.group for c in full_grid()}
    assert {"mortar-r", "mortar-stiffness", "mortar-sliding"} <= groups
    (reference_case,) = select(full_grid(), ["mortar-cyl-r1e0"])
    reference = run_case(reference_case, "gnrm")
    assert reference.status == "converged", reference.message
    (case,) = select(full_grid(), ["mortar-cyl-r1e12"])
    gnrm = run_case(case, "gnrm")
    assert gnrm.status != "converged"  # the case is extreme: the plain strategy fails
    record = run_case(case, "auto")
    assert record.status == "converged", record.message
    assert record.steps_completed == 3 and record.max_penetration < 1e-8
    assert record.iterations <= 20  # measured 17
    assert abs(record.contact_force - reference.contact_force) <= 1e-6 * reference.contact_force


L_BRACKET = """// an L bracket and a block in its inside corner, touching both of its faces
Geometry.AutoCoherence = 0;
Point(1) = {0, 0, 0, 0.05}; Point(2) = {1, 0, 0, 0.05}; Point(3) = {1, 0.2, 0, 0.05};
Point(4) = {0.2, 0.2, 0, 0.05}; Point(5) = {0.2, 1, 0, 0.05}; Point(6) = {0, 1, 0, 0.05};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5}; Line(5) = {5, 6};
Line(6) = {6, 1}; Curve Loop(1) = {1, 2, 3, 4, 5, 6}; Plane Surface(1) = {1};
Point(11) = {0.2, 0.2, 0, 0.04}; Point(12) = {0.6, 0.2, 0, 0.04};
Point(13) = {0.6, 0.6, 0, 0.04}; Point(14) = {0.2, 0.6, 0, 0.04};
Line(11) = {11, 12}; Line(12) = {12, 13}; Line(13) = {13, 14}; Line(14) = {14, 11};
Curve Loop(11) = {11, 12, 13, 14}; Plane Surface(11) = {11};
Mesh.Algorithm = 6;
Physical Surface("bracket", 1) = {1}; Physical Surface("block", 2) = {11};
Physical Curve("base", 1) = {1}; Physical Curve("floor", 2) = {3}; Physical Curve("wall", 3) = {4};
Physical Curve("block_corner", 4) = {11, 14}; Physical Curve("block_top", 6) = {13};
"""


def test_a_mortar_striker_turning_a_corner(tmp_path) -> None:
    """A block pushed into the inside corner of an L bracket, its striker the bottom and the
    side (a corner): each target slot of a corner node serves both of its facets, and the
    facet that does not face the target gets nothing from it. Before, the perpendicular
    facet divided by n_s . n_t = 0 and every residual was NaN."""
    import json

    from fenics_contact.cli import main

    (tmp_path / "bracket.geo").write_text(L_BRACKET)
    pairs = "".join(f'[[pair]]\nname = "on-{t}"\nstriker = "block_corner"\ntarget = "{t}"\n'
                    'discretisation = "mortar"\n\n' for t in ("floor", "wall"))
    (tmp_path / "bracket.toml").write_text(
        '[scene]\nname = "bracket"\ndimension = 2\n\n[mesh]\nfile = "bracket.geo"\n\n'
        + "".join(f'[[body]]\nname = "{b}"\ntag = "{b}"\nlaw = "linear"\nE = {e}\nnu = 0.3\n\n'
                  for b, e in (("bracket", 200.0), ("block", 100.0)))
        + pairs + '[[dirichlet]]\ntag = "base"\nvalue = [0.0, 0.0]\n\n'
        '[[dirichlet]]\ntag = "block_top"\nvalue = [-0.02, -0.02]\n\n'
        '[solver]\nmethod = "gnrm"\nsteps = 4\n')
    out = tmp_path / "run"
    assert main(["run", str(tmp_path / "bracket.toml"), "--out", str(out), "--quiet"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "converged"
    last = summary["steps"][-1]
    assert sum(s["iterations"] for s in summary["steps"]) <= 12  # measured 9
    # node-to-segment with the same two pairs: 2.50279 (mortar 2.49862, -0.17 %)
    assert last["contact_force"] == pytest.approx(2.50279, rel=3e-3)
    base = last["reactions"]["base"]
    assert base[0] == pytest.approx(-last["reactions"]["block_top"][0], rel=1e-8)
    assert base[1] == pytest.approx(-last["reactions"]["block_top"][1], rel=1e-8)
