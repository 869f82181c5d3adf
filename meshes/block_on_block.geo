// Contact patch test: a block [0, W] x [H, 2H] (striker) on a block [0, W] x [0, H] (target).
//
// Structured triangles with n_upper and n_lower divisions along x: equal
// values give matching meshes at the interface y = H, different values
// non-matching ones. Same geometry and tags as
// fenics_contact.scene.two_body_meshing.block_on_block.
//
// Physical groups:
//   Surface "striker" = 1, Surface "target" = 2                       (cell tags)
//   Curve "top" = 2, "striker_face" = 3, "target_face" = 4, "bottom" = 5,
//   "symmetry" = 6 (both faces x = 0)                                  (facet tags)

DefineConstant[
  W = {1.0, Name "Parameters/width"},
  H = {0.5, Name "Parameters/height"},
  n_upper = {8, Name "Parameters/n_upper"},
  n_lower = {11, Name "Parameters/n_lower"}
];
Geometry.AutoCoherence = 0;  // keep the two bodies apart

Point(1) = {0, 0, 0}; Point(2) = {W, 0, 0}; Point(3) = {W, H, 0}; Point(4) = {0, H, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Transfinite Curve {1, 3} = n_lower + 1; Transfinite Curve {2, 4} = Round(n_lower * H / W) + 1;
Transfinite Surface {1};

Point(5) = {0, H, 0}; Point(6) = {W, H, 0}; Point(7) = {W, 2 * H, 0}; Point(8) = {0, 2 * H, 0};
Line(5) = {5, 6}; Line(6) = {6, 7}; Line(7) = {7, 8}; Line(8) = {8, 5};
Curve Loop(2) = {5, 6, 7, 8}; Plane Surface(2) = {2};
Transfinite Curve {5, 7} = n_upper + 1; Transfinite Curve {6, 8} = Round(n_upper * H / W) + 1;
Transfinite Surface {2};

Physical Surface("striker", 1) = {2};
Physical Surface("target", 2) = {1};
Physical Curve("top", 2) = {7};
Physical Curve("striker_face", 3) = {5};
Physical Curve("target_face", 4) = {3};
Physical Curve("bottom", 5) = {1};
Physical Curve("symmetry", 6) = {4, 8};
