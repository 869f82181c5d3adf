"""Variants of a validated scene: the same problem with other contact or solver settings.

The sweeps (``study``, ``tradeoff``, ``stability``) run one scene at many r
and strategies; these functions give each run its scene, so every run is
built by :func:`~fenics_contact.scene.build.build_problem` from a scene.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from fenics_contact.model.contact import Quadrature
from fenics_contact.scene.spec import Scene


def with_contact_settings(
    scene: Scene, r: float, relative: bool, quadrature: Quadrature | None = None
) -> Scene:
    """The scene with r (stress/length, or relative to E/h) on every contact.

    ``quadrature`` (rigid obstacles only; pairs are nodal) None keeps each
    contact's own.
    """
    pairs = tuple(replace(p, r=r, relative=relative) for p in scene.pairs)
    obstacles = tuple(
        replace(o, contact=replace(o.contact, r=r, relative=relative,
                                   quadrature=quadrature or o.contact.quadrature))
        for o in scene.obstacles
    )
    pairing = scene.pairing and replace(scene.pairing, r=r, relative=relative)
    if len(obstacles) == 1 and scene.obstacle.type != "none":
        return replace(scene, contact=obstacles[0].contact, pairs=pairs, pairing=pairing)
    return replace(scene, obstacles=obstacles, pairs=pairs, pairing=pairing)


def with_solver(scene: Scene, **settings: Any) -> Scene:
    """The scene with some [solver] keys changed (method, steps, rtol, predictor, ...)."""
    return replace(scene, solver=replace(scene.solver, **settings))


def with_mesh_parameters(scene: Scene, **parameters: float) -> Scene:
    """The scene with some [mesh] parameters of its .geo changed (h_contact, ...)."""
    merged = {**scene.mesh.parameters, **parameters}
    return replace(scene, mesh=replace(scene.mesh, parameters=merged))
