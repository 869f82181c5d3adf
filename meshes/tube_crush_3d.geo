// The thin tube of tube_crush.geo extruded along z: half of its section
// (x >= 0), n_z layers of prisms split into tetrahedra over the depth Lz.
// With u_z = 0 on both end faces it is the plane-strain section again, in
// 3D: tests/test_self_contact.py compares the two.
//
// Physical groups:
//   Volume "tube" = 1                                                   (cell tags)
//   Surface "outer_bottom" = 1, "outer_top" = 2 (the outer quarters),
//   "inner_bottom" = 3, "inner_top" = 5 (the inner quarters), "cut" = 4 (the
//   wall at x = 0), "front" = 6 (z = 0), "back" = 7 (z = Lz)             (facet tags)

DefineConstant[
  R_out = {1.0, Name "Parameters/outer radius"},
  t = {0.1, Name "Parameters/wall thickness"},
  n_t = {4, Name "Parameters/n_t"},
  n_q = {54, Name "Parameters/n_q"},
  Lz = {0.1, Name "Parameters/depth"},
  n_z = {1, Name "Parameters/n_z"}
];
R_in = R_out - t;
Point(1) = {0, 0, 0};
Point(2) = {0, -R_out, 0};
Point(3) = {R_out, 0, 0};
Point(4) = {0, R_out, 0};
Point(5) = {0, -R_in, 0};
Point(6) = {R_in, 0, 0};
Point(7) = {0, R_in, 0};
Circle(1) = {2, 1, 3};  // outer bottom quarter
Circle(2) = {3, 1, 4};  // outer top quarter
Circle(3) = {5, 1, 6};  // inner bottom quarter
Circle(4) = {6, 1, 7};  // inner top quarter
Line(5) = {5, 2};       // cut, bottom
Line(6) = {6, 3};       // radial line at y = 0
Line(7) = {7, 4};       // cut, top
Curve Loop(1) = {1, -6, -3, 5};
Plane Surface(1) = {1};
Curve Loop(2) = {2, -7, -4, 6};
Plane Surface(2) = {2};
Transfinite Curve {1, 2, 3, 4} = n_q + 1;
Transfinite Curve {5, 6, 7} = n_t + 1;
Transfinite Surface {1} = {2, 3, 6, 5} Alternate;
Transfinite Surface {2} = {3, 4, 7, 6} Alternate;

// Extrude returns the end face, the volume, then the side faces in the order
// of the section's boundary curves (loop 1: 1, 6, 3, 5; loop 2: 2, 7, 4, 6)
low[] = Extrude {0, 0, Lz} { Surface{1}; Layers{n_z}; };
high[] = Extrude {0, 0, Lz} { Surface{2}; Layers{n_z}; };

Physical Volume("tube", 1) = {low[1], high[1]};
Physical Surface("outer_bottom", 1) = {low[2]};
Physical Surface("outer_top", 2) = {high[2]};
Physical Surface("inner_bottom", 3) = {low[4]};
Physical Surface("inner_top", 5) = {high[4]};
Physical Surface("cut", 4) = {low[5], high[3]};
Physical Surface("front", 6) = {1, 2};
Physical Surface("back", 7) = {low[0], high[0]};
