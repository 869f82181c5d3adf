"""Two deformable bodies: search, patch test, two cylinders against Hertz, strategies."""

from __future__ import annotations

import numpy as np
import pytest

from mpi4py import MPI

from benchmarks import cases
from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.materials import material
from fenics_contact.model.problem import Body, ContactProblem, two_body_problem
from fenics_contact.model.search import SurfaceSearch
from fenics_contact.references.hertz import fit_contact_profile, half_width, peak_pressure
from fenics_contact.scene.build import BodyMesh, build_mesh, build_two_body_problem
from fenics_contact.scene.spec import Scene
from fenics_contact.scene.variants import with_contact_settings
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings


# -- search --------------------------------------------------------------------------
def test_node_sliding_across_facet_boundary() -> None:
    """On a flat target the assignment switches at the shared vertex and the gap is continuous."""
    verts = np.array([[[0.0, 0.0], [1.0, 0.0]], [[1.0, 0.0], [2.0, 0.0]]])
    search = SurfaceSearch(verts)
    xs = np.linspace(0.8, 1.2, 41)
    pts = np.stack([xs, np.full_like(xs, -0.01)], axis=1)
    proj = search.closest(pts)
    assert np.all(proj.facet[xs < 1.0 - 1e-12] == 0) and np.all(proj.facet[xs > 1 + 1e-12] == 1)
    # the gap (x - x_a).n with n = perp(b - a) = (0, -1) (target above): 0.01 everywhere
    a, b = verts[proj.facet, 0], verts[proj.facet, 1]
    t = b - a
    n = np.stack([t[:, 1], -t[:, 0]], 1) / np.linalg.norm(t, axis=1)[:, None]
    g = np.einsum("ij,ij->i", pts - a, n)
    np.testing.assert_allclose(g, 0.01, atol=1e-15)
    # hysteresis: a node just past the vertex keeps its previous facet
    kept = search.closest(np.array([[1.01, -0.01]]), previous=np.array([0]))
    assert kept.facet[0] == 0 and abs(kept.xi[0, 0] - 1.01) < 1e-12
    far = search.closest(np.array([[1.2, -0.01]]), previous=np.array([0]))
    assert far.facet[0] == 1


def test_convex_corner_rule() -> None:
    """In the dead zone of a convex corner the facet with the least overshoot is taken."""
    verts = np.array([[[0.0, 0.0], [1.0, 0.0]], [[1.0, 0.0], [1.0, -1.0]]])  # corner at (1, 0)
    search = SurfaceSearch(verts)
    proj = search.closest(np.array([[1.3, 0.1], [1.1, 0.3]]))
    assert proj.facet.tolist() == [1, 0]
    np.testing.assert_allclose(proj.distance, [np.hypot(0.3, 0.1), np.hypot(0.1, 0.3)])


def test_search_matches_brute_force() -> None:
    """The k-d tree search finds the brute-force closest facet on a curved polyline."""
    rng = np.random.default_rng(1)
    s = np.sort(rng.uniform(0, np.pi, 60))
    p = np.stack([np.cos(s), np.sin(s)], 1)
    verts = np.stack([p[:-1], p[1:]], axis=1)
    pts = rng.uniform(-1.5, 1.5, (200, 2))
    proj = SurfaceSearch(verts, candidates=2).closest(pts)
    a, b = verts[None, :, 0], verts[None, :, 1]
    t = b - a
    xi = np.clip(np.einsum("nmi,nmi->nm", pts[:, None] - a, t) / np.einsum("nmi,nmi->nm", t, t),
                 0, 1)
    d = np.linalg.norm(pts[:, None] - (a + xi[..., None] * t), axis=-1).min(axis=1)
    np.testing.assert_allclose(proj.distance, d, rtol=1e-12, atol=1e-14)


# -- problems --------------------------------------------------------------------------
def _with_mesh(scene: Scene, r: float = 1.0) -> tuple[ContactProblem, BodyMesh]:
    """The scene's problem at r (relative to E/h) and its mesh, for the facet tags."""
    scene = with_contact_settings(scene, r, relative=True)
    body = build_mesh(scene)
    return build_two_body_problem(scene, body), body


def _facets(body: BodyMesh, name: str) -> np.ndarray:
    return body.facet_tags.find(body.names[name])


def _blocks(n_upper: int, n_lower: int, r: float = 1.0) -> tuple[ContactProblem, BodyMesh]:
    return _with_mesh(cases.block_on_block(n_upper, n_lower), r)


def _solve(problem, method: str, steps: int) -> list:
    strategy = make_strategy(method, problem, SolverSettings())
    out = []
    for i in range(1, steps + 1):
        problem.set_load(i / steps)
        result = strategy.solve()
        assert result.converged, (method, i, result.status)
        out.append(result.iterations)
    return out


@pytest.mark.mpi
def test_patch_matching_uniform_pressure() -> None:
    problem, _ = _blocks(8, 8)
    its = _solve(problem, "gnrm", 1)
    state = problem.contact_state()
    p = state.pressure
    exact = -200.0 / (1 - 0.3**2) * 0.01  # uniaxial plane strain, total height 1
    np.testing.assert_allclose(p, exact, rtol=1e-8)
    assert state.max_penetration <= 1e-12
    assert its == [2]


@pytest.mark.mpi
def test_patch_non_matching_force_balance() -> None:
    problem, body = _blocks(8, 11)
    _solve(problem, "gnrm", 2)
    state = problem.contact_state()
    top = problem.reaction(_facets(body, "top"))[1]
    bottom = problem.reaction(_facets(body, "bottom"))[1]
    # the load balances through the interface: top and bottom reactions to 1e-10
    assert abs(top + bottom) <= 1e-10 * state.contact_force
    # the normal-force magnitude differs from the vertical load by the tilt of the
    # deformed target facets (measured 1.2e-6 relative)
    assert abs(-top - state.contact_force) <= 1e-5 * state.contact_force
    # node-to-segment is not exact on non-matching meshes: measured deviation (8 vs 11)
    p = state.pressure
    spread = problem.comm.allreduce(float(np.ptp(p)) if p.size else 0.0, op=MPI.MAX)
    assert 0.2 < spread / 2.1978 < 0.3


@pytest.mark.parametrize(("method", "r"), [("penalty", 1.0), ("nua", 1.0), ("auto", 1.0),
                                           ("sua", 0.1)])
def test_strategies_on_two_bodies(method: str, r: float) -> None:
    """Every strategy on the non-matching patch (SUA cycles at r >= 1 E/h here: r = 0.1)."""
    problem, _ = _blocks(8, 11, r=r)
    if method == "sua":
        strategy = make_strategy("sua", problem, SolverSettings(max_iterations=200))
        for i in (1, 2):
            problem.set_load(i / 2)
            result = strategy.solve()
            assert result.converged and result.iterations <= 120
        assert abs(problem.contact_state().contact_force - 2.1941563995900544) < 1e-7
        return
    its = _solve(problem, method, 2)
    state = problem.contact_state()
    if method == "penalty":  # pressure / r penetration: r = 1 E/h
        assert 1e-4 < state.max_penetration < 1e-2
        assert sum(its) <= 8
    else:
        assert state.max_penetration < 1e-9
        assert abs(state.contact_force - 2.1941563995900544) < 1e-7


def _cylinders(h: float, r: float) -> ContactProblem:
    return cases.build(cases.two_cylinders(h, push=0.02), r)


@pytest.fixture(scope="module")
def cylinders() -> dict:
    out = {}
    for r in (1e-2, 1.0, 1e2):
        problem = _cylinders(0.02, r)
        its = _solve(problem, "gnrm", 3)
        state = problem.contact_state()
        x = np.concatenate(problem.comm.allgather(problem.nodal_coordinates()[:, 0]))
        p = np.concatenate(problem.comm.allgather(state.pressure))
        out[r] = (its, state, x, p)
    return out


@pytest.mark.mpi
def test_two_cylinders_hertz_small_mesh(cylinders: dict) -> None:
    """Coarse mesh (h = 0.02, a/h ~ 4): fitted a and p0 within 3 % of Hertz."""
    its, state, x, p = cylinders[1.0]
    assert all(i <= 6 for i in its)
    assert state.constraint_penetration < 1e-10 and state.max_penetration < 1e-6
    P = state.contact_force
    fit = fit_contact_profile(x, p)
    # two identical cylinders: R_eff = R/2, E* = E / (2 (1 - nu^2))
    assert abs(fit.a / half_width(P, 0.5, 100.0, 0.3) - 1) < 0.03
    assert abs(fit.p0 / peak_pressure(P, 0.5, 100.0, 0.3) - 1) < 0.03


@pytest.mark.mpi
def test_two_cylinders_gnrm_independent_of_r(cylinders: dict) -> None:
    ref = cylinders[1.0][1].contact_force
    for r in (1e-2, 1e2):
        assert abs(cylinders[r][1].contact_force - ref) <= 1e-8 * ref
        np.testing.assert_allclose(cylinders[r][3], cylinders[1.0][3], atol=1e-8 * 10)


@pytest.mark.mpi
def test_two_cylinders_serial_counts(cylinders: dict) -> None:
    """Newton counts and force measured in serial; 2 ranks must give the same."""
    its, state, _, _ = cylinders[1.0]
    assert its == EXPECTED_ITS
    assert abs(state.contact_force - EXPECTED_FORCE) <= 1e-10 * EXPECTED_FORCE


#: Measured in serial (3 steps, h = 0.02, r = 1 E/h).
EXPECTED_ITS = [6, 3, 3]
EXPECTED_FORCE = 1.073291683514986


def _order(residuals: list[float], floor: float = 1e-11) -> float:
    r = [v for v in residuals if v > floor]
    a, b, c = r[-3:]
    return float(np.log(c / b) / np.log(b / a))


def test_ironing_short() -> None:
    """Press, then slide 1.2 radii in 8 steps (coarse mesh): GNRM converges, no penetration."""
    problem, body = _with_mesh(cases.ironing(h_indenter=0.08, h_block=0.12, slide=0.6))
    from fenics_contact.solvers.predictor import Extrapolated
    from fenics_contact.solvers.stepping import solve_load_path

    strategy = Extrapolated(make_strategy("gnrm", problem, SolverSettings()))
    orders, vertical, depths = [], [], []

    def check(step) -> None:
        orders.append(_order(step.residuals[-1]))
        assert problem.contact_state().constraint_penetration <= 1e-8 * 0.5
        depths.append(step.max_penetration)
        vertical.append(problem.reaction(_facets(body, "top"))[1])

    path = solve_load_path(strategy, 10, max_cutbacks=3, on_step=check)
    assert path.converged and len(orders) == 10
    assert all(f < 0 for f in vertical[2:])  # the support keeps pushing the indenter down
    assert np.median(orders) >= 1.8, orders
    # nodes left on the extension of facets they passed sit slightly inside the deformed
    # block (node-to-segment); within the surface tolerance (measured: 3.6e-5 = 4.5e-4 h)
    assert max(depths) <= 1e-3 * problem.surface.h, depths


def test_ironing_mortar_sliding_force_a_fifth_of_node_to_segment() -> None:
    """Frictionless ironing on the shipped meshes: R_x (zero in the continuum) while
    sliding from 0.6 to 1.2 radii, sampled every 0.0068 (under a quarter of the striking
    face's facets). Measured: amplitude mortar 0.0048, node-to-segment 0.070 (ratio 0.068); the
    whole 2.4 radii in 250 steps: 0.0048 and 0.0688 (benchmarks/validation/ironing_mortar.py).
    """
    from benchmarks.validation.ironing_mortar import run

    runs = {d: run(d, False, SolverSettings().surface_tol, steps=110, slide=0.6,
                   window=(0.6, 1.2)) for d in ("node-to-segment", "mortar")}
    for r in runs.values():
        assert r["status"] == "converged" and r["cutbacks"] == 0 and r["steady_steps"] >= 40
    ratio = runs["mortar"]["rx_amplitude"] / runs["node-to-segment"]["rx_amplitude"]
    print({d: r["rx_amplitude"] for d, r in runs.items()}, ratio)
    assert ratio <= 0.2
    assert abs(runs["mortar"]["rx_mean"]) < 0.01 * abs(runs["mortar"]["ry_mean"])


# -- scenes ------------------------------------------------------------------------------
def test_two_body_scenes_load() -> None:
    from pathlib import Path

    from fenics_contact.scene.schema import load_scene

    root = Path(__file__).resolve().parents[1] / "scenes"
    for name in ("two_cylinders", "block_on_block", "ironing"):
        scene = load_scene(root / f"{name}.toml")
        assert scene.two_body and len(scene.bodies) == 2 and len(scene.pairs) == 1
    ironing = load_scene(root / "ironing.toml")
    assert ironing.dirichlet[1].path[-1] == (1.0, 1.2, -0.1)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda s: s.replace('striker = "striker_arc"', ""), "needs 'striker'"),
        (lambda s: s.replace('tag = "target"\n', ""), "needs 'tag'"),
        (lambda s: s + '\n[contact]\ntag = "x"\n', "[contact] belongs to single-body"),
        (lambda s: s + '\n[[pair]]\nname = "arcs"\nstriker = 3\ntarget = 4\n',
         "contact names ['arcs', 'arcs'] repeat"),
        (lambda s: s + '\n[obstacle]\ntype = "plane"\n', "give rigid obstacles as [[obstacle]]"),
        (lambda s: s.replace('value = [0.0, -0.02]', 'path = [[0.0, 0.0, 0.0], [0.5, 0.0]]'),
         "knot [0.5, 0.0]"),
        (lambda s: s.replace('value = [0.0, -0.02]',
                             'path = [[0.0, 0.0, 0.0], [0.5, 0.0, 1.0]]'), "must increase"),
        (lambda s: s.replace("relative = true", "relative = true\nmu = -0.1"),
         "[[pair]] mu = -0.1: the friction coefficient must be >= 0"),
        (lambda s: s + '\n[output]\nfields = ["slip"]\n',
         "friction fields need [[pair]] or [[obstacle]] mu"),
    ],
)
def test_two_body_scene_errors(tmp_path, edit, message: str) -> None:
    from pathlib import Path

    from fenics_contact.scene.schema import SceneError, load_scene

    scenes = Path(__file__).resolve().parents[1] / "scenes"
    text = (scenes / "two_cylinders_node_to_segment.toml").read_text()
    path = tmp_path / "bad.toml"
    path.write_text(edit(text).replace("../meshes", str(Path(__file__).parents[1] / "meshes")))
    with pytest.raises(SceneError, match=__import__("re").escape(message)):
        load_scene(path)


@pytest.mark.slow
def test_two_hemispheres_hertz_coarse() -> None:
    """3D quarter model, h = 0.05 at the poles: contact radius and peak within 3 % of Hertz.

    Slow only through the first FFCx compilation of the 3D forms (about a minute).
    """
    import dataclasses
    from pathlib import Path

    from fenics_contact import build_problem, load_scene
    from fenics_contact.references.hertz3d import hertz_point_contact

    # the shipped quarter model: flat faces pushed 0.02 closer, symmetric on x = 0, y = 0
    scenes = Path(__file__).resolve().parents[1] / "scenes"
    scene = load_scene(scenes / "two_hemispheres_3d_node_to_segment.toml")
    scene = dataclasses.replace(scene, mesh=dataclasses.replace(
        scene.mesh, parameters={**scene.mesh.parameters, "h_contact": 0.05}))
    assert scene.dirichlet[0].value == (None, None, -0.02)
    problem = build_problem(with_contact_settings(scene, 1.0, relative=True))
    its = _solve(problem, "gnrm", 2)
    assert all(i <= 6 for i in its)
    state = problem.contact_state()
    assert state.constraint_penetration < 1e-10 and state.max_penetration < 1e-6
    r = np.concatenate(problem.comm.allgather(
        np.linalg.norm(problem.nodal_coordinates()[:, :2], axis=1)))
    p = np.concatenate(problem.comm.allgather(state.pressure))
    fit = fit_contact_profile(r, p)
    # two identical spheres: R_eff = R/2, E* = E / (2 (1 - nu^2)); 4 quarters
    force = 4 * problem.comm.allreduce(state.contact_force, op=MPI.MAX)
    hertz = hertz_point_contact(force, 0.5, 100.0, 0.3)
    assert abs(fit.a / hertz.a - 1) < 0.03
    assert abs(fit.p0 / hertz.p0 - 1) < 0.03


@pytest.mark.mpi
def test_target_force_balances_contact_force() -> None:
    """The force handed to the target's vertices sums to the striker's contact force."""
    problem, body = _blocks(8, 11)
    _solve(problem, "gnrm", 1)
    f = problem.target_force()
    n = problem.V.dofmap.index_map.size_local
    total = problem.comm.allreduce(f.x.array[: 2 * n].reshape(-1, 2).sum(axis=0), op=MPI.SUM)
    state = problem.contact_state()
    # pressed down: the target is pushed in -y by the normal force (nearly flat interface)
    assert abs(total[1] + state.contact_force) <= 1e-5 * state.contact_force  # facet tilt
    bottom = problem.reaction(_facets(body, "bottom"))[1]
    assert abs(total[1] + bottom) <= 1e-10 * state.contact_force


def test_two_body_problem_errors() -> None:
    md = build_mesh(cases.block_on_block(2, 2))
    law = material("linear", 200.0, 0.3)
    bodies = [Body("upper", md.cell_names["striker"], law),
              Body("lower", md.cell_names["target"], law)]
    s, t = _facets(md, "striker_face"), _facets(md, "target_face")
    with pytest.raises(ValueError, match="share facets"):
        two_body_problem(md.domain, md.cell_tags, bodies, s, s, ContactSettings())
    with pytest.raises(ValueError, match="quadrature = 'nodal'"):
        two_body_problem(md.domain, md.cell_tags, bodies, s, t,
                         ContactSettings(quadrature="gauss"))
    with pytest.raises(ValueError, match="cell tag 9"):
        two_body_problem(md.domain, md.cell_tags, [bodies[0], Body("x", 9, law)], s, t,
                         ContactSettings())
    with pytest.raises(ValueError, match="not among the bodies"):
        two_body_problem(md.domain, md.cell_tags, bodies, s, t, ContactSettings(),
                         striker="top")


def test_stability_grid_two_body_case() -> None:
    """Two-body stability cases run through the same driver: auto at r = 1e8 E/h."""
    from benchmarks.robustness.stability_grid import full_grid
    from fenics_contact.sweeps.stability import run_case, select

    groups = {c.group for c in full_grid()}
    assert {"two-body-r", "two-body-stiffness", "two-body-sliding"} <= groups
    (case,) = select(full_grid(), ["two-cyl-r1e8"])
    record = run_case(case, "auto")
    assert record.status == "converged", record.message
    assert record.steps_completed == 3 and record.max_penetration < 1e-6
    assert record.iterations <= 20
    assert abs(record.contact_force - EXPECTED_FORCE) <= 1e-6 * EXPECTED_FORCE


def test_penetration_depth_of_points_near_a_concave_kink() -> None:
    """The closest-point depth sees a point past the end of one facet that is inside the next."""
    from fenics_contact.model.search import penetration_depth

    # a valley: facets (-1, 1) -> (0, 0) -> (1, 1), oriented so the normals point up (outside)
    valley = np.array([[[-1.0, 1.0], [0.0, 0.0]], [[0.0, 0.0], [1.0, 1.0]]])[:, ::-1]
    valley = np.array([valley[1], valley[0]])
    points = np.array([[0.1, 0.05], [0.1, 0.2], [-0.3, 0.2], [0.0, -0.1], [2.0, 1.5]])
    # (0.1, 0.05): on the extension of the left facet's plane (gap 0.1/sqrt2 > 0 to it) but
    # 0.05/sqrt2 inside the right one
    expected = [0.05 / np.sqrt(2), 0.0, 0.1 / np.sqrt(2), 0.1, 0.0]
    np.testing.assert_allclose(penetration_depth(points, valley), expected, atol=1e-15)


def test_reported_penetration_is_into_the_actual_target_surface(cylinders: dict) -> None:
    """A node left on the extension of its facet at a kink of the deformed target is seen.

    The apex node of the upper cylinder sits over a target vertex; the search's
    hysteresis keeps it on the extension of the facet it had, where the
    deformed target is slightly concave: it lies inside the next facet by
    about 1.5e-7 while its gap to its own facet's plane is round-off.
    """
    problem = _cylinders(0.02, 1e-2)
    _solve(problem, "gnrm", 3)
    state = problem.contact_state()
    pair = problem.pair
    current = (pair.X_vertices + pair.target_displacements())[pair.facet_vertex]
    points = pair.striker_positions()[: pair.n_owned]
    # independent: below the target polyline (top of the lower body), by the closest distance
    verts = current.reshape(-1, 2)
    order = np.argsort(verts[:, 0])
    below = points[:, 1] < np.interp(points[:, 0], verts[order, 0], verts[order, 1])
    a, b = current[None, :, 0], current[None, :, 1]
    t = b - a
    xi = np.clip(np.einsum("nmi,nmi->nm", points[:, None] - a, t) / np.einsum("nmi,nmi->nm", t, t),
                 0, 1)
    dist = np.linalg.norm(points[:, None] - (a + xi[..., None] * t), axis=-1).min(axis=1)
    deepest = problem.comm.allreduce(float(np.max(np.where(below, dist, 0.0), initial=0.0)),
                                     op=MPI.MAX)
    assert 1e-8 < deepest < 1e-6
    assert state.max_penetration == pytest.approx(deepest, rel=1e-9)
    assert state.constraint_penetration < 1e-12  # the discretisation's own gap sees nothing
    # the Signorini check refuses it once the tolerance is below it
    from fenics_contact.solvers.diagnostics import signorini_admissibility

    check = signorini_admissibility(problem, SolverSettings(surface_tol=1e-7))
    assert "penetration into the target surface" in check()
    assert signorini_admissibility(problem, SolverSettings())() is None


def test_a_step_refused_by_the_surface_check_says_why() -> None:
    """A load step whose residual converged but whose iterate the Signorini test refuses
    fails with a message naming the refusal (not a bare ``max_iterations``) and the cure."""
    from fenics_contact.solvers.stepping import solve_load_path

    problem = _cylinders(0.02, 1e-2)
    settings = SolverSettings(surface_tol=1e-7, max_iterations=8)
    path = solve_load_path(make_strategy("gnrm", problem, settings), 3, max_cutbacks=1)
    failed = path.steps[-1]
    assert path.status == "max_iterations" and failed.status == "max_iterations"
    assert failed.message.startswith("max_iterations at load factor")
    assert ("the residual met its tolerance but the iterate was refused: penetration into "
            "the target surface") in failed.message
    assert 'discretisation = "mortar"' in failed.message
