// A cylinder (disk of radius R, centre (0, 0)) between two rigid plates that
// touch it at (0, -R) and (0, R), and a second cylinder of the same radius,
// centre (2R, 0), touching the first at (R, 0). Each disk is split along its
// vertical diameter (a line of the mesh, held by a [[dirichlet]]). The disks
// are meshed apart (two coincident points at (R, 0)). Triangles of size
// h_contact within fine_radius of the three contact points, growing to h_far
// at coarse_radius.
//
// Physical groups:
//   Surface "left_cylinder" = 1, "right_cylinder" = 2                  (cell tags)
//   Curve "left_bottom" = 1 (arc from -135 to -45 degrees), "left_top" = 2
//   (45 to 135 degrees), "left_side" = 3 (-45 to 45: faces the right
//   cylinder), "left_axis" = 4 (x = 0), "right_side" = 5 (the right
//   cylinder's arc from 135 to 225 degrees), "right_axis" = 6 (x = 2R)  (facet tags)

DefineConstant[
  R = {1.0, Name "Parameters/radius"},
  h_contact = {0.01, Name "Parameters/h_contact"},
  h_far = {0.2, Name "Parameters/h_far"},
  fine_radius = {0.15, Name "Parameters/fine_radius"},
  coarse_radius = {0.8, Name "Parameters/coarse_radius"}
];
Geometry.AutoCoherence = 0;  // keep the cylinders apart at (R, 0)

Macro RoundBody
  // disk of radius R at (xc, 0), points every 45 degrees from -90, entities from k
  Point(k) = {xc, 0, 0, h_far};
  For i In {0 : 7}
    Point(k + 1 + i) = {xc + R * Cos((i - 2) * Pi / 4), R * Sin((i - 2) * Pi / 4), 0, h_far};
  EndFor
  For i In {0 : 7}
    Circle(k + 1 + i) = {k + 1 + i, k, k + 1 + (i + 1) % 8};
  EndFor
  Line(k + 9) = {k + 5, k + 1};  // the vertical diameter, top to bottom
  Curve Loop(k + 1) = {k + 1, k + 2, k + 3, k + 4, k + 9};
  Plane Surface(k + 1) = {k + 1};
  Curve Loop(k + 2) = {k + 5, k + 6, k + 7, k + 8, -(k + 9)};
  Plane Surface(k + 2) = {k + 2};
Return

k = 0; xc = 0; Call RoundBody;
k = 20; xc = 2 * R; Call RoundBody;
// arcs: k + 1 (-90..-45), k + 2 (-45..0), k + 3 (0..45), k + 4 (45..90),
// k + 5 (90..135), k + 6 (135..180), k + 7 (180..225), k + 8 (225..270)

Physical Surface("left_cylinder", 1) = {1, 2};
Physical Surface("right_cylinder", 2) = {21, 22};
Physical Curve("left_bottom", 1) = {8, 1};
Physical Curve("left_top", 2) = {4, 5};
Physical Curve("left_side", 3) = {2, 3};
Physical Curve("left_axis", 4) = {9};
Physical Curve("right_side", 5) = {26, 27};
Physical Curve("right_axis", 6) = {29};

Field[1] = Distance;
Field[1].PointsList = {1, 3, 5, 27};  // (0, -R), (R, 0) twice, (0, R)
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
