// An elastic hemisphere on an elastic block, quarter model (x >= 0, y >= 0), 3D.
//
// Hemisphere: ball centre (0, 0, R) cut to z in [0, R], its pole touching the
// block's top z = 0 at the origin; block [0, L] x [0, L] x [-H, 0]. Meshed
// independently with tetrahedra (non-matching at the contact): h_sphere on the
// hemisphere and h_block on the block within fine_radius of the origin,
// growing to h_far at coarse_radius; scenes/sphere_on_block_3d.toml.
//
// Physical groups:
//   Volume "sphere" = 1, Volume "block" = 2                            (cell tags)
//   Surface "top" = 2 (z = R), "sphere_cap" = 3, "block_top" = 4 (z = 0),
//   "bottom" = 5 (z = -H), "symmetry_x" = 6, "symmetry_y" = 7 (both bodies),
//   "block_sides" = 8 (x = L and y = L, free)                          (facet tags)

DefineConstant[
  R = {1.0, Name "Parameters/radius"},
  L = {2.0, Name "Parameters/block_half_width"},
  H = {1.0, Name "Parameters/block_height"},
  h_sphere = {0.016, Name "Parameters/h_sphere"},
  h_block = {0.012, Name "Parameters/h_block"},
  h_far = {0.3, Name "Parameters/h_far"},
  fine_radius = {0.2, Name "Parameters/fine_radius"},
  coarse_radius = {1.0, Name "Parameters/coarse_radius"}
];
SetFactory("OpenCASCADE");
Sphere(1) = {0, 0, R, R};
Box(2) = {0, 0, 0, R, R, R};
BooleanIntersection(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
Box(4) = {0, 0, -H, L, L, H};

e = 1e-6 * R;
top() = Surface In BoundingBox{-e, -e, R - e, R + e, R + e, R + e};
block_top() = Surface In BoundingBox{-e, -e, -e, L + e, L + e, e};
bottom() = Surface In BoundingBox{-e, -e, -H - e, L + e, L + e, -H + e};
symx() = Surface In BoundingBox{-e, -e, -H - e, e, L + e, R + e};
symy() = Surface In BoundingBox{-e, -e, -H - e, L + e, e, R + e};
side_x() = Surface In BoundingBox{L - e, -e, -H - e, L + e, L + e, e};
side_y() = Surface In BoundingBox{-e, L - e, -H - e, L + e, L + e, e};
cap() = Boundary{ Volume{3}; };
cap() -= {top(), symx(), symy()};

Physical Volume("sphere", 1) = {3};
Physical Volume("block", 2) = {4};
Physical Surface("top", 2) = {top()};
Physical Surface("sphere_cap", 3) = {cap()};
Physical Surface("block_top", 4) = {block_top()};
Physical Surface("bottom", 5) = {bottom()};
Physical Surface("symmetry_x", 6) = {symx()};
Physical Surface("symmetry_y", 7) = {symy()};
Physical Surface("block_sides", 8) = {side_x(), side_y()};

// Size: by the distance from the origin, each body its own near the contact.
Field[1] = MathEval;
Field[1].F = "Sqrt(x*x + y*y + z*z)";
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = h_sphere;
Field[2].SizeMax = h_far;
Field[2].DistMin = fine_radius;
Field[2].DistMax = coarse_radius;
Field[3] = Restrict;
Field[3].InField = 2;
Field[3].VolumesList = {3};
Field[4] = Threshold;
Field[4].InField = 1;
Field[4].SizeMin = h_block;
Field[4].SizeMax = h_far;
Field[4].DistMin = fine_radius;
Field[4].DistMax = coarse_radius;
Field[5] = Restrict;
Field[5].InField = 4;
Field[5].VolumesList = {4};
Field[6] = Min;
Field[6].FieldsList = {3, 5};
Background Field = 6;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
