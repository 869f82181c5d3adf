"""Two-body meshes (one mesh, two cell tags) built with the gmsh Python API.

The bodies do not share nodes: each is its own gmsh surface, so the meshes
at the interface are independent (non-matching unless the sizes agree).
Tags: cells of the striker (upper body) 1, of the target (lower body) 2;
facets as listed per builder. The ``.geo`` files in ``meshes/`` describe
the same geometries for the gmsh command line.
"""

from __future__ import annotations

from dolfinx.io.gmsh import MeshData

from mpi4py import MPI

from fenics_contact.scene.meshing import mesh_on_rank

#: Cell tags.
STRIKER_TAG, TARGET_TAG = 1, 2
#: Facet tags: striker loaded face, striker contact face, target contact face,
#: target supported face, symmetry face x = 0 (blocks only).
LOAD_TAG, STRIKER_FACE_TAG, TARGET_FACE_TAG, SUPPORT_TAG, SYMMETRY_TAG = 2, 3, 4, 5, 6


def _check(**sizes: float) -> None:
    for name, value in sizes.items():
        if not value > 0:
            raise ValueError(f"{name} must be > 0, got {name} = {value}.")


def two_half_disks(
    comm: MPI.Comm,
    radius: float = 1.0,
    h_contact: float = 0.01,
    h_far: float = 0.2,
    target_ratio: float = 1.37,
    fine_radius: float = 0.15,
    coarse_radius: float = 0.6,
    *,
    rank: int = 0,
) -> MeshData:
    """Two half-disks touching at the origin: upper {y >= 0, centre (0, R)}, lower mirrored.

    The upper (striker) has its flat face on y = R (tag 2) and arc (tag 3);
    the lower (target) its arc (tag 4) and flat face y = -R (tag 5). The
    lower one's contact size is ``target_ratio * h_contact`` (non-matching).
    """
    _check(radius=radius, h_contact=h_contact, h_far=h_far, target_ratio=target_ratio)

    def build(gmsh) -> None:
        gmsh.option.setNumber("General.Verbosity", 0)
        gmsh.option.setNumber("Geometry.AutoCoherence", 0)  # keep the bodies apart
        gmsh.model.add("two_half_disks")
        geo = gmsh.model.geo
        R = radius
        tags = {}
        for name, sign, h in (("upper", 1.0, h_contact), ("lower", -1.0, h_contact * target_ratio)):
            c = geo.addPoint(0.0, sign * R, 0.0)
            left = geo.addPoint(-R, sign * R, 0.0)
            tip = geo.addPoint(0.0, 0.0, 0.0)
            right = geo.addPoint(R, sign * R, 0.0)
            a1 = geo.addCircleArc(left, c, tip)
            a2 = geo.addCircleArc(tip, c, right)
            flat = geo.addLine(right, left)
            surf = geo.addPlaneSurface([geo.addCurveLoop([a1, a2, flat])])
            tags[name] = (tip, [a1, a2], flat, surf, h)
        geo.synchronize()
        up, lo = tags["upper"], tags["lower"]
        gmsh.model.addPhysicalGroup(2, [up[3]], STRIKER_TAG, name="striker")
        gmsh.model.addPhysicalGroup(2, [lo[3]], TARGET_TAG, name="target")
        gmsh.model.addPhysicalGroup(1, [up[2]], LOAD_TAG, name="top")
        gmsh.model.addPhysicalGroup(1, up[1], STRIKER_FACE_TAG, name="striker_arc")
        gmsh.model.addPhysicalGroup(1, lo[1], TARGET_FACE_TAG, name="target_arc")
        gmsh.model.addPhysicalGroup(1, [lo[2]], SUPPORT_TAG, name="bottom")
        field = gmsh.model.mesh.field
        fields = []
        for tip, arcs, flat, surf, h in (up, lo):
            d = field.add("Distance")
            field.setNumbers(d, "PointsList", [tip])
            th = field.add("Threshold")
            field.setNumber(th, "InField", d)
            field.setNumber(th, "SizeMin", h)
            field.setNumber(th, "SizeMax", h_far)
            field.setNumber(th, "DistMin", fine_radius)
            field.setNumber(th, "DistMax", coarse_radius)
            r = field.add("Restrict")
            field.setNumber(r, "InField", th)
            field.setNumbers(r, "SurfacesList", [surf])
            field.setNumbers(r, "CurvesList", [*arcs, flat])
            fields.append(r)
        mn = field.add("Min")
        field.setNumbers(mn, "FieldsList", fields)
        field.setAsBackgroundMesh(mn)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
        gmsh.option.setNumber("Mesh.Algorithm", 6)
        gmsh.model.mesh.generate(2)

    return mesh_on_rank(comm, rank, 2, build)


def block_on_block(
    comm: MPI.Comm,
    width: float = 1.0,
    height: float = 0.5,
    n_upper: int = 8,
    n_lower: int = 8,
    *,
    upper_width: float | None = None,
    rank: int = 0,
) -> MeshData:
    """Two stacked blocks [0, W] x [0, H] (target) and [x0, x0 + Wu] x [H, 2H] (striker).

    Structured triangles, ``n_upper`` and ``n_lower`` divisions along x (equal
    with equal widths: matching interface). The upper block has width
    ``upper_width`` (default W), centred: x0 = (W - Wu) / 2. Facets: striker
    top 2, striker bottom 3, target top 4, target bottom 5, both left faces: 6.
    """
    upper = width if upper_width is None else upper_width
    _check(width=width, height=height, n_upper=n_upper, n_lower=n_lower, upper_width=upper)

    def build(gmsh) -> None:
        gmsh.option.setNumber("General.Verbosity", 0)
        gmsh.option.setNumber("Geometry.AutoCoherence", 0)  # keep the bodies apart
        gmsh.model.add("block_on_block")
        geo = gmsh.model.geo
        out = {}
        x0 = 0.5 * (width - upper)
        for name, y0, n, a, b in (("lower", 0.0, n_lower, 0.0, width),
                                  ("upper", height, n_upper, x0, x0 + upper)):
            p = [geo.addPoint(a, y0, 0), geo.addPoint(b, y0, 0),
                 geo.addPoint(b, y0 + height, 0), geo.addPoint(a, y0 + height, 0)]
            lines = [geo.addLine(p[i], p[(i + 1) % 4]) for i in range(4)]
            ny = max(2, round(n * height / (b - a)))
            for i, line in enumerate(lines):
                geo.mesh.setTransfiniteCurve(line, n + 1 if i % 2 == 0 else ny + 1)
            s = geo.addPlaneSurface([geo.addCurveLoop(lines)])
            geo.mesh.setTransfiniteSurface(s)
            out[name] = (lines, s)
        geo.synchronize()
        (lb, _, lt, ll), ls = out["lower"]
        (ub, _, ut, ul), us = out["upper"]
        gmsh.model.addPhysicalGroup(2, [us], STRIKER_TAG, name="striker")
        gmsh.model.addPhysicalGroup(2, [ls], TARGET_TAG, name="target")
        gmsh.model.addPhysicalGroup(1, [ut], LOAD_TAG, name="top")
        gmsh.model.addPhysicalGroup(1, [ub], STRIKER_FACE_TAG, name="striker_face")
        gmsh.model.addPhysicalGroup(1, [lt], TARGET_FACE_TAG, name="target_face")
        gmsh.model.addPhysicalGroup(1, [lb], SUPPORT_TAG, name="bottom")
        gmsh.model.addPhysicalGroup(1, [ll, ul], SYMMETRY_TAG, name="symmetry")
        gmsh.model.mesh.generate(2)

    return mesh_on_rank(comm, rank, 2, build)


def ironing(
    comm: MPI.Comm,
    radius: float = 0.5,
    length: float = 4.0,
    depth: float = 1.0,
    h_indenter: float = 0.04,
    h_block: float = 0.06,
    *,
    rank: int = 0,
) -> MeshData:
    """A half-disk indenter (centre (0, R), flat top y = R) on a block [-1, L - 1] x [-D, 0].

    Facets: indenter top 2, indenter arc 3, block top 4, block bottom 5.
    Uniform sizes ``h_indenter`` (arc) and ``h_block`` (block top).
    """
    _check(radius=radius, length=length, depth=depth, h_indenter=h_indenter, h_block=h_block)

    def build(gmsh) -> None:
        gmsh.option.setNumber("General.Verbosity", 0)
        gmsh.option.setNumber("Geometry.AutoCoherence", 0)  # keep the bodies apart
        gmsh.model.add("ironing")
        geo = gmsh.model.geo
        R = radius
        c = geo.addPoint(0, R, 0, 4 * h_indenter)
        left = geo.addPoint(-R, R, 0, 4 * h_indenter)
        tip = geo.addPoint(0, 0, 0, h_indenter)
        right = geo.addPoint(R, R, 0, 4 * h_indenter)
        a1, a2 = geo.addCircleArc(left, c, tip), geo.addCircleArc(tip, c, right)
        flat = geo.addLine(right, left)
        s_ind = geo.addPlaneSurface([geo.addCurveLoop([a1, a2, flat])])
        x0, x1 = -1.0, length - 1.0
        p = [geo.addPoint(x0, -depth, 0, 4 * h_block), geo.addPoint(x1, -depth, 0, 4 * h_block),
             geo.addPoint(x1, 0, 0, h_block), geo.addPoint(x0, 0, 0, h_block)]
        lines = [geo.addLine(p[i], p[(i + 1) % 4]) for i in range(4)]
        s_blk = geo.addPlaneSurface([geo.addCurveLoop(lines)])
        geo.synchronize()
        gmsh.model.addPhysicalGroup(2, [s_ind], STRIKER_TAG, name="striker")
        gmsh.model.addPhysicalGroup(2, [s_blk], TARGET_TAG, name="target")
        gmsh.model.addPhysicalGroup(1, [flat], LOAD_TAG, name="top")
        gmsh.model.addPhysicalGroup(1, [a1, a2], STRIKER_FACE_TAG, name="striker_arc")
        gmsh.model.addPhysicalGroup(1, [lines[2]], TARGET_FACE_TAG, name="target_face")
        gmsh.model.addPhysicalGroup(1, [lines[0]], SUPPORT_TAG, name="bottom")
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
        gmsh.option.setNumber("Mesh.Algorithm", 6)
        gmsh.model.mesh.generate(2)

    return mesh_on_rank(comm, rank, 2, build)


#: Facet tag of the symmetry faces y = 0 of the hemisphere quarters (x = 0 is SYMMETRY_TAG).
SYMMETRY_Y_TAG = 7


def two_hemispheres(
    comm: MPI.Comm,
    radius: float = 1.0,
    h_contact: float = 0.025,
    h_far: float = 0.25,
    fine_radius: float = 0.15,
    coarse_radius: float = 0.6,
    *,
    rank: int = 0,
) -> MeshData:
    """Quarters (x, y >= 0) of two hemispheres touching at the origin (3D, tetrahedra).

    Upper (striker): ball centre (0, 0, R), z in [0, R]; lower (target): ball
    centre (0, 0, -R), z in [-R, 0]. Meshed independently (non-matching).
    Facets: upper flat face z = R 2, upper sphere 3, lower sphere 4, lower
    flat face z = -R 5, symmetry x = 0 6 and y = 0 7 (both bodies).
    """
    _check(radius=radius, h_contact=h_contact, h_far=h_far)

    def build(gmsh) -> None:
        gmsh.option.setNumber("General.Verbosity", 0)
        gmsh.model.add("two_hemispheres")
        occ = gmsh.model.occ
        R = radius
        upper, _ = occ.intersect([(3, occ.addSphere(0, 0, R, R))],
                                 [(3, occ.addBox(0, 0, 0, R, R, R))])
        lower, _ = occ.intersect([(3, occ.addSphere(0, 0, -R, R))],
                                 [(3, occ.addBox(0, 0, -R, R, R, R))])
        occ.synchronize()
        tol = 1e-6 * R
        groups: dict[int, list[int]] = {t: [] for t in (LOAD_TAG, STRIKER_FACE_TAG,
                                                          TARGET_FACE_TAG, SUPPORT_TAG,
                                                          SYMMETRY_TAG, SYMMETRY_Y_TAG)}
        for body, curved, flat in ((upper[0], STRIKER_FACE_TAG, LOAD_TAG),
                                   (lower[0], TARGET_FACE_TAG, SUPPORT_TAG)):
            for _, tag in gmsh.model.getBoundary([body], oriented=False):
                x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(2, tag)
                if z1 - z0 < tol and abs(abs(z0) - R) < tol:
                    groups[flat].append(tag)
                elif x1 - x0 < tol and abs(x0) < tol:
                    groups[SYMMETRY_TAG].append(tag)
                elif y1 - y0 < tol and abs(y0) < tol:
                    groups[SYMMETRY_Y_TAG].append(tag)
                else:
                    groups[curved].append(tag)
        gmsh.model.addPhysicalGroup(3, [upper[0][1]], STRIKER_TAG, name="striker")
        gmsh.model.addPhysicalGroup(3, [lower[0][1]], TARGET_TAG, name="target")
        names = {LOAD_TAG: "top", STRIKER_FACE_TAG: "striker_cap", TARGET_FACE_TAG: "target_cap",
                 SUPPORT_TAG: "bottom", SYMMETRY_TAG: "symmetry_x", SYMMETRY_Y_TAG: "symmetry_y"}
        for tag, surfaces in groups.items():
            gmsh.model.addPhysicalGroup(2, surfaces, tag, name=names[tag])
        field = gmsh.model.mesh.field
        d = field.add("MathEval")
        field.setString(d, "F", "Sqrt(x*x + y*y + z*z)")
        th = field.add("Threshold")
        field.setNumber(th, "InField", d)
        field.setNumber(th, "SizeMin", h_contact)
        field.setNumber(th, "SizeMax", h_far)
        field.setNumber(th, "DistMin", fine_radius)
        field.setNumber(th, "DistMax", coarse_radius)
        field.setAsBackgroundMesh(th)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
        gmsh.model.mesh.generate(3)

    return mesh_on_rank(comm, rank, 3, build)
