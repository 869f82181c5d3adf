// Half of an O-ring's cross-section: the disk of diameter d, centre (0, 0),
// for x >= 0 (the plane x = 0 is a symmetry plane), between two plates that
// touch it at (0, -d/2) and (0, d/2). Triangles of size h_contact within
// fine_radius of the two contact points, growing to h_far at coarse_radius.
//
// Physical groups:
//   Surface "ring" = 1                                                   (cell tags)
//   Curve "bottom_arc" = 1 (-90 to -10 degrees), "top_arc" = 2 (10 to 90),
//   "side_arc" = 3 (-10 to 10), "symmetry" = 4 (x = 0)                  (facet tags)

DefineConstant[
  d = {2.0, Name "Parameters/diameter"},
  h_contact = {0.02, Name "Parameters/h_contact"},
  h_far = {0.08, Name "Parameters/h_far"},
  fine_radius = {0.7, Name "Parameters/fine_radius"},
  coarse_radius = {1.0, Name "Parameters/coarse_radius"}
];
R = d / 2;
a = 10 * Pi / 180;
Point(1) = {0, 0, 0, h_far};
Point(2) = {0, -R, 0, h_contact};
Point(3) = {R * Cos(a), -R * Sin(a), 0, h_far};
Point(4) = {R * Cos(a), R * Sin(a), 0, h_far};
Point(5) = {0, R, 0, h_contact};
Circle(1) = {2, 1, 3};
Circle(2) = {3, 1, 4};
Circle(3) = {4, 1, 5};
Line(4) = {5, 2};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

Physical Surface("ring", 1) = {1};
Physical Curve("bottom_arc", 1) = {1};
Physical Curve("top_arc", 2) = {3};
Physical Curve("side_arc", 3) = {2};
Physical Curve("symmetry", 4) = {4};

Field[1] = Distance;
Field[1].PointsList = {2, 5};
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
Mesh.Algorithm = 6;
