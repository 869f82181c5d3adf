// Plane-strain Hertz validation: the lower half of a disk on the plane y = 0.
//
// The geometry of scenes/hertz_cylinder.toml and of benchmarks/cases.py
// (hertz_cylinder): the half-disk {x^2 + (y - R)^2 <= R^2, y <= R}, centre (0, R), touching
// y = 0 at (0, 0), which is a mesh vertex. P1 triangles of size h_contact
// within fine_radius of (0, 0), growing linearly to h_far at coarse_radius.
//
// Physical groups:
//   Physical Surface "body"    = 1   the half-disk (cell tags)
//   Physical Curve   "top"     = 2   the flat face y = R (facet tags; moved down)
//   Physical Curve   "contact" = 3   the arc (facet tags; candidate contact surface)
//
// Mesh it with, for example,
//   gmsh -2 -format msh4 meshes/hertz_cylinder.geo -o hertz_cylinder.msh
//   gmsh -2 -setnumber h_contact 0.002 meshes/hertz_cylinder.geo -o fine.msh
// and read it with dolfinx.io.gmsh.read_from_msh(path, comm, 0, gdim=2).

DefineConstant[
  R = {1.0, Name "Parameters/radius"},
  h_contact = {0.004, Name "Parameters/h_contact"},
  h_far = {0.1, Name "Parameters/h_far"},
  fine_radius = {0.1, Name "Parameters/fine_radius"},
  coarse_radius = {0.5, Name "Parameters/coarse_radius"}
];

Point(1) = {0, R, 0, h_far};        // centre of the disk
Point(2) = {-R, R, 0, h_far};       // left end of the flat face
Point(3) = {0, 0, 0, h_contact};    // contact point
Point(4) = {R, R, 0, h_far};        // right end of the flat face

Circle(1) = {2, 1, 3};              // left quarter arc
Circle(2) = {3, 1, 4};              // right quarter arc
Line(3) = {4, 2};                   // flat face y = R

Curve Loop(1) = {1, 2, 3};
Plane Surface(1) = {1};

Physical Surface("body", 1) = {1};
Physical Curve("top", 2) = {3};
Physical Curve("contact", 3) = {1, 2};

// Size field: h_contact near (0, 0), h_far far from it.
Field[1] = Distance;
Field[1].PointsList = {3};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = h_contact;
Field[2].SizeMax = h_far;
Field[2].DistMin = fine_radius;
Field[2].DistMax = coarse_radius;
Background Field = 2;

Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.Algorithm = 6;  // Frontal-Delaunay
