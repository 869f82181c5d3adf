"""fenics-contact: contact of hyperelastic bodies on FEniCSx.

The contact term (penalty or the Alart-Curnier augmented Lagrangian) is a UFL
form on a mixed displacement/multiplier space whose multiplier lives on a
submesh of the candidate contact facets. Every tangent comes from
``ufl.derivative``. Solution strategies (penalty, Uzawa, generalized Newton)
are Python drivers over one Newton kernel.

Sign convention: the gap ``g`` is positive when open; the multiplier
``lam <= 0`` is the normal contact pressure (force per reference area).

The public API, in the order a run uses it::

    scene = load_scene("scenes/hertz_cylinder.toml")     # validated description
    problem = build_problem(scene)                       # mesh, spaces, UFL forms
    strategy = scene_strategy(scene, problem)            # the scene's [solver]
    # or: make_strategy("gnrm", problem, SolverSettings(atol=1e-10))
    record = solve_load_path(strategy, n_steps=4)        # a RunRecord
    # or all of it, with XDMF/JSON/pictures: run_scene(scene, Path("results/x"))

Layers (each imports only those above it in this list): ``model`` (materials,
obstacles, contact terms, the problem and its UFL systems), ``references``
(Hertz, Cattaneo-Mindlin: closed forms and the measurements against them),
``solvers`` (Newton kernel, strategies, load stepping, the run record),
``scene`` (TOML schema, meshes, building) and ``output`` (XDMF, JSON,
pictures), ``sweeps`` (method x r studies, speed against accuracy,
stability), ``runner`` and ``cli``. The laboratory (the paper's studies, the
sweeps' case lists, the benchmarks) is ``benchmarks/``, outside the package.
"""

from __future__ import annotations

try:  # the wheel build of DOLFINx must be imported before dolfinx/petsc4py
    import dolfinx_solver  # noqa: F401
except ImportError:  # DOLFINx installed otherwise (official images)
    pass

from fenics_contact import form_compiler
from fenics_contact.model.body import Body, Solid
from fenics_contact.model.compositions import one_body_problem, two_body_problem
from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.friction import FrictionSettings
from fenics_contact.model.materials import material
from fenics_contact.model.mortar import MortarContact
from fenics_contact.model.obstacle_contact import ObstacleContact
from fenics_contact.model.obstacles import RigidBall, RigidPlane
from fenics_contact.model.pairs import NodeToSegmentContact
from fenics_contact.model.problem import (
    ContactProblem,
    PrescribedDisplacement,
    SurfaceTraction,
)
from fenics_contact.runner import run_scene, scene_strategy
from fenics_contact.scene.build import build_problem
from fenics_contact.scene.schema import Scene, SceneError, load_scene, scene_from_data
from fenics_contact.solvers import STRATEGIES, make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings, Status
from fenics_contact.solvers.linear import LinearSolverSettings
from fenics_contact.solvers.stepping import RunRecord, StepRecord, solve_load_path

form_compiler.install()  # FFCx's value numbering in linear time (see form_compiler)

__version__ = "0.1.0"

__all__ = [
    "STRATEGIES",
    "Body",
    "ContactProblem",
    "ContactSettings",
    "FrictionSettings",
    "LinearSolverSettings",
    "MortarContact",
    "NodeToSegmentContact",
    "ObstacleContact",
    "PrescribedDisplacement",
    "RigidBall",
    "RigidPlane",
    "RunRecord",
    "Scene",
    "SceneError",
    "Solid",
    "SolverSettings",
    "Status",
    "StepRecord",
    "SurfaceTraction",
    "build_problem",
    "load_scene",
    "make_strategy",
    "material",
    "one_body_problem",
    "run_scene",
    "scene_from_data",
    "scene_strategy",
    "solve_load_path",
    "two_body_problem",
]
