"""Two-body meshes (one mesh, two cell tags) built with the gmsh Python API.

The bodies do not share nodes: each is its own gmsh surface, so the meshes
at the interface are independent (non-matching unless the sizes agree).
Tags: cells of the striker (upper body) 1, of the target (lower body) 2;
facets as listed per builder. The ``.geo`` files in ``meshes/`` describe
the same geometries for the gmsh command line.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from dolfinx.io.gmsh import MeshData

from mpi4py import MPI

from fenics_contact.scene.meshing import (
    add_groups,
    ball_quarters,
    half_disk,
    mesh_on_rank,
    new_model,
    quarter_faces,
    size_field_only,
    threshold_field,
)

#: Cell tags.
STRIKER_TAG, TARGET_TAG = 1, 2
#: Facet tags: striker loaded face, striker contact face, target contact face,
#: target supported face, symmetry face x = 0 (blocks only).
LOAD_TAG, STRIKER_FACE_TAG, TARGET_FACE_TAG, SUPPORT_TAG, SYMMETRY_TAG = 2, 3, 4, 5, 6


def _check(**sizes: float) -> None:
    for name, value in sizes.items():
        if not value > 0:
            raise ValueError(f"{name} must be > 0, got {name} = {value}.")


def _add_pair_groups(
    gmsh: Any,
    dim: int,
    bodies: tuple[int, int],
    faces: dict[int, Sequence[int]],
    face_names: tuple[str, str],
) -> None:
    """Physical groups shared by every pair: the two bodies and four facet groups.

    Args:
        gmsh: the gmsh module.
        dim: dimension of the bodies (their facets have ``dim - 1``).
        bodies: (striker, target) entity tags.
        faces: entities under LOAD_TAG, STRIKER_FACE_TAG, TARGET_FACE_TAG, SUPPORT_TAG.
        face_names: names of the striker and target contact faces.
    """
    add_groups(gmsh, dim, {STRIKER_TAG: ("striker", [bodies[0]]),
                           TARGET_TAG: ("target", [bodies[1]])})
    names = {LOAD_TAG: "top", STRIKER_FACE_TAG: face_names[0],
             TARGET_FACE_TAG: face_names[1], SUPPORT_TAG: "bottom"}
    add_groups(gmsh, dim - 1, {tag: (names[tag], faces[tag]) for tag in names})


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
        new_model(gmsh, "two_half_disks", separate=True)
        up = half_disk(gmsh.model.geo, radius, 1.0)
        lo = half_disk(gmsh.model.geo, radius, -1.0)
        gmsh.model.geo.synchronize()
        _add_pair_groups(
            gmsh, 2, (up[3], lo[3]),
            {LOAD_TAG: [up[2]], STRIKER_FACE_TAG: up[1], TARGET_FACE_TAG: lo[1],
             SUPPORT_TAG: [lo[2]]},
            ("striker_arc", "target_arc"),
        )
        field = gmsh.model.mesh.field
        fields = []
        for (tip, arcs, flat, surf), h in ((up, h_contact), (lo, h_contact * target_ratio)):
            d = field.add("Distance")
            field.setNumbers(d, "PointsList", [tip])
            th = threshold_field(gmsh, d, h, h_far, fine_radius, coarse_radius)
            r = field.add("Restrict")
            field.setNumber(r, "InField", th)
            field.setNumbers(r, "SurfacesList", [surf])
            field.setNumbers(r, "CurvesList", [*arcs, flat])
            fields.append(r)
        mn = field.add("Min")
        field.setNumbers(mn, "FieldsList", fields)
        size_field_only(gmsh, mn)
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
        new_model(gmsh, "block_on_block", separate=True)
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
        _add_pair_groups(
            gmsh, 2, (us, ls),
            {LOAD_TAG: [ut], STRIKER_FACE_TAG: [ub], TARGET_FACE_TAG: [lt], SUPPORT_TAG: [lb]},
            ("striker_face", "target_face"),
        )
        add_groups(gmsh, 1, {SYMMETRY_TAG: ("symmetry", [ll, ul])})
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
        new_model(gmsh, "ironing", separate=True)
        geo = gmsh.model.geo
        _, arcs, flat, s_ind = half_disk(geo, radius, h_rim=4 * h_indenter, h_tip=h_indenter)
        x0, x1 = -1.0, length - 1.0
        p = [geo.addPoint(x0, -depth, 0, 4 * h_block), geo.addPoint(x1, -depth, 0, 4 * h_block),
             geo.addPoint(x1, 0, 0, h_block), geo.addPoint(x0, 0, 0, h_block)]
        lines = [geo.addLine(p[i], p[(i + 1) % 4]) for i in range(4)]
        s_blk = geo.addPlaneSurface([geo.addCurveLoop(lines)])
        geo.synchronize()
        _add_pair_groups(
            gmsh, 2, (s_ind, s_blk),
            {LOAD_TAG: [flat], STRIKER_FACE_TAG: arcs, TARGET_FACE_TAG: [lines[2]],
             SUPPORT_TAG: [lines[0]]},
            ("striker_arc", "target_face"),
        )
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
        new_model(gmsh, "two_hemispheres")
        upper, lower = ball_quarters(gmsh, radius, [radius, -radius])
        up, lo = quarter_faces(gmsh, upper, radius), quarter_faces(gmsh, lower, radius)
        _add_pair_groups(
            gmsh, 3, (upper[1], lower[1]),
            {LOAD_TAG: up["flat"], STRIKER_FACE_TAG: up["curved"],
             TARGET_FACE_TAG: lo["curved"], SUPPORT_TAG: lo["flat"]},
            ("striker_cap", "target_cap"),
        )
        add_groups(gmsh, 2, {SYMMETRY_TAG: ("symmetry_x", up["x"] + lo["x"]),
                             SYMMETRY_Y_TAG: ("symmetry_y", up["y"] + lo["y"])})
        d = gmsh.model.mesh.field.add("MathEval")
        gmsh.model.mesh.field.setString(d, "F", "Sqrt(x*x + y*y + z*z)")
        size_field_only(
            gmsh, threshold_field(gmsh, d, h_contact, h_far, fine_radius, coarse_radius)
        )
        gmsh.model.mesh.generate(3)

    return mesh_on_rank(comm, rank, 3, build)
