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
    strategy = make_strategy("gnrm", problem, SolverSettings(atol=1e-10))
    record = solve_load_path(strategy, n_steps=4)        # a RunRecord
    # or all of it, with XDMF/JSON/pictures: run_scene(scene, Path("results/x"))

Layers (each imports only those above it in this list): ``model`` (materials,
obstacles, contact terms, the problem and its UFL systems), ``solvers``
(Newton kernel, strategies, load stepping, the run record), ``scene`` (TOML
schema, meshes, building) and ``output`` (XDMF, JSON, pictures),
``verification`` (problems with known answers), ``studies`` (sweeps),
``runner`` and ``cli``.
"""

from __future__ import annotations

import importlib
from typing import Any

try:  # the wheel build of DOLFINx must be imported before dolfinx/petsc4py
    import dolfinx_solver  # noqa: F401
except ImportError:  # DOLFINx installed otherwise (official images)
    pass

__version__ = "0.1.0"

#: Public names and the modules that define them (imported on first use, so
#: that ``import fenics_contact`` stays cheap).
_PUBLIC = {
    "load_scene": "fenics_contact.scene.schema",
    "Scene": "fenics_contact.scene.schema",
    "SceneError": "fenics_contact.scene.schema",
    "build_problem": "fenics_contact.scene.build",
    "ContactProblem": "fenics_contact.model.problem",
    "PrescribedDisplacement": "fenics_contact.model.problem",
    "SurfaceTraction": "fenics_contact.model.problem",
    "ContactSettings": "fenics_contact.model.contact",
    "material": "fenics_contact.model.materials",
    "RigidPlane": "fenics_contact.model.obstacles",
    "RigidBall": "fenics_contact.model.obstacles",
    "SolverSettings": "fenics_contact.solvers.diagnostics",
    "Status": "fenics_contact.solvers.diagnostics",
    "LinearSolverSettings": "fenics_contact.solvers.linear",
    "make_strategy": "fenics_contact.solvers",
    "STRATEGIES": "fenics_contact.solvers",
    "solve_load_path": "fenics_contact.solvers.stepping",
    "RunRecord": "fenics_contact.solvers.stepping",
    "StepRecord": "fenics_contact.solvers.stepping",
    "run_scene": "fenics_contact.runner",
}

__all__ = sorted(_PUBLIC)


def __getattr__(name: str) -> Any:
    """Import a public name from its module on first access."""
    try:
        module = _PUBLIC[name]
    except KeyError:
        raise AttributeError(f"module 'fenics_contact' has no attribute {name!r}") from None
    return getattr(importlib.import_module(module), name)


def __dir__() -> list[str]:
    return sorted([*globals(), *_PUBLIC])
