// A block resting on two blocks that stand side by side: the bottom blocks
// [0, W] x [0, H] and [W, 2W] x [0, H] touch along x = W; the top block
// [W/2, 3W/2] x [H, 2H] spans the joint, so its underside node at x = W
// sits on the corners of both. Meshed apart, structured triangles, n
// divisions along each block's width (n even: a top node lies on the joint).
//
// Physical groups:
//   Surface "left_block" = 1, "right_block" = 2, "top_block" = 3           (cell tags)
//   Curve "left_floor" = 1, "right_floor" = 2 (y = 0), "top" = 3 (y = 2H),
//   "left_wall" = 4 (x = 0), "right_wall" = 5 (x = 2W)                    (facet tags)

DefineConstant[
  W = {1.0, Name "Parameters/width"},
  H = {0.4, Name "Parameters/height"},
  n = {10, Name "Parameters/n"}
];
Geometry.AutoCoherence = 0;

Macro Slab
  Point(k + 1) = {x0, y0, 0}; Point(k + 2) = {x0 + W, y0, 0};
  Point(k + 3) = {x0 + W, y0 + H, 0}; Point(k + 4) = {x0, y0 + H, 0};
  Line(k + 1) = {k + 1, k + 2}; Line(k + 2) = {k + 2, k + 3};
  Line(k + 3) = {k + 3, k + 4}; Line(k + 4) = {k + 4, k + 1};
  Curve Loop(k + 1) = {k + 1, k + 2, k + 3, k + 4}; Plane Surface(k + 1) = {k + 1};
  Transfinite Curve {k + 1, k + 3} = n + 1;
  Transfinite Curve {k + 2, k + 4} = Round(n * H / W) + 1;
  Transfinite Surface {k + 1};
Return

k = 0; x0 = 0; y0 = 0; Call Slab;
k = 10; x0 = W; y0 = 0; Call Slab;
k = 20; x0 = W / 2; y0 = H; Call Slab;

Physical Surface("left_block", 1) = {1};
Physical Surface("right_block", 2) = {11};
Physical Surface("top_block", 3) = {21};
Physical Curve("left_floor", 1) = {1};
Physical Curve("right_floor", 2) = {11};
Physical Curve("top", 3) = {23};
Physical Curve("left_wall", 4) = {4};
Physical Curve("right_wall", 5) = {12};
