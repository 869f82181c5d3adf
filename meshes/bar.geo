// The Example 2 analog bar: [-3, 3] x [0, 1], 6 x 2 bilinear quadrilaterals
// (12 elements, 7 nodes on the lower face), as in scenes/paper_ex2.toml.
//
// Physical groups:
//   Physical Surface "body"   = 1   the bar (cell tags)
//   Physical Curve   "left"   = 1   x = -3
//   Physical Curve   "right"  = 2   x = 3
//   Physical Curve   "bottom" = 3   y = 0 (candidate contact surface)
//   Physical Curve   "top"    = 4   y = 1, outer thirds
//   Physical Curve   "punch"  = 5   y = 1, |x| <= 1 (driven down)
//
// Mesh with: fenics-contact mesh meshes/bar.geo  (or gmsh -2 meshes/bar.geo)
DefineConstant[
  L = {6.0, Name "Parameters/length"},
  H = {1.0, Name "Parameters/height"},
  nx = {6, Name "Parameters/nx"},
  ny = {2, Name "Parameters/ny"}
];

Point(1) = {-L/2, 0, 0};
Point(2) = {L/2, 0, 0};
Point(3) = {L/2, H, 0};
Point(4) = {L/6, H, 0};
Point(5) = {-L/6, H, 0};
Point(6) = {-L/2, H, 0};

Line(1) = {1, 2};   // bottom
Line(2) = {2, 3};   // right
Line(3) = {3, 4};   // top, right third
Line(4) = {4, 5};   // top, middle third (punch)
Line(5) = {5, 6};   // top, left third
Line(6) = {6, 1};   // left

Curve Loop(1) = {1, 2, 3, 4, 5, 6};
Plane Surface(1) = {1};
Transfinite Curve{1} = nx + 1;
Transfinite Curve{3, 4, 5} = nx / 3 + 1;
Transfinite Curve{2, 6} = ny + 1;
Transfinite Surface{1} = {1, 2, 3, 6};
Recombine Surface{1};

Physical Surface("body", 1) = {1};
Physical Curve("left", 1) = {6};
Physical Curve("right", 2) = {2};
Physical Curve("bottom", 3) = {1};
Physical Curve("top", 4) = {3, 5};
Physical Curve("punch", 5) = {4};
