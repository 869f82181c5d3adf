// Contact patch test: a block [x0, x0 + Wu] x [H, 2H] (striker) on a block
// [0, W] x [0, H] (target), the striker centred: x0 = (W - Wu) / 2 (Wu = W by
// default). Structured triangles with n_upper and n_lower divisions along x
// and rows_upper and rows_lower across (by default about as many per unit
// length as along, at least 2): equal values and
// widths give matching meshes at the interface y = H, different values
// non-matching ones.
//
// Physical groups:
//   Surface "striker" = 1, Surface "target" = 2                       (cell tags)
//   Curve "top" = 2, "striker_face" = 3, "target_face" = 4, "bottom" = 5,
//   "symmetry" = 6 (both faces x = 0)                                  (facet tags)

DefineConstant[
  W = {1.0, Name "Parameters/width"},
  H = {0.5, Name "Parameters/height"},
  n_upper = {8, Name "Parameters/n_upper"},
  n_lower = {11, Name "Parameters/n_lower"},
  Wu = {-1, Name "Parameters/upper_width"},  // -1: the width W
  rows_upper = {-1, Name "Parameters/rows_upper"},  // -1: about n_upper H / Wu, at least 2
  rows_lower = {-1, Name "Parameters/rows_lower"}   // -1: about n_lower H / W, at least 2
];
If (Wu <= 0)
  Wu = W;
EndIf
If (rows_upper <= 0)
  rows_upper = Max(2, Round(n_upper * H / Wu));
EndIf
If (rows_lower <= 0)
  rows_lower = Max(2, Round(n_lower * H / W));
EndIf
x0 = 0.5 * (W - Wu);
Geometry.AutoCoherence = 0;  // keep the two bodies apart

Point(1) = {0, 0, 0}; Point(2) = {W, 0, 0}; Point(3) = {W, H, 0}; Point(4) = {0, H, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Transfinite Curve {1, 3} = n_lower + 1; Transfinite Curve {2, 4} = rows_lower + 1;
Transfinite Surface {1};

Point(5) = {x0, H, 0}; Point(6) = {x0 + Wu, H, 0}; Point(7) = {x0 + Wu, 2 * H, 0};
Point(8) = {x0, 2 * H, 0};
Line(5) = {5, 6}; Line(6) = {6, 7}; Line(7) = {7, 8}; Line(8) = {8, 5};
Curve Loop(2) = {5, 6, 7, 8}; Plane Surface(2) = {2};
Transfinite Curve {5, 7} = n_upper + 1; Transfinite Curve {6, 8} = rows_upper + 1;
Transfinite Surface {2};

Physical Surface("striker", 1) = {2};
Physical Surface("target", 2) = {1};
Physical Curve("top", 2) = {7};
Physical Curve("striker_face", 3) = {5};
Physical Curve("target_face", 4) = {3};
Physical Curve("bottom", 5) = {1};
Physical Curve("symmetry", 6) = {4, 8};
