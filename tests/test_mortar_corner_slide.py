"""A stiff short block slid over a soft long one, the soft block's face striking (mortar).

The short block's corner passes over striker nodes: a node whose support
loses its last facing segment while it still carries pressure took the open
gap h, and with lam + r h < 0 it stayed active on a gap with no derivative (a
zero Jacobian row). Every attempt's first linear solve failed at the same
slide position (a user's scene, with more steps and with ``auto`` alike).
Such a node now opens at once.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from mpi4py import MPI

from fenics_contact import load_scene, run_scene

GEO = """// A short block (upper) on a long one (lower), meshed apart: two bodies that touch.
SetFactory("OpenCASCADE");
DefineConstant[
  n_upper = {12, Name "Parameters/n_upper"},
  n_lower = {30, Name "Parameters/n_lower"}
];
Rectangle(1) = {0.0, 0.0, 0, 2.0, 0.5};
Rectangle(2) = {0.4, 0.5, 0, 0.6, 0.4};
e = 1e-6;
lower_top() = Curve In BoundingBox{-e, 0.5 - e, -e, 2.0 + e, 0.5 + e, e};
upper_bottom() = Curve In BoundingBox{0.4 - e, 0.5 - e, -e, 1.0 + e, 0.5 + e, e};
lower_top() -= upper_bottom();
upper_top() = Curve In BoundingBox{0.4 - e, 0.9 - e, -e, 1.0 + e, 0.9 + e, e};
lower_bottom() = Curve In BoundingBox{-e, -e, -e, 2.0 + e, e, e};
Transfinite Curve{lower_top(), lower_bottom()} = n_lower + 1;
Transfinite Curve{upper_bottom(), upper_top()} = n_upper + 1;
sides() = Curve In BoundingBox{-e, -e, -e, 2.0 + e, 0.9 + e, e};
sides() -= lower_top();
sides() -= upper_bottom();
sides() -= upper_top();
sides() -= lower_bottom();
Transfinite Curve{sides()} = 9;
Transfinite Surface{1, 2};
Physical Surface("upper", 1) = {2};
Physical Surface("lower", 2) = {1};
Physical Curve("top", 3) = {upper_top()};
Physical Curve("upper_face", 4) = {upper_bottom()};
Physical Curve("lower_face", 5) = {lower_top()};
Physical Curve("bottom", 6) = {lower_bottom()};
"""

SCENE = """[scene]
name = "stiff-block-slide"
dimension = 2
[mesh]
file = "blocks.geo"

[[body]]
name = "upper"
tag = "upper"
law = "linear"
E = 100000.0
nu = 0.3
[[body]]
name = "lower"
tag = "lower"
law = "linear"
E = 1000.0
nu = 0.3
[[pair]]
name = "p"
striker = "lower_face"
target = "upper_face"
r = 1.0
discretisation = "mortar"
[[dirichlet]]
tag = "bottom"
value = [0.0, 0.0]
[[dirichlet]]
tag = "top"
path = [[0.0, 0.0, 0.0], [0.3, 0.0, -0.01], [1.0, 0.3, -0.01]]
[solver]
method = "gnrm"
steps = 20
[output]
pictures = false
"""


def test_a_stiff_corner_slides_over_a_soft_mortar_striker(tmp_path):
    (tmp_path / "blocks.geo").write_text(GEO)
    (tmp_path / "scene.toml").write_text(SCENE)
    outcome = run_scene(load_scene(tmp_path / "scene.toml"), tmp_path / "out",
                        comm=MPI.COMM_SELF, pictures=False)
    assert outcome.path.status == "converged", outcome.path.steps[-1].message
    steps = json.loads((tmp_path / "out" / "summary.json").read_text())["steps"]
    assert len(steps) == 20 and max(s["cutbacks"] for s in steps) == 0
    for s in steps[1:]:  # the two supports balance at every step (frictionless pair)
        total = np.asarray(s["reaction_total"])
        assert np.abs(total).max() < 1e-8 * s["contact_force"]
    # pressed 0.01 then slid: the stiff block indents the soft one (E 1e5 on 1e3)
    assert steps[-1]["contact_force"] == pytest.approx(21.3377, rel=1e-3)
