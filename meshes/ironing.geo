// Ironing: a half-disk indenter (centre (0, R), flat face y = R, touching the
// origin) above a block [-1, L - 1] x [-D, 0] (scenes/ironing.toml,
// scenes/ironing_friction.toml, benchmarks/cases.py: ironing).
//
// The arc is meshed at h_indenter at the tip and arc_grading * h_indenter at its
// ends (x = +-R). indenter = 0 meshes the block alone (a rigid indenter instead).
//
// Physical groups:
//   Surface "striker" = 1 (indenter), Surface "target" = 2 (block)    (cell tags)
//   Curve "top" = 2, "striker_arc" = 3, "target_face" = 4, "bottom" = 5  (facet tags)

DefineConstant[
  R = {0.5, Name "Parameters/radius"},
  L = {4.0, Name "Parameters/length"},
  D = {1.0, Name "Parameters/depth"},
  h_indenter = {0.04, Name "Parameters/h_indenter"},
  h_block = {0.06, Name "Parameters/h_block"},
  arc_grading = {4, Name "Parameters/arc_grading"},
  indenter = {1, Name "Parameters/indenter"}
];
Geometry.AutoCoherence = 0;  // keep the two bodies apart

If (indenter)
Point(1) = {0, R, 0, arc_grading * h_indenter}; Point(2) = {-R, R, 0, arc_grading * h_indenter};
Point(3) = {0, 0, 0, h_indenter}; Point(4) = {R, R, 0, arc_grading * h_indenter};
Circle(1) = {2, 1, 3}; Circle(2) = {3, 1, 4}; Line(3) = {4, 2};
Curve Loop(1) = {1, 2, 3}; Plane Surface(1) = {1};
EndIf
Point(11) = {-1, -D, 0, 4 * h_block}; Point(12) = {L - 1, -D, 0, 4 * h_block};
Point(13) = {L - 1, 0, 0, h_block}; Point(14) = {-1, 0, 0, h_block};
Line(11) = {11, 12}; Line(12) = {12, 13}; Line(13) = {13, 14}; Line(14) = {14, 11};
Curve Loop(2) = {11, 12, 13, 14}; Plane Surface(2) = {2};

If (indenter)
  Physical Surface("striker", 1) = {1};
  Physical Curve("top", 2) = {3};
  Physical Curve("striker_arc", 3) = {1, 2};
EndIf
Physical Surface("target", 2) = {2};
Physical Curve("target_face", 4) = {13};
Physical Curve("bottom", 5) = {11};
Mesh.MeshSizeFromCurvature = 0;
Mesh.Algorithm = 6;
