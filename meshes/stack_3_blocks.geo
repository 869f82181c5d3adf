// Three blocks stacked: [0, W] x [0, H] (bottom), [0, W] x [H, 2H] (middle),
// [0, W] x [2H, 3H] (top), meshed apart (each interface has two coincident
// lines). Structured triangles with n_bottom, n_middle and n_top divisions
// along x: different values give non-matching interfaces.
//
// Physical groups:
//   Surface "bottom_block" = 1, "middle_block" = 2, "top_block" = 3     (cell tags)
//   Curve "floor_face" = 1 (y = 0), "top" = 2 (y = 3H),
//   "middle_underside" = 3, "bottom_topside" = 4 (y = H),
//   "top_underside" = 5, "middle_topside" = 6 (y = 2H),
//   "symmetry" = 7 (every block's side x = 0)                            (facet tags)

DefineConstant[
  W = {1.0, Name "Parameters/width"},
  H = {0.4, Name "Parameters/height"},
  n_bottom = {10, Name "Parameters/n_bottom"},
  n_middle = {7, Name "Parameters/n_middle"},
  n_top = {5, Name "Parameters/n_top"}
];
Geometry.AutoCoherence = 0;  // keep the blocks apart

Macro Slab
  // a block [0, W] x [y0, y0 + H] with n divisions along x, from entity number k
  Point(k + 1) = {0, y0, 0}; Point(k + 2) = {W, y0, 0};
  Point(k + 3) = {W, y0 + H, 0}; Point(k + 4) = {0, y0 + H, 0};
  Line(k + 1) = {k + 1, k + 2}; Line(k + 2) = {k + 2, k + 3};
  Line(k + 3) = {k + 3, k + 4}; Line(k + 4) = {k + 4, k + 1};
  Curve Loop(k + 1) = {k + 1, k + 2, k + 3, k + 4}; Plane Surface(k + 1) = {k + 1};
  Transfinite Curve {k + 1, k + 3} = n + 1;
  Transfinite Curve {k + 2, k + 4} = Round(n * H / W) + 1;
  Transfinite Surface {k + 1};
Return

k = 0; y0 = 0; n = n_bottom; Call Slab;
k = 10; y0 = H; n = n_middle; Call Slab;
k = 20; y0 = 2 * H; n = n_top; Call Slab;

Physical Surface("bottom_block", 1) = {1};
Physical Surface("middle_block", 2) = {11};
Physical Surface("top_block", 3) = {21};
Physical Curve("floor_face", 1) = {1};
Physical Curve("top", 2) = {23};
Physical Curve("middle_underside", 3) = {11};
Physical Curve("bottom_topside", 4) = {3};
Physical Curve("top_underside", 5) = {21};
Physical Curve("middle_topside", 6) = {13};
Physical Curve("symmetry", 7) = {4, 14, 24};
