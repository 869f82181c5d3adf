"""Cattaneo-Mindlin runs: the cylinder on a plane and the two-cylinder scene, measured.

The theory and the measurements (stick zone, contact profile, Hertz fit)
are the package's (:mod:`fenics_contact.references.cattaneo`); this module
drives the solvers over the load paths. :class:`CattaneoCylinder` is the
interim single-body check (a half-cylinder on a rigid plane, Dundurs beta
small but not zero, with an optional P2 displacement that no scene
expresses); ``scenes/cattaneo_mindlin_node_to_segment.toml`` is the two-body case.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from mpi4py import MPI

from benchmarks.cases import hertz_cylinder
from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.friction import FrictionSettings
from fenics_contact.model.materials import LinearElastic
from fenics_contact.model.obstacles import RigidPlane
from fenics_contact.model.problem import ContactProblem, PrescribedDisplacement, one_body_problem
from fenics_contact.references.cattaneo import (
    CentredFit,
    ContactProfile,
    StickZone,
    contact_profile,
    hertz_fit,
    measure_stick_zone,
    two_cylinders_hertz,
)
from fenics_contact.references.hertz import HertzSolution
from fenics_contact.scene.build import _restricted, build_mesh, tagged_facets
from fenics_contact.scene.schema import FIELDS, Scene
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.stepping import RunRecord, StepRecord


@dataclass(frozen=True)
class CattaneoCylinder:
    """A small-strain half-cylinder (R, E, nu) on a rigid plane with friction mu.

    Attributes:
        radius: R (length).
        E: Young's modulus (stress).
        nu: Poisson's ratio (close to 0.5 for beta ~ 0).
        mu: friction coefficient.
        push: upward plane displacement, reached at load factor ``press_until`` (length).
        shift: sideways plane displacement at load factor 1 (length).
        press_until: load factor at which pressing ends and the shift starts.
        h_contact: element size near contact (length).
        fine_radius: radius meshed at ``h_contact`` (length).
        contact_band: candidate facets have midpoints below contact_band * R.
        degree: displacement degree (2 avoids the volumetric locking of P1
            triangles at nu -> 0.5, which makes nodal tractions oscillate).
    """

    radius: float = 1.0
    E: float = 200.0
    nu: float = 0.45
    mu: float = 0.3
    push: float = 0.01
    shift: float = 0.002
    press_until: float = 0.5
    h_contact: float = 0.004
    fine_radius: float = 0.15
    contact_band: float = 0.02
    degree: int = 1

    @property
    def dundurs_beta(self) -> float:
        """Dundurs' beta of an elastic body on a rigid plane (plane strain)."""
        return (1.0 - 2.0 * self.nu) / (2.0 * (1.0 - self.nu))

    def build(
        self, settings: ContactSettings, comm: MPI.Comm = MPI.COMM_WORLD
    ) -> ContactProblem:
        """Mesh the half-disk and create the frictional problem (plane on a schedule)."""
        scene = hertz_cylinder(self.h_contact, radius=self.radius, E=self.E, nu=self.nu,
                               fine_radius=self.fine_radius, contact_band=self.contact_band)
        body = build_mesh(scene, comm)
        domain = body.domain
        band = _restricted(body, tagged_facets(body, scene, "contact", "contact"),
                           scene.contact)
        top = tagged_facets(body, scene, "dirichlet", "top")
        plane = RigidPlane(domain, point=(0.0, 0.0), normal=(0.0, 1.0))
        schedule = [
            (0.0, 0.0, 0.0), (self.press_until, 0.0, self.push), (1.0, self.shift, self.push)
        ]
        return one_body_problem(
            domain, LinearElastic(E=self.E, nu=self.nu), plane, band, settings,
            prescribed=[PrescribedDisplacement(top, (0.0, 0.0))],
            obstacle_schedule=schedule, friction=FrictionSettings(self.mu), degree=self.degree,
        )


def solve_cattaneo(
    cylinder: CattaneoCylinder,
    settings: ContactSettings | None = None,
    *,
    press_steps: int = 4,
    shear_steps: int = 8,
    frictionless_press: bool = True,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> tuple[ContactProblem, list[StickZone], list[int]]:
    """Press (frictionless unless told), then shear; measure the stick zone each shear step.

    GNRM at r = 0.01 E/h (nodal) unless ``settings`` say otherwise. Returns the
    problem, one :class:`StickZone` per shear step and the Newton iterations of
    every step. Raises RuntimeError when a step does not converge.
    """
    problem = cylinder.build(settings or ContactSettings(r=0.01), comm)
    strategy = make_strategy(
        "gnrm", problem, SolverSettings(atol=1e-10, rtol=1e-10, max_iterations=60),
        predictor="previous",
    )
    mu = problem.friction_coefficient
    zones: list[StickZone] = []
    iterations: list[int] = []
    if frictionless_press:
        problem.mu.value = 0.0
    loads = [cylinder.press_until * k / press_steps for k in range(1, press_steps + 1)]
    loads += [
        cylinder.press_until + (1.0 - cylinder.press_until) * k / shear_steps
        for k in range(1, shear_steps + 1)
    ]
    for k, t in enumerate(loads):
        if k == press_steps:
            problem.mu.value = mu
        problem.commit()
        problem.set_load(t)
        result = strategy.solve()
        if not result.converged:
            raise RuntimeError(f"Cattaneo-Mindlin step at load {t:g}: {result.status.value}.")
        iterations.append(result.iterations)
        if k >= press_steps:
            zones.append(measure_stick_zone(problem))
    return problem, zones, iterations


# -- two identical cylinders (Dundurs beta = 0): scenes/cattaneo_mindlin*.toml --------------
@dataclass
class CattaneoRun:
    """A solved two-body Cattaneo-Mindlin scene.

    Attributes:
        problem: the solved problem (final state).
        record: steps, iterations and status of the load path.
        zones: one :class:`StickZone` per converged step after pressing.
        load_factors: the load factor of each zone.
        reactions: force (x, y) the prescribed path exerts on the loaded
            body at each zone (force per thickness): a check of Q and P
            independent of the contact term.
        profiles: the nodal contact profile of each zone.
        pressed: Hertz fit at the end of pressing (None if no step ends there).
        pressed_force: normal contact force at the end of pressing.
    """

    problem: ContactProblem
    record: RunRecord
    zones: list[StickZone]
    load_factors: list[float]
    reactions: list[np.ndarray]
    profiles: list[ContactProfile]
    pressed: CentredFit | None = None
    pressed_force: float = float("nan")


def shear_start(scene: Scene) -> tuple[int, float]:
    """Index of the [[dirichlet]] block with a path and the load factor where it starts shifting.

    The shift is the first component of the path; pressing is the part
    before it moves. Raises ValueError when no path shifts sideways.
    """
    for i, spec in enumerate(scene.dirichlet):
        if spec.path:
            knots = np.asarray(spec.path, dtype=float)
            moved = np.nonzero(knots[:, 1] != knots[0, 1])[0]
            if moved.size:
                return i, float(knots[moved[0] - 1, 0])
    raise ValueError(
        f"{scene.path.name}: no [[dirichlet]] path shifts sideways; give one as "
        "path = [[0, 0, 0], [t_press, 0, -d], [1, s, -d]]."
    )


def _solve_scene(
    scene: Scene,
    comm: MPI.Comm,
    on_step: Callable[[ContactProblem, np.ndarray, StepRecord], None] | None = None,
    loaded: int | str | None = None,
) -> tuple[ContactProblem, RunRecord]:
    """Build a two-body scene and solve its load path with its own solver settings.

    Nothing is written; ``on_step(problem, facets, step)`` after each
    converged step, ``facets`` those of the facet tag ``loaded``. Raises
    RuntimeError when the load path stops before load factor 1.
    """
    from fenics_contact.scene.build import build_mesh, build_two_body_problem, tagged_facets
    from fenics_contact.solvers.linear import LinearSolverSettings
    from fenics_contact.solvers.stepping import solve_load_path

    body = build_mesh(scene, comm)
    problem = build_two_body_problem(scene, body)
    facets = tagged_facets(body, scene, "loaded", loaded) if loaded is not None else None
    solver = scene.solver
    strategy = make_strategy(
        solver.method, problem,
        SolverSettings(atol=solver.atol, rtol=solver.rtol, max_iterations=solver.max_iterations),
        linear=LinearSolverSettings(kind=solver.linear_solver), predictor=solver.predictor,
        contact_set=solver.contact_set,
    )
    record = solve_load_path(
        strategy, solver.steps, max_cutbacks=solver.max_cutbacks,
        on_step=None if on_step is None else lambda step: on_step(problem, facets, step),
    )
    if not record.converged:
        raise RuntimeError(
            f"{scene.path.name}: the load path stopped at load factor "
            f"{record.steps[-1].load_factor:g} ({record.status})."
        )
    return problem, record


def solve_cattaneo_mindlin(scene: Scene, comm: MPI.Comm = MPI.COMM_WORLD) -> CattaneoRun:
    """Solve a two-body friction scene along its path; measure the stick zone after pressing.

    The scene's solver settings (method, tolerances, predictor, steps,
    cut-backs) are used; nothing is written. The reaction is taken on the
    facets of the [[dirichlet]] block that carries the path.
    """
    index, t_shear = shear_start(scene)
    zones: list[StickZone] = []
    loads: list[float] = []
    reactions: list[np.ndarray] = []
    profiles: list[ContactProfile] = []
    pressed: list = []

    def measure(problem: ContactProblem, loaded: np.ndarray, step: StepRecord) -> None:
        if abs(step.load_factor - t_shear) <= 1e-12:
            pressed.extend([hertz_fit(contact_profile(problem)), step.contact_force])
        if step.load_factor > t_shear + 1e-12:
            profiles.append(contact_profile(problem))
            zones.append(measure_stick_zone(problem, profiles[-1]))
            loads.append(step.load_factor)
            reactions.append(problem.reaction(loaded))  # type: ignore[attr-defined]

    problem, record = _solve_scene(scene, comm, measure, loaded=scene.dirichlet[index].tag)
    return CattaneoRun(problem, record, zones, loads, reactions, profiles, *pressed)


def pressing_scene(scene: Scene) -> Scene:
    """The scene up to the end of pressing, frictionless: the path's knots before the shift.

    Load factors are rescaled to 0 ... 1 and the steps cut in proportion,
    so the last step is the pressed state of the frictional run.
    """
    index, t_shear = shear_start(scene)
    spec = scene.dirichlet[index]
    knots = tuple((t / t_shear, *rest) for t, *rest in spec.path if t <= t_shear + 1e-12)
    dirichlet = list(scene.dirichlet)
    dirichlet[index] = replace(spec, path=knots)
    pairs = tuple(replace(pair, mu=None) for pair in scene.pairs)
    return replace(
        scene, dirichlet=tuple(dirichlet), pairs=pairs,
        contact=replace(scene.contact, mu=None), fields=FIELDS,
        solver=replace(scene.solver, steps=max(1, round(scene.solver.steps * t_shear))),
    )


def pressing_check(
    scene: Scene, R: float = 1.0, comm: MPI.Comm = MPI.COMM_WORLD
) -> tuple[float, CentredFit, HertzSolution]:
    """Frictionless pressing of a two-identical-cylinder scene against Hertz.

    Returns the normal contact force P, the fitted ellipse and Hertz for two
    identical cylinders of radius R with the first body's E and nu at P.
    """
    press = pressing_scene(scene)
    problem, record = _solve_scene(press, comm)
    P = record.steps[-1].contact_force
    body = scene.bodies[0]
    return P, hertz_fit(contact_profile(problem)), two_cylinders_hertz(P, R, body.E, body.nu)
