// A bridge block resting across two support blocks (2D, plane strain).
//
// Supports [0, 1] x [0, H] and [2, 3] x [0, H]; bridge [0.5, 2.5] x [H, H + T]
// on them. Three separate bodies (no shared nodes), non-matching at the
// contacts: hs on the supports, hb on the bridge; scenes/bridge.toml.
//
// Physical groups:
//   Surface "left_support" = 1, "right_support" = 2, "bridge" = 3     (cell tags)
//   Curve "left_base" = 1, "right_base" = 2, "left_top" = 3, "right_top" = 4,
//   "bridge_under_left" = 5, "bridge_under_right" = 6: the halves of the bridge's
//   underside, x in [0.5, 1.5] and [1.5, 2.5], each running on past its support
//   over the gap; with whole_underside = 0 only the parts over the supports,
//   x in [0.5, 1] and [2, 2.5], "bridge_top" = 9                     (facet tags)
DefineConstant[
  H = {0.5, Name "Parameters/support_height"},
  T = {0.3, Name "Parameters/bridge_thickness"},
  hs = {0.1, Name "Parameters/h_support"},
  hb = {0.05, Name "Parameters/h_bridge"},
  whole_underside = {1, Name "Parameters/whole_underside"}
];
Geometry.AutoCoherence = 0;
Point(1) = {0, 0, 0, hs}; Point(2) = {1, 0, 0, hs}; Point(3) = {1, H, 0, hs}; Point(4) = {0, H, 0, hs};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Point(11) = {2, 0, 0, hs}; Point(12) = {3, 0, 0, hs}; Point(13) = {3, H, 0, hs}; Point(14) = {2, H, 0, hs};
Line(11) = {11, 12}; Line(12) = {12, 13}; Line(13) = {13, 14}; Line(14) = {14, 11};
Curve Loop(11) = {11, 12, 13, 14}; Plane Surface(11) = {11};
// the bridge's underside in four pieces: over the left support, the span's halves, over the right
Point(21) = {0.5, H, 0, hb}; Point(22) = {1.0, H, 0, hb}; Point(23) = {1.5, H, 0, hb};
Point(24) = {2.0, H, 0, hb}; Point(25) = {2.5, H, 0, hb};
Point(26) = {2.5, H + T, 0, hb}; Point(27) = {0.5, H + T, 0, hb};
Line(21) = {21, 22}; Line(22) = {22, 23}; Line(23) = {23, 24}; Line(24) = {24, 25};
Line(25) = {25, 26}; Line(26) = {26, 27}; Line(27) = {27, 21};
Curve Loop(21) = {21, 22, 23, 24, 25, 26, 27}; Plane Surface(21) = {21};
Mesh.Algorithm = 6;
Physical Surface("left_support", 1) = {1};
Physical Surface("right_support", 2) = {11};
Physical Surface("bridge", 3) = {21};
Physical Curve("left_base", 1) = {1};
Physical Curve("right_base", 2) = {11};
Physical Curve("left_top", 3) = {3};
Physical Curve("right_top", 4) = {13};
If (whole_underside)
  Physical Curve("bridge_under_left", 5) = {21, 22};
  Physical Curve("bridge_under_right", 6) = {23, 24};
Else
  Physical Curve("bridge_under_left", 5) = {21};
  Physical Curve("bridge_under_right", 6) = {24};
EndIf
Physical Curve("bridge_top", 9) = {26};
