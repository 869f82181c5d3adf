// The 3D contact patch test: a square block pressed onto another of the same
// footprint, quarter model (the planes x = 0 and y = 0 are symmetry planes).
// Lower block [0, W]^2 x [0, H], upper block [0, W]^2 x [H, 2H], meshed apart
// with tetrahedra of sizes h_lower and h_upper: the two faces at z = H
// coincide but their triangles do not match.
//
// Physical groups:
//   Volume "striker" = 1 (upper block), "target" = 2 (lower block)        (cell tags)
//   Surface "top" = 2 (z = 2H), "striker_face" = 3 and "target_face" = 4
//   (z = H), "bottom" = 5 (z = 0), "symmetry_x" = 6 (x = 0),
//   "symmetry_y" = 7 (y = 0)                                              (facet tags)

SetFactory("OpenCASCADE");
DefineConstant[
  W = {0.5, Name "Parameters/width"},
  H = {0.5, Name "Parameters/height"},
  h_upper = {0.125, Name "Parameters/h_upper"},
  h_lower = {0.17, Name "Parameters/h_lower"}
];

Box(1) = {0, 0, H, W, W, H};
Box(2) = {0, 0, 0, W, W, H};

e = 1e-6;
MeshSize{PointsOf{Volume{1};}} = h_upper;
MeshSize{PointsOf{Volume{2};}} = h_lower;

Physical Volume("striker", 1) = {1};
Physical Volume("target", 2) = {2};
Physical Surface("top", 2) = Surface In BoundingBox{-e, -e, 2 * H - e, W + e, W + e, 2 * H + e};
// the interface plane holds two coincident faces: tell them apart by volume
s1[] = Boundary{Volume{1};}; s2[] = Boundary{Volume{2};};
Physical Surface("striker_face", 3) = {s1[4]};
Physical Surface("target_face", 4) = {s2[5]};
Physical Surface("bottom", 5) = Surface In BoundingBox{-e, -e, -e, W + e, W + e, e};
Physical Surface("symmetry_x", 6) = {s1[0], s2[0]};
Physical Surface("symmetry_y", 7) = {s1[2], s2[2]};
Mesh.MeshSizeFromCurvature = 0;
Mesh.MeshSizeExtendFromBoundary = 1;
