// A 3D block [-0.5, 0.5] x [-0.5, 0.5] x [0, 0.5] of tetrahedra, refined
// toward the centre of its base (where a rigid ball presses, see
// scenes/block_3d_tet.toml).
//
// Physical groups:
//   Physical Volume  "body" = 1
//   Physical Surface "xmin" = 1, "xmax" = 2, "ymin" = 3, "ymax" = 4,
//                    "zmin" = 5 (base: candidate contact), "zmax" = 6 (top)
//
// Mesh with: fenics-contact mesh meshes/block.geo
DefineConstant[
  h_far = {0.1, Name "Parameters/h_far"},
  h_contact = {0.03, Name "Parameters/h_contact"}
];
SetFactory("OpenCASCADE");
Box(1) = {-0.5, -0.5, 0, 1, 1, 0.5};

Field[1] = Distance;
Field[1].PointsList = {};
Point(100) = {0, 0, 0};
Field[1].PointsList = {100};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = h_contact;
Field[2].SizeMax = h_far;
Field[2].DistMin = 0.1;
Field[2].DistMax = 0.5;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;

Physical Volume("body", 1) = {1};
Physical Surface("xmin", 1) = {1};
Physical Surface("xmax", 2) = {2};
Physical Surface("ymin", 3) = {3};
Physical Surface("ymax", 4) = {4};
Physical Surface("zmin", 5) = {5};
Physical Surface("zmax", 6) = {6};
