// Two identical half-disks touching at the origin (plane-strain Hertz, two cylinders).
//
// Upper (striker): {x^2 + (y - R)^2 <= R^2, y <= R}, flat face y = R.
// Lower (target):  {x^2 + (y + R)^2 <= R^2, y >= -R}, flat face y = -R.
// The bodies share no node: the lower one is meshed with a contact size
// target_ratio * h_contact, so the meshes at the interface do not match.
// Used by scenes/two_cylinders*.toml, cattaneo_mindlin*.toml and benchmarks/cases.py.
//
// Physical groups:
//   Surface "striker" = 1, Surface "target" = 2        (cell tags)
//   Curve "top" = 2, "striker_arc" = 3, "target_arc" = 4, "bottom" = 5   (facet tags)

DefineConstant[
  R = {1.0, Name "Parameters/radius"},
  h_contact = {0.01, Name "Parameters/h_contact"},
  h_far = {0.1, Name "Parameters/h_far"},
  target_ratio = {1.37, Name "Parameters/target_ratio"},
  fine_radius = {0.15, Name "Parameters/fine_radius"},
  coarse_radius = {0.6, Name "Parameters/coarse_radius"}
];
Geometry.AutoCoherence = 0;  // keep the two bodies apart

Point(1) = {0, R, 0};  Point(2) = {-R, R, 0};  Point(3) = {0, 0, 0};  Point(4) = {R, R, 0};
Circle(1) = {2, 1, 3};  Circle(2) = {3, 1, 4};  Line(3) = {4, 2};
Curve Loop(1) = {1, 2, 3};  Plane Surface(1) = {1};

Point(11) = {0, -R, 0};  Point(12) = {-R, -R, 0};  Point(13) = {0, 0, 0};  Point(14) = {R, -R, 0};
Circle(11) = {12, 11, 13};  Circle(12) = {13, 11, 14};  Line(13) = {14, 12};
Curve Loop(11) = {11, 12, 13};  Plane Surface(11) = {11};

Physical Surface("striker", 1) = {1};
Physical Surface("target", 2) = {11};
Physical Curve("top", 2) = {3};
Physical Curve("striker_arc", 3) = {1, 2};
Physical Curve("target_arc", 4) = {11, 12};
Physical Curve("bottom", 5) = {13};

Field[1] = Distance;  Field[1].PointsList = {3};
Field[2] = Threshold; Field[2].InField = 1; Field[2].SizeMin = h_contact;
Field[2].SizeMax = h_far; Field[2].DistMin = fine_radius; Field[2].DistMax = coarse_radius;
Field[3] = Restrict;  Field[3].InField = 2; Field[3].SurfacesList = {1}; Field[3].CurvesList = {1, 2, 3};
Field[4] = Distance;  Field[4].PointsList = {13};
Field[5] = Threshold; Field[5].InField = 4; Field[5].SizeMin = h_contact * target_ratio;
Field[5].SizeMax = h_far; Field[5].DistMin = fine_radius; Field[5].DistMax = coarse_radius;
Field[6] = Restrict;  Field[6].InField = 5; Field[6].SurfacesList = {11}; Field[6].CurvesList = {11, 12, 13};
Field[7] = Min; Field[7].FieldsList = {3, 6};
Background Field = 7;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.Algorithm = 6;
