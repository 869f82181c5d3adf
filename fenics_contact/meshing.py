"""Meshes built with the gmsh Python API.

The gmsh model is created on one MPI rank only and distributed by
:func:`dolfinx.io.gmsh.model_to_mesh`. ``gmsh`` is an optional dependency
(the ``mesh`` extra); it is imported when a mesh is built.
"""

from __future__ import annotations

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
    if not radius > 0:
        raise ValueError(f"The disk radius must be > 0, got {radius}.")
    if not 0 < h_contact <= h_far:
        raise ValueError(
            f"Element sizes need 0 < h_contact <= h_far, got h_contact={h_contact}, h_far={h_far}."
        )
    fine = 0.1 * radius if fine_radius is None else fine_radius
    coarse = 0.5 * radius if coarse_radius is None else coarse_radius
    if not 0 <= fine < coarse:
        raise ValueError(
            f"Grading radii need 0 <= fine_radius < coarse_radius, got {fine} and {coarse}."
        )

    import gmsh

    owns_session = False
    if comm.rank == rank and not gmsh.isInitialized():
        gmsh.initialize(interruptible=False)
        owns_session = True
    try:
        if comm.rank == rank:
            _build_half_disk(gmsh, radius, h_contact, h_far, fine, coarse, verbosity)
        data = model_to_mesh(gmsh.model, comm, rank, gdim=2)
    finally:
        if comm.rank == rank:
            if owns_session:
                gmsh.finalize()
            else:
                gmsh.model.remove()
    return data


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

    field = gmsh.model.mesh.field
    distance = field.add("Distance")
    field.setNumbers(distance, "PointsList", [bottom])
    threshold = field.add("Threshold")
    field.setNumber(threshold, "InField", distance)
    field.setNumber(threshold, "SizeMin", h_contact)
    field.setNumber(threshold, "SizeMax", h_far)
    field.setNumber(threshold, "DistMin", fine)
    field.setNumber(threshold, "DistMax", coarse)
    field.setAsBackgroundMesh(threshold)
    # The field alone sets the size: no point sizes, no curvature sizes.
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.option.setNumber("Mesh.Algorithm", 6)  # Frontal-Delaunay
    gmsh.model.mesh.generate(2)
