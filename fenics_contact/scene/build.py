"""Turn a validated :class:`~fenics_contact.scene.schema.Scene` into a contact problem.

Builds the mesh (gmsh .geo/.msh or a generator), resolves facet tags by
number or physical name, and creates only what the scene declares. Tag and
dimension mistakes that need the mesh to be seen are reported here, still
before any form is compiled.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from dolfinx import mesh

from mpi4py import MPI

from fenics_contact.model.body import describe_unclaimed, unclaimed_cells
from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.friction import FrictionSettings
from fenics_contact.model.materials import material
from fenics_contact.model.mortar import MortarContact
from fenics_contact.model.obstacle_contact import ObstacleContact
from fenics_contact.model.obstacles import RigidBall, RigidObstacle, RigidPlane
from fenics_contact.model.pairs import NodeToSegmentContact, check_pair_cells
from fenics_contact.model.problem import (
    Body,
    ContactProblem,
    PathDisplacement,
    PrescribedDisplacement,
    Solid,
    SurfaceTraction,
)
from fenics_contact.model.rigid import free_rigid_motions
from fenics_contact.scene.checks import (
    SceneWarning,
    check_bodies_held,
    check_cells,
    check_initial_overlap,
    check_obstacles_face_their_facets,
    check_pair_surfaces,
    check_pair_surfaces_face,
    facet_owners,
    held_by_closed_contacts,
    warn_locking,
    warn_skipped_knots,
)
from fenics_contact.scene.meshing import (
    MeshGroupError,
    gmsh_session,
    mesh_on_rank,
    open_geo,
    overlapping_groups,
)
from fenics_contact.scene.pairing import pairing_contacts
from fenics_contact.scene.schema import (
    GENERATOR_TAGS,
    BoundarySpec,
    ContactSpec,
    ObstacleContactSpec,
    ObstacleSpec,
    PairSpec,
    Scene,
    SceneError,
)


@dataclass
class BodyMesh:
    """A mesh with its facet tags and the names of its physical groups."""

    domain: mesh.Mesh
    facet_tags: mesh.MeshTags
    names: dict[str, int]
    cell_tags: mesh.MeshTags | None = None
    cell_names: dict[str, int] = field(default_factory=dict)


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


def _physical_groups(scene: Scene, comm: MPI.Comm) -> dict[tuple[int, int], str]:
    """The file's physical groups, {(dim, tag): name}, read on rank 0, known to all.

    A file gmsh cannot read, or whose groups overlap (a mesh keeps one tag
    per cell and facet), raises SceneError (on every rank) naming it.
    """
    groups: dict[tuple[int, int], str] = {}
    problem: str | None = None
    if comm.rank == 0:
        with gmsh_session() as (gmsh, opened):
            try:
                _open(gmsh, scene)
                for d, t in gmsh.model.getPhysicalGroups():
                    groups[(d, t)] = gmsh.model.getPhysicalName(d, t)
                overlap = overlapping_groups(gmsh)
                if overlap:
                    problem = f"{scene.path.name}: [mesh] {scene.mesh.file.name}: {overlap}"
            except SceneError as exc:  # the file was read; the scene asks what it lacks
                problem = str(exc)
            except Exception as exc:  # gmsh raises bare Exception
                message = " ".join(str(exc).split()) or type(exc).__name__
                problem = (
                    f"{scene.path.name}: [mesh] file = {str(scene.mesh.file)!r}: gmsh cannot "
                    f"read it ({message}); check that it is a complete .geo/.msh file."
                )
            finally:
                if not opened:
                    gmsh.model.remove()
    groups, problem = comm.bcast((groups, problem), root=0)
    if problem is not None:
        raise SceneError(problem)
    return groups


def _check_tags(scene: Scene, groups: dict[tuple[int, int], str]) -> None:
    """Every tag the scene names must be a facet physical group of the file."""
    fdim = scene.dimension - 1
    names = {name: tag for (d, tag), name in groups.items() if d == fdim and name}
    numbers = {tag for (d, tag) in groups if d == fdim}
    uses = [(f"dirichlet {i + 1}", b.tag) for i, b in enumerate(scene.dirichlet)]
    uses += [(f"traction {i + 1}", b.tag) for i, b in enumerate(scene.tractions)]
    uses += [(_contact_section(o), o.contact.tag) for o in scene.obstacles
             if o.contact.tag is not None]
    listing = ", ".join(
        (f"{n} = {t}" if n else str(t))
        for t, n in sorted((t, groups[(fdim, t)]) for t in numbers)
    )
    for section, tag in uses:
        known = tag in names if isinstance(tag, str) else tag in numbers
        if not known:
            raise SceneError(
                f"{scene.path.name}: [{section}] tag = {tag!r} is not a {fdim}D physical group "
                f"of {scene.mesh.file.name}; available: {listing or 'none'}."
            )


def _from_gmsh(scene: Scene, comm: MPI.Comm) -> BodyMesh:
    spec = scene.mesh
    assert spec.file is not None
    groups = _physical_groups(scene, comm)
    dims = {d for d, _ in groups}
    if dims and max(dims) > scene.dimension:
        raise SceneError(
            f"{scene.path.name}: [scene] dimension = {scene.dimension}, but {spec.file.name} "
            f"is a {max(dims)}D mesh (it has {max(dims)}D physical groups); set "
            f"dimension = {max(dims)}."
        )
    if scene.dimension not in dims:
        raise SceneError(
            f"{scene.path.name}: [scene] dimension = {scene.dimension}, but the mesh "
            f"{spec.file.name} has no {scene.dimension}D physical group; set the "
            "dimension to the mesh's or add a physical group for the body."
        )
    _check_tags(scene, groups)  # before meshing: the file names its groups

    def build(gmsh: Any) -> None:
        _open(gmsh, scene)
        if spec.file is not None and spec.file.suffix == ".geo":
            gmsh.model.mesh.generate(scene.dimension)

    try:
        data = mesh_on_rank(comm, 0, scene.dimension, build)
    except MeshGroupError as exc:
        raise SceneError(f"{scene.path.name}: [mesh] file = {str(spec.file)!r}: {exc}") from None
    except ValueError as exc:
        raise SceneError(f"{scene.path.name}: [mesh] file = {str(spec.file)!r}: gmsh could not "
                         f"mesh it ({exc}); check the geometry (closed curve loops, surfaces "
                         "that do not cross) and the mesh sizes.") from exc
    if data.facet_tags is None:
        raise SceneError(f"{spec.file}: the mesh has no physical groups on its boundary.")
    fdim = scene.dimension - 1
    names = {
        name: group.tag for name, group in data.physical_groups.items() if group.dim == fdim
    }
    cell_names = {
        name: group.tag for name, group in data.physical_groups.items()
        if group.dim == scene.dimension
    }
    return BodyMesh(data.mesh, data.facet_tags, names, data.cell_tags, cell_names)


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
        label = section if section.startswith("[") else f"[{section}]"
        raise SceneError(
            f"{scene.path.name}: {label} tag = {tag!r} is not a facet tag of the mesh; "
            f"available: {named or ', '.join(map(str, available))}."
        )
    return body.facet_tags.find(number)


def _restricted(
    body: BodyMesh, facets: np.ndarray, spec: BoundarySpec | ContactSpec
) -> np.ndarray:
    """The facets whose midpoints lie within the spec's coordinate bounds."""
    if not spec.bounds:
        return facets
    fdim = body.domain.topology.dim - 1
    midpoints = mesh.compute_midpoints(body.domain, fdim, facets)
    keep = np.ones(facets.size, dtype=bool)
    for axis, (lo, hi) in spec.bounds.items():
        tol = 1e-10 * max(1.0, abs(lo), abs(hi))
        keep &= (midpoints[:, axis] >= lo - tol) & (midpoints[:, axis] <= hi + tol)
    return facets[keep]


def _contact_section(entry: ObstacleContactSpec) -> str:
    """Where an obstacle's contact keys sit in the scene file (for messages)."""
    return "contact" if entry.name == "obstacle" else f"obstacle '{entry.name}'"


def build_obstacle(spec: ObstacleSpec, domain: mesh.Mesh) -> RigidObstacle:
    """A rigid obstacle of the scene, placed by dolfinx Constants."""
    if spec.type == "plane":
        return RigidPlane(domain, spec.point, spec.normal)
    return RigidBall(domain, spec.point, spec.radius, inside=spec.inside)


def contact_facets(
    scene: Scene, body: BodyMesh, entry: ObstacleContactSpec, obstacle: RigidObstacle
) -> np.ndarray:
    """Candidate facets of one obstacle: by tag, or detected along the obstacle's path."""
    spec = entry.contact
    if spec.tag is not None:
        facets = tagged_facets(body, scene, _contact_section(entry), spec.tag)
        return _restricted(body, facets, spec)
    from fenics_contact.model.candidates import detect_candidate_facets

    pushes = [abs(v) for d in scene.dirichlet for v in d.value if v is not None]
    pushes += [abs(v) for d in scene.dirichlet for knot in d.path for v in knot[1:]]
    return detect_candidate_facets(
        body.domain, obstacle, entry.obstacle.motion, spec.margin,
        displacement_bound=max(pushes, default=0.0),
    )


def obstacle_contact(
    scene: Scene, body: BodyMesh, entry: ObstacleContactSpec, bodies: Sequence[Body] = ()
) -> ObstacleContact:
    """One [[obstacle]] (or [obstacle] with [contact]) as a contact of the body.

    With several ``bodies`` the body that carries the facets sets the r scale
    E/h; facets on no single body are refused.
    """
    obstacle = build_obstacle(entry.obstacle, body.domain)
    spec = entry.contact
    facets = contact_facets(scene, body, entry, obstacle)
    owner = None
    if bodies:
        assert body.cell_tags is not None
        owners = facet_owners(body.domain, body.cell_tags, bodies, facets)
        if len(owners) != 1:
            raise SceneError(
                f"{scene.path.name}: [{_contact_section(entry)}] tag = {spec.tag!r} lies on "
                f"{'no body' if not owners else 'bodies ' + ', '.join(map(repr, owners))}; "
                "give an obstacle the facets of one body (one [[obstacle]] per body)."
            )
        owner = owners[0]
    friction = None if spec.mu is None else FrictionSettings(spec.mu, spec.tangential_r_max)
    return ObstacleContact(
        obstacle, facets,
        spec,  # a ContactSettings with the candidate and friction keys
        motion=entry.obstacle.motion, schedule=entry.obstacle.schedule or None,
        friction=friction, body=owner, name=entry.name,
    )


def boundary_conditions(
    scene: Scene, body: BodyMesh
) -> tuple[list[PrescribedDisplacement], list[SurfaceTraction]]:
    """The scene's [[dirichlet]] (values or load paths) and [[traction]] conditions on ``body``.

    Raises SceneError for a condition whose tag and bounds select no facet.
    """
    comm = body.domain.comm
    prescribed: list[PrescribedDisplacement] = []
    for i, spec in enumerate(scene.dirichlet):
        facets = _restricted(body, tagged_facets(body, scene, f"dirichlet {i + 1}", spec.tag), spec)
        if comm.allreduce(facets.size, op=MPI.SUM) == 0:
            raise SceneError(
                f"{scene.path.name}: [[dirichlet]] {i + 1} selects no facet; widen its bounds."
            )
        prescribed.append(
            PathDisplacement(facets, spec.value, str(spec.tag), path=spec.path) if spec.path
            else PrescribedDisplacement(facets, spec.value, str(spec.tag))
        )
    tractions = [
        SurfaceTraction(
            _restricted(body, tagged_facets(body, scene, f"traction {i + 1}", spec.tag), spec),
            tuple(float(v) for v in spec.value if v is not None),
        )
        for i, spec in enumerate(scene.tractions)
    ]
    return prescribed, tractions


def build_two_body_problem(scene: Scene, body: BodyMesh) -> ContactProblem:
    """Bodies, conditions, every contact pair and every obstacle of a scene with [[body]] blocks."""
    comm = body.domain.comm
    if body.cell_tags is None:
        raise SceneError(
            f"{scene.path.name}: [[body]] needs a mesh file with physical groups for the "
            "bodies' cells; the generated meshes hold one body."
        )
    present = sorted(set(comm.allreduce(body.cell_tags.values.tolist(), op=MPI.SUM)))
    bodies = []
    for i, spec in enumerate(scene.bodies):
        tag = body.cell_names.get(spec.tag) if isinstance(spec.tag, str) else spec.tag
        if tag is None or tag not in present:
            named = ", ".join(f"{n} = {t}" for n, t in sorted(body.cell_names.items()))
            raise SceneError(
                f"{scene.path.name}: [[body]] {i + 1} tag = {spec.tag!r} is not a cell tag of "
                f"the mesh; available: {named or ', '.join(map(str, present))}."
            )
        warn_locking(scene, spec.nu, f"[[body]] {spec.name!r}")
        bodies.append(Body(spec.name, tag, material(spec.law, spec.E, spec.nu),
                           stabilise=spec.stabilise))
    unclaimed = unclaimed_cells(body.domain, body.cell_tags, [b.tag for b in bodies])
    if unclaimed:
        names = {t: n for n, t in body.cell_names.items()}
        declared = ", ".join(f"{b.name!r} (tag {b.tag})" for b in bodies)
        raise SceneError(
            f"{scene.path.name}: {describe_unclaimed(unclaimed, names)} belong to no "
            f"[[body]] (declared: {declared}); nothing would hold or stiffen them. Add a "
            "[[body]] with their tag, or mesh without them (a .geo that leaves that part "
            "out)."
        )
    prescribed, tractions = boundary_conditions(scene, body)
    contacts: list = []
    for pair in scene.pairs:
        striker = tagged_facets(body, scene, f"[[pair]] {pair.name!r} striker", pair.striker)
        target = tagged_facets(body, scene, f"[[pair]] {pair.name!r} target", pair.target)
        check_pair_surfaces(scene, body.domain, body.cell_tags, bodies, striker, target, pair)
        try:
            check_pair_cells(body.domain, pair.name)
        except ValueError as exc:
            raise SceneError(f"{scene.path.name}: {exc}") from None
        if not pair.self_contact:
            check_pair_surfaces_face(
                scene, body.domain, striker, target, pair,
                lambda role, pair=pair, facets={"striker": striker, "target": target}:
                _surfaces_beside(body, bodies, pair, facets[role]))
        friction = (None if pair.mu is None
                    else FrictionSettings(pair.mu, pair.tangential_r_max))
        settings = ContactSettings(r=pair.r, relative=pair.relative,
                                   interference_until=pair.interference_until)
        if pair.discretisation == "mortar":
            contacts.append(MortarContact(striker, target, settings, friction=friction,
                                          name=pair.name, slots=pair.slots))
            continue
        contacts.append(NodeToSegmentContact(
            striker, target, settings,
            friction=friction, name=pair.name, self_contact=pair.self_contact,
            neighbourhood=pair.neighbourhood))
    paired = {frozenset(facet_owners(body.domain, body.cell_tags, bodies, np.concatenate(
        [tagged_facets(body, scene, "pair", p.striker), tagged_facets(body, scene, "pair",
                                                                      p.target)])))
              for p in scene.pairs} if scene.pairing else set()
    contacts += pairing_contacts(scene, body.domain, body.cell_tags, bodies, paired, prescribed)
    contacts += [obstacle_contact(scene, body, entry, bodies) for entry in scene.obstacles]
    solid = _solid(scene, body.domain, bodies, body.cell_tags, prescribed=prescribed,
                   tractions=tractions)
    problem = _problem(scene, solid, contacts)
    check_obstacles_face_their_facets(scene, problem)
    check_bodies_held(scene, problem, body.cell_tags, bodies, prescribed)
    check_initial_overlap(scene, problem)
    warn_initial_penetration(scene, problem)
    return problem


def _surfaces_beside(body: BodyMesh, bodies: list[Body], pair: PairSpec,
                     facets_of: np.ndarray) -> dict[str, np.ndarray]:
    """The other named facet groups of the body that holds ``facets_of`` (collective)."""
    owner = facet_owners(body.domain, body.cell_tags, bodies, facets_of)
    found = {}
    for name in sorted(body.names):
        if name in (pair.striker, pair.target):
            continue
        facets = body.facet_tags.find(body.names[name])
        if facet_owners(body.domain, body.cell_tags, bodies, facets) == owner:
            found[name] = facets
    return found


def _problem(scene: Scene, solid: Solid, contacts: list) -> ContactProblem:
    """The scene's :class:`ContactProblem`, its refusals as scene errors.

    (A support that holds a frictional contact's node obliquely to its normal.)
    """
    try:
        return ContactProblem(solid, contacts)
    except ValueError as exc:
        raise SceneError(f"{scene.path.name}: {exc}") from None


def _solid(scene: Scene, *args, **kwargs) -> Solid:
    """The scene's :class:`Solid`, its refusals of the conditions as scene errors.

    (Two supports that disagree at a node, a support that holds no facet.)
    """
    try:
        return Solid(*args, **kwargs)
    except ValueError as exc:
        raise SceneError(f"{scene.path.name}: {exc}") from None


def build_problem(scene: Scene, comm: MPI.Comm = MPI.COMM_WORLD) -> ContactProblem:
    """Mesh, material, conditions, obstacle and contact surface of a scene."""
    warn_skipped_knots(scene)
    body = build_mesh(scene, comm)
    check_cells(scene, body.domain)
    if scene.two_body:
        return build_two_body_problem(scene, body)
    if body.domain.geometry.dim != scene.dimension:
        raise SceneError(
            f"{scene.path.name}: [scene] dimension = {scene.dimension} but the mesh is "
            f"{body.domain.geometry.dim}D."
        )
    prescribed, tractions = boundary_conditions(scene, body)
    free = free_rigid_motions(body.domain, [(p.facets, p.at(1.0)) for p in prescribed])
    warn_locking(scene, scene.nu, "[material]")
    solid = _solid(scene, body.domain,
                   [Body("body", None, material(scene.law, scene.E, scene.nu))],
                   prescribed=prescribed, tractions=tractions)
    contacts = [obstacle_contact(scene, body, entry) for entry in scene.obstacles]
    problem = _problem(scene, solid, contacts)
    check_obstacles_face_their_facets(scene, problem)
    check_rigid_motions(scene, problem, free, prescribed)
    warn_initial_penetration(scene, problem)
    return problem


def check_rigid_motions(
    scene: Scene, problem: ContactProblem, free: list[str],
    prescribed: list[PrescribedDisplacement],
) -> None:
    """Raise SceneError naming the rigid motions (``free``) no Dirichlet condition holds.

    Tractions do not count, nor contacts that are open at the start: before
    contact is made they hold nothing and the stiffness is singular. Contacts
    closed at the start hold the motions that would close them (a block
    squeezed between two plates it touches).
    """
    cells = np.arange(problem.domain.topology.index_map(problem.domain.topology.dim).size_local,
                      dtype=np.int32)
    if free and not held_by_closed_contacts(problem, [("body", cells)], prescribed):
        raise SceneError(
            f"{scene.path.name}: the [[dirichlet]] conditions leave rigid motions of the body "
            f"free ({'; '.join(free)}); contact does not hold them. Fix: prescribe more "
            "components or facets (e.g. value = [0.0, 0.0] on a side, or a second side)."
        )


def initial_penetration(contact: ObstacleContact) -> float:
    """Largest penetration of a contact's nodes into its obstacle at load factor 0 (length)."""
    points = contact.nodal_coordinates()[:, : contact.gdim]
    gap = contact.obstacle.gap_value(points) if points.size else np.zeros(0)
    local = float(np.max(-np.minimum(gap, 0.0), initial=0.0))
    return float(contact.comm.allreduce(local, op=MPI.MAX))


#: A body's start inside an obstacle deeper than this fraction of h is reported.
SHALLOW_START = 1e-3


def warn_initial_penetration(scene: Scene, problem: ContactProblem) -> float:
    """Warn (SceneWarning) when the body starts inside an obstacle.

    Past h: expect squashed elements, move the obstacle. Past
    :data:`SHALLOW_START` h: the first load step pushes the body out (as two
    bodies that start inside each other are reported). Returns the largest
    initial depth over the obstacles (length).
    """
    deepest = 0.0
    obstacles = [c for c in problem.contacts if isinstance(c, ObstacleContact)]
    for contact in obstacles:
        depth = initial_penetration(contact)
        deepest = max(deepest, depth)
        h = contact.surface.h
        which = "the obstacle" if len(obstacles) == 1 else f"obstacle '{contact.name}'"
        if SHALLOW_START * h < depth <= h and contact.starting_overlap() is None:
            warnings.warn(SceneWarning(
                f"{scene.path.name}: the body starts {depth:.3g} ({depth / h:.2g} h) inside "
                f"{which}; the first load step pushes it out. Move [obstacle] point/centre "
                "if the gap at load 0 should be >= 0."), stacklevel=2)
        if depth <= h:
            continue
        #: What a failed run's advice repeats: the body started deep inside an obstacle.
        problem.initial_overlap = (f"the body starts {depth:.4g} inside {which} "
                                   f"({depth / h:.3g} h, the warning at the start)")
        warnings.warn(
            SceneWarning(
                f"{scene.path.name}: the body starts {depth:.4g} inside {which}, more "
                f"than the contact facet size h = {h:.4g} ({depth / h:.3g} h); expect squashed "
                "or inverted elements. Move [obstacle] point/centre so the gap at load 0 is "
                ">= 0, and let [obstacle] motion or [[dirichlet]] values bring contact."
            ),
            stacklevel=2,
        )
    return deepest
