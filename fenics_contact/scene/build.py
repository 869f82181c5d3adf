"""Turn a validated :class:`~fenics_contact.scene.schema.Scene` into a contact problem.

Builds the mesh (gmsh .geo/.msh or a generator), resolves facet tags by
number or physical name, and creates only what the scene declares. Tag and
dimension mistakes that need the mesh to be seen are reported here, still
before any form is compiled.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from dolfinx import mesh

from mpi4py import MPI

from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.materials import material
from fenics_contact.model.obstacles import RigidBall, RigidObstacle, RigidPlane
from fenics_contact.model.problem import ContactProblem, PrescribedDisplacement, SurfaceTraction
from fenics_contact.scene.meshing import mesh_on_rank, open_geo
from fenics_contact.scene.schema import GENERATOR_TAGS, BoundarySpec, Scene, SceneError


@dataclass
class BodyMesh:
    """A mesh with its facet tags and the names of its physical groups."""

    domain: mesh.Mesh
    facet_tags: mesh.MeshTags
    names: dict[str, int]


def _generated(scene: Scene, comm: MPI.Comm) -> BodyMesh:
    spec = scene.mesh
    lo = np.array(spec.origin, dtype=float)
    hi = lo + np.array(spec.size, dtype=float)
    if spec.generator == "rectangle":
        cell = mesh.CellType[spec.cell]
        domain = mesh.create_rectangle(comm, [lo, hi], list(spec.cells), cell)
    else:
        cell = mesh.CellType[spec.cell]
        domain = mesh.create_box(comm, [lo, hi], list(spec.cells), cell)
    names = GENERATOR_TAGS[spec.generator]  # type: ignore[index]
    fdim = domain.topology.dim - 1
    facets, values = [], []
    for axis in range(domain.topology.dim):
        for side, coordinate in enumerate((lo[axis], hi[axis])):
            found = mesh.locate_entities_boundary(
                domain, fdim, lambda x, a=axis, c=coordinate: np.isclose(x[a], c)
            )
            facets.append(found)
            values.append(np.full(found.size, 2 * axis + side + 1, dtype=np.int32))
    all_facets = np.concatenate(facets)
    all_values = np.concatenate(values)
    # a facet on two sides cannot exist; edges shared by sides are not facets in 2D/3D
    order = np.argsort(all_facets, kind="stable")
    unique, first = np.unique(all_facets[order], return_index=True)
    tags = mesh.meshtags(domain, fdim, unique, all_values[order][first])
    return BodyMesh(domain, tags, dict(names))


def _open(gmsh: Any, scene: Scene) -> None:
    """Load the scene's .geo (parameters set) or .msh into the current gmsh session."""
    gmsh.option.setNumber("General.Terminal", 0)
    try:
        open_geo(gmsh, scene.mesh.file, scene.mesh.parameters)
    except ValueError as exc:
        raise SceneError(f"{scene.path.name}: [mesh] parameters: {exc}") from None


def _physical_dimensions(scene: Scene, comm: MPI.Comm) -> set[int]:
    """Dimensions of the file's physical groups (read on rank 0, known to all)."""
    import gmsh

    found: set[int] | SceneError = set()
    if comm.rank == 0:
        started = not gmsh.isInitialized()
        if started:
            gmsh.initialize(interruptible=False)
        try:
            _open(gmsh, scene)
            found = {d for d, _ in gmsh.model.getPhysicalGroups()}
        except SceneError as exc:
            found = exc  # told to every rank below, so that none waits forever
        finally:
            gmsh.finalize() if started else gmsh.model.remove()
    found = comm.bcast(found, root=0)
    if isinstance(found, SceneError):
        raise found
    return found


def _from_gmsh(scene: Scene, comm: MPI.Comm) -> BodyMesh:
    spec = scene.mesh
    assert spec.file is not None
    dims = _physical_dimensions(scene, comm)
    if scene.dimension not in dims:
        raise SceneError(
            f"{scene.path.name}: [scene] dimension = {scene.dimension}, but the mesh "
            f"{spec.file.name} has no {scene.dimension}D physical group; set the "
            "dimension to the mesh's or add a physical group for the body."
        )

    def build(gmsh: Any) -> None:
        _open(gmsh, scene)
        if spec.file is not None and spec.file.suffix == ".geo":
            gmsh.model.mesh.generate(scene.dimension)

    data = mesh_on_rank(comm, 0, scene.dimension, build)
    if data.facet_tags is None:
        raise SceneError(f"{spec.file}: the mesh has no physical groups on its boundary.")
    fdim = scene.dimension - 1
    names = {
        name: group.tag for name, group in data.physical_groups.items() if group.dim == fdim
    }
    return BodyMesh(data.mesh, data.facet_tags, names)


def build_mesh(scene: Scene, comm: MPI.Comm = MPI.COMM_WORLD) -> BodyMesh:
    """Create the body mesh the scene asks for."""
    return _from_gmsh(scene, comm) if scene.mesh.file is not None else _generated(scene, comm)


def tagged_facets(body: BodyMesh, scene: Scene, section: str, tag: int | str) -> np.ndarray:
    """Facets carrying ``tag`` (a number or a physical name); errors name the choices."""
    number = body.names.get(tag) if isinstance(tag, str) else tag
    comm = body.domain.comm
    available = sorted(set(comm.allreduce(body.facet_tags.values.tolist(), op=MPI.SUM)))
    named = ", ".join(f"{n} = {t}" for n, t in sorted(body.names.items(), key=lambda kv: kv[1]))
    if number is None or number not in available:
        raise SceneError(
            f"{scene.path.name}: [{section}] tag = {tag!r} is not a facet tag of the mesh; "
            f"available: {named or ', '.join(map(str, available))}."
        )
    return body.facet_tags.find(number)


def _restricted(body: BodyMesh, facets: np.ndarray, spec: BoundarySpec) -> np.ndarray:
    if not spec.bounds:
        return facets
    fdim = body.domain.topology.dim - 1
    midpoints = mesh.compute_midpoints(body.domain, fdim, facets)
    keep = np.ones(facets.size, dtype=bool)
    for axis, (lo, hi) in spec.bounds.items():
        tol = 1e-10 * max(1.0, abs(lo), abs(hi))
        keep &= (midpoints[:, axis] >= lo - tol) & (midpoints[:, axis] <= hi + tol)
    return facets[keep]


def build_obstacle(scene: Scene, domain: mesh.Mesh) -> RigidObstacle:
    """The scene's rigid obstacle, placed by dolfinx Constants."""
    spec = scene.obstacle
    if spec.type == "plane":
        return RigidPlane(domain, spec.point, spec.normal)
    return RigidBall(domain, spec.point, spec.radius, inside=spec.inside)


def contact_facets(scene: Scene, body: BodyMesh, obstacle: RigidObstacle) -> np.ndarray:
    """Candidate contact facets: by tag, or detected along the obstacle's path."""
    spec = scene.contact
    if spec.tag is not None:
        return tagged_facets(body, scene, "contact", spec.tag)
    from fenics_contact.model.candidates import detect_candidate_facets

    pushes = [abs(v) for d in scene.dirichlet for v in d.value if v is not None]
    return detect_candidate_facets(
        body.domain, obstacle, scene.obstacle.motion, spec.margin,
        displacement_bound=max(pushes, default=0.0),
    )


def build_problem(scene: Scene, comm: MPI.Comm = MPI.COMM_WORLD) -> ContactProblem:
    """Mesh, material, conditions, obstacle and contact surface of a scene."""
    body = build_mesh(scene, comm)
    if body.domain.geometry.dim != scene.dimension:
        raise SceneError(
            f"{scene.path.name}: [scene] dimension = {scene.dimension} but the mesh is "
            f"{body.domain.geometry.dim}D."
        )
    prescribed = []
    for i, spec in enumerate(scene.dirichlet):
        facets = _restricted(body, tagged_facets(body, scene, f"dirichlet {i + 1}", spec.tag), spec)
        if comm.allreduce(facets.size, op=MPI.SUM) == 0:
            raise SceneError(
                f"{scene.path.name}: [[dirichlet]] {i + 1} selects no facet; widen its bounds."
            )
        prescribed.append(PrescribedDisplacement(facets, spec.value))
    tractions = [
        SurfaceTraction(
            _restricted(body, tagged_facets(body, scene, f"traction {i + 1}", spec.tag), spec),
            tuple(float(v) for v in spec.value if v is not None),
        )
        for i, spec in enumerate(scene.tractions)
    ]
    obstacle = build_obstacle(scene, body.domain)
    settings = ContactSettings(
        r=scene.contact.r, relative=scene.contact.relative,
        quadrature=scene.contact.quadrature,  # type: ignore[arg-type]
    )
    args = (
        body.domain,
        material(scene.law, scene.E, scene.nu),
        obstacle,
        contact_facets(scene, body, obstacle),
        settings,
    )
    options: dict[str, Any] = {
        "prescribed": prescribed,
        "tractions": tractions,
        "obstacle_motion": scene.obstacle.motion,
        "obstacle_schedule": scene.obstacle.schedule or None,
    }
    if scene.contact.mu is not None:
        from fenics_contact.model.friction import FrictionalContactProblem

        return FrictionalContactProblem(
            *args, mu=scene.contact.mu, tangential_r_max=scene.contact.tangential_r_max,
            **options,
        )
    return ContactProblem(*args, **options)
