// A U-shaped strip (2D, plane strain): a block [0, L] x [0, 1] with a slot
// [c, L] x [a, a + s] cut from its right side, leaving a lower arm (below the
// slot) and an upper arm (above it) joined on the left. The upper arm's face
// on the slot is meshed finer than the lower arm's (h_upper, h_lower): the
// two faces meet non-matching. scenes/u_strip.toml.
//
// Physical groups:
//   Surface "strip" = 1                                               (cell tag)
//   Curve "bottom" = 1 (y = 0), "lower_face" = 2 (the lower arm's face on the
//   slot), "upper_face" = 3 (the upper arm's), "tip" = 4 (the upper arm's end,
//   x = L), "slot_end" = 5 (x = c), "sides" = 6 (the other faces)   (facet tags)
DefineConstant[
  L = {2.0, Name "Parameters/length"},
  c = {0.3, Name "Parameters/slot_start"},
  a = {0.4, Name "Parameters/lower_thickness"},
  s = {0.2, Name "Parameters/slot_width"},
  h_upper = {0.05, Name "Parameters/h_upper"},
  h_lower = {0.08, Name "Parameters/h_lower"}
];
Point(1) = {0, 0, 0, h_lower}; Point(2) = {L, 0, 0, h_lower}; Point(3) = {L, a, 0, h_lower};
Point(4) = {c, a, 0, h_lower}; Point(5) = {c, a + s, 0, h_upper}; Point(6) = {L, a + s, 0, h_upper};
Point(7) = {L, 1, 0, h_upper}; Point(8) = {0, 1, 0, h_upper};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5};
Line(5) = {5, 6}; Line(6) = {6, 7}; Line(7) = {7, 8}; Line(8) = {8, 1};
Curve Loop(1) = {1, 2, 3, 4, 5, 6, 7, 8}; Plane Surface(1) = {1};
Physical Surface("strip", 1) = {1};
Physical Curve("bottom", 1) = {1};
Physical Curve("lower_face", 2) = {3};
Physical Curve("upper_face", 3) = {5};
Physical Curve("tip", 4) = {6};
Physical Curve("slot_end", 5) = {4};
Physical Curve("sides", 6) = {2, 7, 8};
