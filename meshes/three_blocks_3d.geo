// Three square blocks stacked in a column on a rigid floor, each narrower
// than the one below: quarter model (the planes x = 0 and y = 0 are
// symmetry planes). Bottom [0, a1]^2 x [0, H], middle [0, a2]^2 x [H, 2H],
// top [0, a3]^2 x [2H, 3H], meshed apart (each interface has two coincident
// faces) with tetrahedra of sizes h_bottom, h_middle and h_top: the upper
// blocks are finer.
//
// Physical groups:
//   Volume "bottom_block" = 1, "middle_block" = 2, "top_block" = 3         (cell tags)
//   Surface "floor_face" = 1 (z = 0), "top" = 2 (z = 3H),
//   "middle_underside" = 3, "bottom_topside" = 4 (z = H),
//   "top_underside" = 5, "middle_topside" = 6 (z = 2H),
//   "symmetry_x" = 7 (x = 0), "symmetry_y" = 8 (y = 0)                     (facet tags)

SetFactory("OpenCASCADE");
DefineConstant[
  a1 = {0.5, Name "Parameters/a1"},
  a2 = {0.4, Name "Parameters/a2"},
  a3 = {0.3, Name "Parameters/a3"},
  H = {0.4, Name "Parameters/height"},
  h_bottom = {0.12, Name "Parameters/h_bottom"},
  h_middle = {0.1, Name "Parameters/h_middle"},
  h_top = {0.08, Name "Parameters/h_top"}
];

Box(1) = {0, 0, 0, a1, a1, H};
Box(2) = {0, 0, H, a2, a2, H};
Box(3) = {0, 0, 2 * H, a3, a3, H};

e = 1e-6;
MeshSize{PointsOf{Volume{1};}} = h_bottom;
MeshSize{PointsOf{Volume{2};}} = h_middle;
MeshSize{PointsOf{Volume{3};}} = h_top;

Physical Volume("bottom_block", 1) = {1};
Physical Volume("middle_block", 2) = {2};
Physical Volume("top_block", 3) = {3};
Physical Surface("floor_face", 1) = Surface In BoundingBox{-e, -e, -e, a1 + e, a1 + e, e};
Physical Surface("top", 2) = Surface In BoundingBox{-e, -e, 3 * H - e, a3 + e, a3 + e, 3 * H + e};
// each interface plane holds two coincident-in-part faces: tell them apart by volume
s1[] = Boundary{Volume{1};}; s2[] = Boundary{Volume{2};}; s3[] = Boundary{Volume{3};};
Physical Surface("middle_underside", 3) = {s2[4]};
Physical Surface("bottom_topside", 4) = {s1[5]};
Physical Surface("top_underside", 5) = {s3[4]};
Physical Surface("middle_topside", 6) = {s2[5]};
Physical Surface("symmetry_x", 7) = {s1[0], s2[0], s3[0]};
Physical Surface("symmetry_y", 8) = {s1[2], s2[2], s3[2]};
Mesh.MeshSizeFromCurvature = 0;
Mesh.MeshSizeExtendFromBoundary = 1;
