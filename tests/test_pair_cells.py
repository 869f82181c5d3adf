"""Contact pairs on cells they cannot handle are refused before the work, naming the fix."""

from __future__ import annotations

import pytest

from fenics_contact.scene.build import build_problem
from fenics_contact.scene.schema import SceneError, load_scene

#: Two hexahedral blocks stacked, meshed apart (2 x 2 under 1 x 1 facets).
TOWER_GEO = """
SetFactory("OpenCASCADE");
Box(1) = {0,0,0, 1,1,0.5};
Box(2) = {0,0,0.5, 1,1,0.5};
Transfinite Curve{:} = 2;
Transfinite Surface "*"; Recombine Surface "*"; Transfinite Volume "*";
Physical Volume("lower", 1) = {1};
Physical Volume("upper", 2) = {2};
Physical Surface("lower_top", 2) = {6};
Physical Surface("upper_bottom", 3) = {11};
Physical Surface("floor_side", 1) = {5};
Physical Surface("upper_top", 4) = {12};
"""

TOWER = """
[scene]
name = "tower"
dimension = 3

[mesh]
file = "tower.geo"

[[body]]
name = "lower"
tag = "lower"
law = "linear"
E = 200.0
nu = 0.3

[[body]]
name = "upper"
tag = "upper"
law = "linear"
E = 200.0
nu = 0.3

[[pair]]
name = "joint"
striker = "upper_bottom"
target = "lower_top"
{discretisation}

[[dirichlet]]
tag = "floor_side"
value = [0.0, 0.0, 0.0]

[[dirichlet]]
tag = "upper_top"
value = [0.0, 0.0, -0.01]
"""


@pytest.mark.parametrize("discretisation", ["", 'discretisation = "mortar"'])
def test_a_3d_pair_on_hexahedra_is_a_scene_error_naming_the_fix(tmp_path, discretisation):
    """Before: "cannot reshape array of size 16 into shape (3)" (node-to-segment)."""
    (tmp_path / "tower.geo").write_text(TOWER_GEO)
    (tmp_path / "tower.toml").write_text(TOWER.format(discretisation=discretisation))
    with pytest.raises(SceneError) as err:
        build_problem(load_scene(tmp_path / "tower.toml"))
    said = str(err.value)
    assert said.startswith("tower.toml: Contact pair 'joint': the mesh's cells are hexahedron")
    assert "need triangle facets" in said and "with tetrahedra" in said
    assert "Recombine" in said and "reshape" not in said


def test_the_library_refuses_a_pair_on_hexahedra_by_name():
    from dolfinx import mesh

    from mpi4py import MPI

    from fenics_contact.model.pairs import check_pair_cells

    box = mesh.create_unit_cube(MPI.COMM_SELF, 1, 1, 1, mesh.CellType.hexahedron)
    with pytest.raises(ValueError, match="Contact pair 'p': the mesh's cells are hexahedron"):
        check_pair_cells(box, "p")
    check_pair_cells(mesh.create_unit_cube(MPI.COMM_SELF, 1, 1, 1), "p")  # tetrahedra
    check_pair_cells(mesh.create_unit_square(MPI.COMM_SELF, 1, 1, mesh.CellType.quadrilateral),
                     "p")  # 2D: segments
