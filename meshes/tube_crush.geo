// Half of a thin tube's section: the annulus R_in <= r <= R_out, x >= 0
// (x = 0 is a symmetry plane), between two plates that touch it at (0, -R_out)
// and (0, R_out). Structured triangles: n_t layers through the wall, n_q
// divisions along each quarter, diagonals alternating (stiffens less in
// bending than one diagonal direction: 11 % against 17 % at n_t = 4 vs 8).
//
// Physical groups:
//   Surface "tube" = 1                                                   (cell tags)
//   Curve "outer_bottom" = 1, "outer_top" = 2 (the outer quarters),
//   "inner_bottom" = 3, "inner_top" = 5 (the inner quarters), "cut" = 4 (the
//   wall at x = 0)                                                       (facet tags)

DefineConstant[
  R_out = {1.0, Name "Parameters/outer radius"},
  t = {0.1, Name "Parameters/wall thickness"},
  n_t = {3, Name "Parameters/n_t"},
  n_q = {40, Name "Parameters/n_q"}
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

Physical Surface("tube", 1) = {1, 2};
Physical Curve("outer_bottom", 1) = {1};
Physical Curve("outer_top", 2) = {2};
Physical Curve("inner_bottom", 3) = {3};
Physical Curve("inner_top", 5) = {4};
Physical Curve("cut", 4) = {5, 7};
