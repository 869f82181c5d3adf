// Two hemispheres touching at the origin, quarter models (x >= 0, y >= 0), 3D.
//
// Upper (striker): ball centre (0, 0, R) cut to z in [0, R]; lower (target):
// ball centre (0, 0, -R) cut to z in [-R, 0]. Meshed independently with
// tetrahedra (non-matching at the contact); scenes/two_hemispheres_3d.toml.
//
// Physical groups:
//   Volume "striker" = 1, Volume "target" = 2                         (cell tags)
//   Surface "top" = 2, "striker_cap" = 3, "target_cap" = 4, "bottom" = 5,
//   "symmetry_x" = 6, "symmetry_y" = 7 (both bodies)                   (facet tags)

DefineConstant[
  R = {1.0, Name "Parameters/radius"},
  h_contact = {0.02, Name "Parameters/h_contact"},
  h_far = {0.25, Name "Parameters/h_far"},
  fine_radius = {0.15, Name "Parameters/fine_radius"},
  coarse_radius = {0.6, Name "Parameters/coarse_radius"}
];
SetFactory("OpenCASCADE");
Sphere(1) = {0, 0, R, R};
Box(2) = {0, 0, 0, R, R, R};
BooleanIntersection(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
Sphere(4) = {0, 0, -R, R};
Box(5) = {0, 0, -R, R, R, R};
BooleanIntersection(6) = { Volume{4}; Delete; }{ Volume{5}; Delete; };

e = 1e-6 * R;
top() = Surface In BoundingBox{-e, -e, R - e, R + e, R + e, R + e};
bottom() = Surface In BoundingBox{-e, -e, -R - e, R + e, R + e, -R + e};
symx() = Surface In BoundingBox{-e, -e, -R - e, e, R + e, R + e};
symy() = Surface In BoundingBox{-e, -e, -R - e, R + e, e, R + e};
cap_u() = Boundary{ Volume{3}; };
cap_u() -= {top(), symx(), symy()};
cap_l() = Boundary{ Volume{6}; };
cap_l() -= {bottom(), symx(), symy()};

Physical Volume("striker", 1) = {3};
Physical Volume("target", 2) = {6};
Physical Surface("top", 2) = {top()};
Physical Surface("striker_cap", 3) = {cap_u()};
Physical Surface("target_cap", 4) = {cap_l()};
Physical Surface("bottom", 5) = {bottom()};
Physical Surface("symmetry_x", 6) = {symx()};
Physical Surface("symmetry_y", 7) = {symy()};

Field[1] = MathEval;
Field[1].F = "Sqrt(x*x + y*y + z*z)";
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
