// A ring shrunk onto a disk, a quarter of each (plane strain, symmetry cuts x = 0, y = 0).
//
// Disk: r <= b + delta (the oversize delta is the interference).
// Ring: b <= r <= c.
// Meshed as before assembly: the disk's rim lies delta inside the ring. The
// two surfaces of the fit are divided into n_disk and n_ring arcs (set them
// apart for non-matching meshes); the bulk grows to h_far.
// Used by scenes/shrink_fit.toml.
//
// Physical groups:
//   Surface "disk" = 1, Surface "ring" = 2                     (cell tags)
//   Curve "disk_rim" = 1, "ring_bore" = 2, "cut_x" = 3 (x = 0), "cut_y" = 4 (y = 0)

DefineConstant[
  b = {1.0, Name "Parameters/b"},
  c = {2.0, Name "Parameters/c"},
  delta = {0.005, Name "Parameters/delta"},
  n_disk = {40, Name "Parameters/n_disk"},
  n_ring = {31, Name "Parameters/n_ring"},
  h_far = {0.15, Name "Parameters/h_far"}
];
Geometry.AutoCoherence = 0;  // the two bodies overlap and share nothing

a = b + delta;
Point(1) = {0, 0, 0};  Point(2) = {a, 0, 0};  Point(3) = {0, a, 0};
Line(1) = {1, 2};  Circle(2) = {2, 1, 3};  Line(3) = {3, 1};
Curve Loop(1) = {1, 2, 3};  Plane Surface(1) = {1};

Point(11) = {0, 0, 0};
Point(12) = {b, 0, 0};  Point(13) = {c, 0, 0};  Point(14) = {0, c, 0};  Point(15) = {0, b, 0};
Line(11) = {12, 13};  Circle(12) = {13, 11, 14};  Line(13) = {14, 15};  Circle(14) = {15, 11, 12};
Curve Loop(11) = {11, 12, 13, 14};  Plane Surface(11) = {11};

Transfinite Curve{2} = n_disk + 1;
Transfinite Curve{14} = n_ring + 1;
Mesh.MeshSizeMax = h_far;
Mesh.MeshSizeFromCurvature = 0;
Mesh.Algorithm = 6;

Physical Surface("disk", 1) = {1};
Physical Surface("ring", 2) = {11};
Physical Curve("disk_rim", 1) = {2};
Physical Curve("ring_bore", 2) = {14};
Physical Curve("cut_x", 3) = {3, 13};
Physical Curve("cut_y", 4) = {1, 11};
