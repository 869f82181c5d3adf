"""Meshes built with the gmsh Python API.

The gmsh model is created on one MPI rank only and distributed by
:func:`dolfinx.io.gmsh.model_to_mesh`. ``gmsh`` is an optional dependency
(the ``mesh`` extra); it is imported when a mesh is built.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, NamedTuple

from dolfinx.io.gmsh import MeshData, model_to_mesh

from mpi4py import MPI

#: Physical tag of the half-disk surface (cells).
BODY_TAG = 1
#: Physical tag of the flat face y = R (facets).
TOP_TAG = 2
#: Physical tag of the circular arc, the candidate contact surface (facets).
CONTACT_TAG = 3


def hertz_half_disk(
    comm: MPI.Comm,
    radius: float = 1.0,
    h_contact: float = 0.004,
    h_far: float = 0.1,
    fine_radius: float | None = None,
    coarse_radius: float | None = None,
    *,
    rank: int = 0,
    verbosity: int = 0,
) -> MeshData:
    """The lower half of a disk resting on y = 0, graded toward its lowest point.

    The body is {x^2 + (y - R)^2 <= R^2, y <= R}: its centre is (0, R), its
    flat face lies on y = R and its arc touches the line y = 0 at (0, 0),
    which is a mesh vertex. P1 triangles have size ``h_contact`` within
    ``fine_radius`` of (0, 0), growing linearly with the distance to
    ``h_far`` at ``coarse_radius`` and beyond (gmsh Distance + Threshold
    fields). All lengths are in the units of ``radius``.

    Physical groups (tags of the returned meshtags):

    - surface "body": tag 1 (``BODY_TAG``), in ``cell_tags``;
    - curve "top", the flat face y = R: tag 2 (``TOP_TAG``), in ``facet_tags``;
    - curve "contact", the arc: tag 3 (``CONTACT_TAG``), in ``facet_tags``.

    ``meshes/hertz_cylinder.geo`` describes the same geometry, default sizes
    and tags for the gmsh command line.

    Args:
        comm: communicator the mesh is distributed over.
        radius: disk radius R (length).
        h_contact: element size near the contact point (length).
        h_far: element size far from it (length).
        fine_radius: distance from (0, 0) within which the size is
            ``h_contact``; 0.1 R by default.
        coarse_radius: distance from (0, 0) beyond which the size is
            ``h_far``; 0.5 R by default.
        rank: the MPI rank that builds the gmsh model.
        verbosity: gmsh ``General.Verbosity`` (0 silent, 5 everything).

    Returns:
        The dolfinx ``MeshData``: use its ``mesh``, ``cell_tags`` and
        ``facet_tags``.
    """
    grading = _Grading.checked(
        "disk", radius, h_contact, h_far,
        0.1 * radius if fine_radius is None else fine_radius,
        0.5 * radius if coarse_radius is None else coarse_radius,
    )
    return mesh_on_rank(comm, rank, 2, lambda gmsh: _build_half_disk(gmsh, grading, verbosity))


def _build_half_disk(gmsh: Any, g: _Grading, verbosity: int) -> None:
    """Create and mesh the half-disk model in the current gmsh session."""
    new_model(gmsh, "hertz_half_disk", verbosity)
    bottom, arcs, top, surface = half_disk(gmsh.model.geo, g.radius, h_rim=g.h_far,
                                           h_tip=g.h_contact)
    gmsh.model.geo.synchronize()
    add_groups(gmsh, 2, {BODY_TAG: ("body", [surface])})
    add_groups(gmsh, 1, {TOP_TAG: ("top", [top]), CONTACT_TAG: ("contact", arcs)})
    g.toward(gmsh, [bottom])
    gmsh.option.setNumber("Mesh.Algorithm", 6)  # Frontal-Delaunay
    gmsh.model.mesh.generate(2)


#: Physical tag of the symmetry face x = 0 of the sphere octant (facets).
SYMMETRY_X_TAG = 4
#: Physical tag of the symmetry face y = 0 of the sphere octant (facets).
SYMMETRY_Y_TAG = 5


def hertz_sphere_octant(
    comm: MPI.Comm,
    radius: float = 1.0,
    h_contact: float = 0.02,
    h_far: float = 0.25,
    fine_radius: float | None = None,
    coarse_radius: float | None = None,
    *,
    rank: int = 0,
    verbosity: int = 0,
) -> MeshData:
    """One eighth of a sphere resting on z = 0, graded toward its lowest point (3D).

    The body is {x >= 0, y >= 0, z <= R, x^2 + y^2 + (z - R)^2 <= R^2}: the
    quarter of the lower hemisphere of the sphere centred at (0, 0, R), which
    touches the plane z = 0 at the origin (a mesh vertex). P1 tetrahedra have
    size ``h_contact`` within ``fine_radius`` of the origin, growing linearly
    to ``h_far`` at ``coarse_radius``. All lengths in the units of ``radius``.

    Physical groups: volume tag 1 (``BODY_TAG``); facets: the flat face
    z = R tag 2 (``TOP_TAG``), the spherical surface tag 3
    (``CONTACT_TAG``), the symmetry faces x = 0 tag 4 (``SYMMETRY_X_TAG``)
    and y = 0 tag 5 (``SYMMETRY_Y_TAG``). ``meshes/sphere.geo`` describes
    the same model for the gmsh command line.

    Args:
        comm: communicator the mesh is distributed over.
        radius: sphere radius R (length).
        h_contact: element size near the contact point (length).
        h_far: element size far from it (length).
        fine_radius: distance from the origin meshed at ``h_contact``; 0.15 R by default.
        coarse_radius: distance beyond which the size is ``h_far``; 0.6 R by default.
        rank: the MPI rank that builds the gmsh model.
        verbosity: gmsh ``General.Verbosity``.

    Returns:
        The dolfinx ``MeshData`` (``mesh``, ``cell_tags``, ``facet_tags``).
    """
    grading = _Grading.checked(
        "sphere", radius, h_contact, h_far,
        0.15 * radius if fine_radius is None else fine_radius,
        0.6 * radius if coarse_radius is None else coarse_radius,
    )
    return mesh_on_rank(comm, rank, 3, lambda gmsh: _build_sphere_octant(gmsh, grading, verbosity))


def _build_sphere_octant(gmsh: Any, g: _Grading, verbosity: int) -> None:
    """Create and mesh the sphere-octant model in the current gmsh session."""
    new_model(gmsh, "hertz_sphere_octant", verbosity)
    R = g.radius
    (body,) = ball_quarters(gmsh, R, [R])
    faces = quarter_faces(gmsh, body, R)
    add_groups(gmsh, 3, {BODY_TAG: ("body", [body[1]])})
    add_groups(gmsh, 2, {
        TOP_TAG: ("top", faces["flat"]), CONTACT_TAG: ("contact", faces["curved"]),
        SYMMETRY_X_TAG: ("symmetry_x", faces["x"]), SYMMETRY_Y_TAG: ("symmetry_y", faces["y"]),
    })
    tol = 1e-6 * R
    lowest = [tag for dim, tag in gmsh.model.getEntities(0)
              if max(abs(c) for c in gmsh.model.getValue(0, tag, [])) < tol]
    g.toward(gmsh, lowest)
    gmsh.model.mesh.generate(3)


class _Grading(NamedTuple):
    """Body radius and element sizes of a mesh graded toward its contact point (lengths)."""

    radius: float
    h_contact: float
    h_far: float
    fine: float
    coarse: float

    @classmethod
    def checked(
        cls, shape: str, radius: float, h_contact: float, h_far: float, fine: float,
        coarse: float,
    ) -> _Grading:
        """The grading, after checking the sizes (``ValueError`` naming the bad ones)."""
        if not radius > 0:
            raise ValueError(f"The {shape} radius must be > 0, got {radius}.")
        if not 0 < h_contact <= h_far:
            raise ValueError(
                f"Element sizes need 0 < h_contact <= h_far, got h_contact={h_contact}, "
                f"h_far={h_far}."
            )
        if not 0 <= fine < coarse:
            raise ValueError(
                f"Grading radii need 0 <= fine_radius < coarse_radius, got {fine} and {coarse}."
            )
        return cls(radius, h_contact, h_far, fine, coarse)

    def toward(self, gmsh: Any, points: list[int]) -> None:
        """Size field: h_contact within ``fine`` of the points, h_far beyond ``coarse``.

        The field alone sets the size: no point sizes, no curvature sizes.
        """
        distance = gmsh.model.mesh.field.add("Distance")
        gmsh.model.mesh.field.setNumbers(distance, "PointsList", points)
        size_field_only(gmsh, threshold_field(
            gmsh, distance, self.h_contact, self.h_far, self.fine, self.coarse
        ))


# -- shared gmsh building blocks (used by two_body_meshing too) -------------------


def new_model(gmsh: Any, name: str, verbosity: int = 0, *, separate: bool = False) -> None:
    """Add a model ``name`` to the gmsh session at ``verbosity``.

    ``separate`` keeps coincident points of distinct bodies apart
    (``Geometry.AutoCoherence`` 0): the bodies of a contact pair share no nodes.
    """
    gmsh.option.setNumber("General.Verbosity", verbosity)
    if separate:
        gmsh.option.setNumber("Geometry.AutoCoherence", 0)
    gmsh.model.add(name)


def add_groups(gmsh: Any, dim: int, groups: dict[int, tuple[str, Sequence[int]]]) -> None:
    """Add one physical group of dimension ``dim`` per entry ``{tag: (name, entities)}``."""
    for tag, (name, entities) in groups.items():
        gmsh.model.addPhysicalGroup(dim, list(entities), tag, name=name)


def half_disk(
    geo: Any, radius: float, side: float = 1.0, h_rim: float = 0.0, h_tip: float = 0.0
) -> tuple[int, list[int], int, int]:
    """A half-disk of the built-in kernel ``geo`` touching the origin with its arc.

    The centre is (0, side R) and the flat face lies on y = side R (side = 1:
    above the x axis, -1: below). Points get the mesh sizes ``h_rim``
    (centre and rim ends) and ``h_tip`` (the origin); 0 leaves them unset.

    Returns:
        (tip point, [two arcs], flat line, plane surface) tags.
    """
    y = side * radius
    centre = geo.addPoint(0.0, y, 0.0, h_rim)
    left = geo.addPoint(-radius, y, 0.0, h_rim)
    tip = geo.addPoint(0.0, 0.0, 0.0, h_tip)
    right = geo.addPoint(radius, y, 0.0, h_rim)
    arcs = [geo.addCircleArc(left, centre, tip), geo.addCircleArc(tip, centre, right)]
    flat = geo.addLine(right, left)
    surface = geo.addPlaneSurface([geo.addCurveLoop([*arcs, flat])])
    return tip, arcs, flat, surface


def ball_quarters(gmsh: Any, radius: float, centres_z: Sequence[float]) -> list[tuple[int, int]]:
    """Quarters x, y >= 0 of the hemispheres of radius R facing the plane z = 0 (OCC).

    For each centre (0, 0, c) with c = +-R, the part of the ball between z = 0
    and z = c. The model is synchronized; returns the (3, tag) of each volume.
    """
    occ = gmsh.model.occ
    bodies = []
    for c in centres_z:
        ball = occ.addSphere(0.0, 0.0, c, radius)
        box = occ.addBox(0.0, 0.0, min(c, 0.0), radius, radius, radius)
        (body, *_), _ = occ.intersect([(3, ball)], [(3, box)])
        bodies.append(body)
    occ.synchronize()
    return bodies


def quarter_faces(gmsh: Any, body: tuple[int, int], radius: float) -> dict[str, list[int]]:
    """Sort the faces of a ball quarter (:func:`ball_quarters`) by role.

    Returns the surface tags under "flat" (the face |z| = R), "x" (x = 0),
    "y" (y = 0) and "curved" (the spherical face).
    """
    tol = 1e-6 * radius
    faces: dict[str, list[int]] = {"flat": [], "x": [], "y": [], "curved": []}
    for dim, tag in gmsh.model.getBoundary([body], oriented=False):
        xmin, ymin, zmin, xmax, ymax, zmax = gmsh.model.getBoundingBox(dim, tag)
        if zmax - zmin < tol and abs(abs(zmin) - radius) < tol:
            faces["flat"].append(tag)
        elif xmax - xmin < tol and abs(xmin) < tol:
            faces["x"].append(tag)
        elif ymax - ymin < tol and abs(ymin) < tol:
            faces["y"].append(tag)
        else:
            faces["curved"].append(tag)
    return faces


def threshold_field(
    gmsh: Any, in_field: int, size_min: float, size_max: float, dist_min: float, dist_max: float
) -> int:
    """A Threshold field on ``in_field``: size_min below dist_min, size_max beyond dist_max."""
    field = gmsh.model.mesh.field
    threshold = field.add("Threshold")
    field.setNumber(threshold, "InField", in_field)
    field.setNumber(threshold, "SizeMin", size_min)
    field.setNumber(threshold, "SizeMax", size_max)
    field.setNumber(threshold, "DistMin", dist_min)
    field.setNumber(threshold, "DistMax", dist_max)
    return threshold


def size_field_only(gmsh: Any, field: int) -> None:
    """Make ``field`` the background mesh and the only source of element sizes.

    No point sizes, no sizes from the boundary or from curvature.
    """
    gmsh.model.mesh.field.setAsBackgroundMesh(field)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)


def mesh_on_rank(
    comm: MPI.Comm, rank: int, gdim: int, build: Callable[[Any], None]
) -> MeshData:
    """Run ``build(gmsh)`` on ``rank`` and distribute the resulting mesh over ``comm``.

    Uses the caller's gmsh session when one is open (its model is removed
    afterwards), or opens and closes its own. ``build`` must add and mesh a
    model with physical groups.
    """
    import gmsh

    owns_session = False
    if comm.rank == rank and not gmsh.isInitialized():
        gmsh.initialize(interruptible=False)
        owns_session = True
    try:
        if comm.rank == rank:
            build(gmsh)
        return model_to_mesh(gmsh.model, comm, rank, gdim=gdim)
    finally:
        if comm.rank == rank:
            if owns_session:
                gmsh.finalize()
            else:
                gmsh.model.remove()


def open_geo(gmsh: Any, path: Path | str, parameters: dict[str, float]) -> None:
    """Open a gmsh .geo or .msh file in the current session with ``parameters`` set.

    A .geo file declares its parameters with ``DefineConstant[x = {default,
    Name "Parameters/x"}]``; such a declaration keeps the ONELAB value, so
    each parameter is set both as a ONELAB number and as a parser variable
    before the file is read. A name the file does not declare raises
    ``ValueError`` listing the names it does.
    """
    if parameters and str(path).endswith(".geo"):
        gmsh.open(str(path))  # a first read learns which parameters the file declares
        declared = {n.split("/", 1)[1] for n in gmsh.onelab.getNames("Parameters/.*")}
        gmsh.clear()
        gmsh.onelab.clear()
        unknown = sorted(set(parameters) - declared)
        if unknown:
            raise ValueError(
                f"{Path(path).name} declares no parameter {', '.join(map(repr, unknown))}; "
                f"it declares: {', '.join(sorted(declared)) or 'none'}."
            )
    for name, value in parameters.items():
        gmsh.onelab.setNumber(f"Parameters/{name}", [float(value)])
        gmsh.parser.setNumber(name, [float(value)])
    gmsh.open(str(path))
