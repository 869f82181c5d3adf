// 3D Hertz validation: one eighth of a sphere resting on the plane z = 0.
//
// The geometry of benchmarks/cases.py (hertz_sphere):
// {x >= 0, y >= 0, z <= R, x^2 + y^2 + (z - R)^2 <= R^2}, the quarter of the
// lower hemisphere of the sphere centred at (0, 0, R); it touches z = 0 at the
// origin, a mesh vertex. P1 tetrahedra of size h_contact within fine_radius
// of the origin, growing linearly to h_far at coarse_radius.
//
// Physical groups:
//   Physical Volume  "body"       = 1
//   Physical Surface "top"        = 2   flat face z = R (pushed down)
//   Physical Surface "contact"    = 3   spherical surface (candidate contact)
//   Physical Surface "symmetry_x" = 4   x = 0 (u_x = 0)
//   Physical Surface "symmetry_y" = 5   y = 0 (u_y = 0)
//
// Mesh it with, for example,
//   gmsh -3 -format msh4 meshes/sphere.geo -o sphere.msh
//   gmsh -3 -setnumber h_contact 0.007 meshes/sphere.geo -o sphere_fine.msh
// and read it with dolfinx.io.gmsh.read_from_msh(path, comm, 0, gdim=3).

SetFactory("OpenCASCADE");

DefineConstant[
  R = {1.0, Name "Parameters/radius"},
  h_contact = {0.02, Name "Parameters/h_contact"},
  h_far = {0.25, Name "Parameters/h_far"},
  fine_radius = {0.15, Name "Parameters/fine_radius"},
  coarse_radius = {0.6, Name "Parameters/coarse_radius"}
];

Sphere(1) = {0, 0, R, R};
Box(2) = {0, 0, 0, R, R, R};
BooleanIntersection(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };

eps = 1e-6 * R;
top() = Surface In BoundingBox{-eps, -eps, R - eps, R + eps, R + eps, R + eps};
symx() = Surface In BoundingBox{-eps, -eps, -eps, eps, R + eps, R + eps};
symy() = Surface In BoundingBox{-eps, -eps, -eps, R + eps, eps, R + eps};
all() = Abs(Boundary{ Volume{3}; });
sphere() = all();
sphere() -= {top(), symx(), symy()};

Physical Volume("body", 1) = {3};
Physical Surface("top", 2) = {top()};
Physical Surface("contact", 3) = {sphere()};
Physical Surface("symmetry_x", 4) = {symx()};
Physical Surface("symmetry_y", 5) = {symy()};

origin() = Point In BoundingBox{-eps, -eps, -eps, eps, eps, eps};
Field[1] = Distance;
Field[1].PointsList = {origin()};
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
