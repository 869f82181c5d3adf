"""A pin pushed sideways in a round hole: a convex striker in a concave target.

Node-to-segment keeps a node on its facet while it passes the facet's end by
up to 0.05 of it (the hysteresis that stops flips at convex vertices). At a
concave vertex of kink theta the node then lies up to 0.05 sin(theta) facet
sizes inside the next facet: here 1.4e-3 h, which the acceptance test of
1e-3 h refused (the last step of a user's pin failed after 140 Newton
iterations), while automatic pairing accepted it and reported zero. Now the
declared and the automatic pair accept the same states (``surface_tol`` =
1e-2 h) and report the same depth, measured by closest point.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from mpi4py import MPI

from fenics_contact import load_scene, run_scene

GEO = """// A square plate with a round hole and a pin (a ring) in it, clearance Rh - Rp.
SetFactory("OpenCASCADE");
DefineConstant[
  half = {2.5, Name "Parameters/half"},
  Rh = {1.0, Name "Parameters/Rh"},
  Rp = {0.98, Name "Parameters/Rp"},
  bore = {0.3, Name "Parameters/bore"},
  h = {0.02, Name "Parameters/h"},
  h_far = {0.3, Name "Parameters/h_far"}
];
Rectangle(1) = {-half, -half, 0, 2 * half, 2 * half};
Disk(2) = {0, 0, 0, Rh};
plate() = BooleanDifference{ Surface{1}; Delete; }{ Surface{2}; Delete; };
Disk(3) = {0, 0, 0, Rp};
Disk(4) = {0, 0, 0, bore};
pin() = BooleanDifference{ Surface{3}; Delete; }{ Surface{4}; Delete; };
e = 1e-6;
hole() = Curve In BoundingBox{-Rh - e, -Rh - e, -e, Rh + e, Rh + e, e};
rim() = Curve In BoundingBox{-Rp - e, -Rp - e, -e, Rp + e, Rp + e, e};
hole() -= rim();
bores() = Curve In BoundingBox{-bore - e, -bore - e, -e, bore + e, bore + e, e};
rim() -= bores();
outer() = Curve In BoundingBox{-half - e, -half - e, -e, half + e, half + e, e};
outer() -= hole();
outer() -= rim();
outer() -= bores();
MeshSize{ PointsOf{ Surface{plate(), pin()}; } } = h_far;
MeshSize{ PointsOf{ Curve{hole(), rim()}; } } = h;
Mesh.MeshSizeFromCurvature = 2 * Pi * Rh / h;
Physical Surface("plate", 1) = {plate()};
Physical Surface("pin", 2) = {pin()};
Physical Curve("outer", 3) = {outer()};
Physical Curve("hole", 4) = {hole()};
Physical Curve("pin_surface", 5) = {rim()};
Physical Curve("bore", 6) = {bores()};
"""

SCENE = """[scene]
name = "pin-in-hole"
dimension = 2
[mesh]
file = "pin_in_hole.geo"
parameters = {{ h = 0.03 }}
[[body]]
name = "plate"
tag = "plate"
law = "linear"
E = 200.0
nu = 0.3
[[body]]
name = "pin"
tag = "pin"
law = "linear"
E = 200.0
nu = 0.3
{pairing}[[dirichlet]]
tag = "outer"
value = [0.0, 0.0]
[[dirichlet]]
tag = "bore"
value = [0.05, 0.0]
[solver]
method = "gnrm"
steps = 10
[output]
pictures = false
"""

DECLARED = ('[[pair]]\nstriker = "pin_surface"\ntarget = "hole"\n'
            'discretisation = "node-to-segment"\n')  # as the automatic pair
AUTOMATIC = "[pairing]\nautomatic = true\n"


def _run(tmp_path, pairing: str) -> dict:
    folder = tmp_path / ("declared" if pairing == DECLARED else "automatic")
    folder.mkdir()
    (folder / "pin_in_hole.geo").write_text(GEO)
    (folder / "scene.toml").write_text(SCENE.format(pairing=pairing))
    outcome = run_scene(load_scene(folder / "scene.toml"), folder / "out", comm=MPI.COMM_SELF,
                        pictures=False)
    assert outcome.path.status == "converged", outcome.path.steps[-1].message
    return json.loads((folder / "out" / "summary.json").read_text())


def test_declared_and_automatic_pin_in_hole_agree(tmp_path):
    declared, automatic = _run(tmp_path, DECLARED), _run(tmp_path, AUTOMATIC)
    h = 0.03
    deepest = max(s["max_penetration"] for s in declared["steps"])
    assert 1e-3 * h < deepest < 1e-2 * h  # the hysteresis at the hole's vertices
    for a, b in zip(declared["steps"], automatic["steps"], strict=True):
        # the same depth (before: refused in one, reported 0 in the other); the
        # hysteresis leaves the two searches states apart by 1e-3 of the force across
        assert a["max_penetration"] == pytest.approx(b["max_penetration"], rel=1e-2, abs=1e-12)
        push, other = np.asarray(a["reactions"]["bore"]), np.asarray(b["reactions"]["bore"])
        assert push[0] == pytest.approx(other[0], rel=1e-5, abs=1e-10)
        assert abs(push[1]) <= 1e-3 * abs(push[0]) + 1e-10  # symmetric about the x axis
        # the pin's push reaches the plate's edge through the contact alone
        np.testing.assert_allclose(push, -np.asarray(a["reactions"]["outer"]), rtol=1e-8,
                                   atol=1e-10)
    last = declared["steps"][-1]
    # the support pushes the pin +x; the contact force sums the pressures over the arc
    assert last["reactions"]["bore"][0] == pytest.approx(5.2626, rel=1e-3)
    assert last["contact_force"] == pytest.approx(5.9858, rel=1e-3)
