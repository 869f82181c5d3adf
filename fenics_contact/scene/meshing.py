"""Meshes built with the gmsh Python API.

The gmsh model is created on one MPI rank only and distributed by
:func:`dolfinx.io.gmsh.model_to_mesh`. ``gmsh`` is an optional dependency
(the ``mesh`` extra); it is imported when a mesh is built.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

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
    fine, coarse = _grading(
        "disk", radius, h_contact, h_far,
        0.1 * radius if fine_radius is None else fine_radius,
        0.5 * radius if coarse_radius is None else coarse_radius,
    )

    return mesh_on_rank(
        comm, rank, 2,
        lambda gmsh: _build_half_disk(gmsh, radius, h_contact, h_far, fine, coarse, verbosity),
    )


def _build_half_disk(
    gmsh,  # the gmsh module (imported lazily)
    radius: float,
    h_contact: float,
    h_far: float,
    fine: float,
    coarse: float,
    verbosity: int,
) -> None:
    """Create and mesh the half-disk model in the current gmsh session."""
    gmsh.option.setNumber("General.Verbosity", verbosity)
    gmsh.model.add("hertz_half_disk")
    geo = gmsh.model.geo
    R = radius
    centre = geo.addPoint(0.0, R, 0.0, h_far)
    left = geo.addPoint(-R, R, 0.0, h_far)
    bottom = geo.addPoint(0.0, 0.0, 0.0, h_contact)
    right = geo.addPoint(R, R, 0.0, h_far)
    arc_left = geo.addCircleArc(left, centre, bottom)
    arc_right = geo.addCircleArc(bottom, centre, right)
    top = geo.addLine(right, left)
    loop = geo.addCurveLoop([arc_left, arc_right, top])
    surface = geo.addPlaneSurface([loop])
    geo.synchronize()

    gmsh.model.addPhysicalGroup(2, [surface], BODY_TAG, name="body")
    gmsh.model.addPhysicalGroup(1, [top], TOP_TAG, name="top")
    gmsh.model.addPhysicalGroup(1, [arc_left, arc_right], CONTACT_TAG, name="contact")

    _graded_toward(gmsh, [bottom], h_contact, h_far, fine, coarse)
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
    fine, coarse = _grading(
        "sphere", radius, h_contact, h_far,
        0.15 * radius if fine_radius is None else fine_radius,
        0.6 * radius if coarse_radius is None else coarse_radius,
    )

    return mesh_on_rank(
        comm, rank, 3,
        lambda gmsh: _build_sphere_octant(gmsh, radius, h_contact, h_far, fine, coarse, verbosity),
    )


def _build_sphere_octant(
    gmsh,  # the gmsh module (imported lazily)
    radius: float,
    h_contact: float,
    h_far: float,
    fine: float,
    coarse: float,
    verbosity: int,
) -> None:
    """Create and mesh the sphere-octant model in the current gmsh session."""
    gmsh.option.setNumber("General.Verbosity", verbosity)
    gmsh.model.add("hertz_sphere_octant")
    occ = gmsh.model.occ
    R = radius
    ball = occ.addSphere(0.0, 0.0, R, R)
    box = occ.addBox(0.0, 0.0, 0.0, R, R, R)
    (body, *_), _ = occ.intersect([(3, ball)], [(3, box)])
    occ.synchronize()
    groups: dict[int, list[int]] = {TOP_TAG: [], CONTACT_TAG: [], SYMMETRY_X_TAG: [],
                                    SYMMETRY_Y_TAG: []}
    tol = 1e-6 * R
    for dim, tag in gmsh.model.getBoundary([body], oriented=False):
        xmin, ymin, zmin, xmax, ymax, zmax = gmsh.model.getBoundingBox(dim, tag)
        if zmax - zmin < tol and abs(zmin - R) < tol:
            groups[TOP_TAG].append(tag)
        elif xmax - xmin < tol and abs(xmin) < tol:
            groups[SYMMETRY_X_TAG].append(tag)
        elif ymax - ymin < tol and abs(ymin) < tol:
            groups[SYMMETRY_Y_TAG].append(tag)
        else:
            groups[CONTACT_TAG].append(tag)
    gmsh.model.addPhysicalGroup(3, [body[1]], BODY_TAG, name="body")
    names = {TOP_TAG: "top", CONTACT_TAG: "contact", SYMMETRY_X_TAG: "symmetry_x",
             SYMMETRY_Y_TAG: "symmetry_y"}
    for tag, surfaces in groups.items():
        gmsh.model.addPhysicalGroup(2, surfaces, tag, name=names[tag])

    lowest = [tag for dim, tag in gmsh.model.getEntities(0)
              if max(abs(c) for c in gmsh.model.getValue(0, tag, [])) < tol]
    _graded_toward(gmsh, lowest, h_contact, h_far, fine, coarse)
    gmsh.model.mesh.generate(3)


def _grading(
    shape: str, radius: float, h_contact: float, h_far: float, fine: float, coarse: float
) -> tuple[float, float]:
    """Check the sizes of a graded mesh; return (fine, coarse) radii."""
    if not radius > 0:
        raise ValueError(f"The {shape} radius must be > 0, got {radius}.")
    if not 0 < h_contact <= h_far:
        raise ValueError(
            f"Element sizes need 0 < h_contact <= h_far, got h_contact={h_contact}, h_far={h_far}."
        )
    if not 0 <= fine < coarse:
        raise ValueError(
            f"Grading radii need 0 <= fine_radius < coarse_radius, got {fine} and {coarse}."
        )
    return fine, coarse


def _graded_toward(
    gmsh: Any, points: list[int], h_contact: float, h_far: float, fine: float, coarse: float
) -> None:
    """Size field: h_contact within ``fine`` of the points, h_far beyond ``coarse``.

    The field alone sets the size: no point sizes, no curvature sizes.
    """
    field = gmsh.model.mesh.field
    distance = field.add("Distance")
    field.setNumbers(distance, "PointsList", points)
    threshold = field.add("Threshold")
    field.setNumber(threshold, "InField", distance)
    field.setNumber(threshold, "SizeMin", h_contact)
    field.setNumber(threshold, "SizeMax", h_far)
    field.setNumber(threshold, "DistMin", fine)
    field.setNumber(threshold, "DistMax", coarse)
    field.setAsBackgroundMesh(threshold)
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
