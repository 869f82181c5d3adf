"""Scene files: every kind of mistake fails fast with a message naming the key and the fix."""

import re
from pathlib import Path

import pytest

from fenics_contact.cli import main
from fenics_contact.scene.schema import SceneError, load_scene

SCENES = Path(__file__).parent.parent / "scenes"
EX2 = (SCENES / "paper_ex2.toml").read_text()


def write(tmp_path, text, name="scene.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def edited(old, new, text=EX2):
    assert old in text, old
    return text.replace(old, new, 1)


# (text to replace in paper_ex2.toml, replacement, expected message)
MISTAKES = [
    ('law = "svk"', 'law = "svk"\nYoung = 3.0', r"unknown key 'Young'.*\[material\]"),
    ("r = 100.0", "rr = 100.0", r"unknown key 'rr'.*Did you mean 'r'\?"),
    ("r = 100.0", "r = 0.0", r"\[contact\] r = 0.0: must be finite and > 0"),
    ("r = 100.0", "r = -5", r"\[contact\] r = -5: must be finite and > 0"),
    ("nu = 0.3", "nu = 0.5", r"\[material\] nu = 0.5: must be < 0.5.*0.4999"),
    ("E = 210.0", "E = -1.0", r"\[material\] E = -1.0: must be finite and > 0"),
    ("dimension = 2", "dimension = 3", r"generator.*2D mesh but \[scene\] dimension = 3"),
    ("dimension = 2", "dimension = 4", r"dimension = 4: use 2 \(plane strain\) or 3"),
    ("value = [0.0, -0.8]", "value = [0.0, -0.8, 0.0]", r"value.*list of 2 numbers"),
    ('method = "gnrm"', 'method = "newton"', r"method = 'newton': choose one of"),
    ('law = "svk"', 'law = "rubber"', r"law = 'rubber': choose one of"),
    (
        'law = "svk"', 'law = "svk"\nkinematics = "small"',
        r"kinematics.*small strain is law = 'linear'",
    ),
    ("steps = 10", "steps = 0", r"steps = 0: must be an integer >= 1"),
    (
        'generator = "rectangle"', 'file = "x.msh"\ngenerator = "rectangle"',
        r"exactly one of 'file'",
    ),
    ("[obstacle]", "[obstacles]", r"unknown key 'obstacles'.*Did you mean 'obstacle'\?"),
    ('tag = "bottom"', 'detect = true\ntag = "bottom"', r"either 'tag'.*or 'detect = true'"),
    ("[solver]", "[contact\n[solver]", r"not valid TOML"),
]


@pytest.mark.parametrize(("old", "new", "message"), MISTAKES)
def test_bad_scene_is_rejected_with_key_value_and_fix(tmp_path, old, new, message):
    with pytest.raises(SceneError, match=message):
        load_scene(write(tmp_path, edited(old, new)))


def test_missing_mesh_file_is_named(tmp_path):
    text = edited('generator = "rectangle"   # tags: left 1, right 2, bottom 3, top 4',
                  'file = "meshes/no_such_mesh.msh"')
    text = re.sub(r"origin = .*\nsize = .*\ncells = .*\n", "", text)
    with pytest.raises(SceneError, match=r"\[mesh\] file.*no such mesh file"):
        load_scene(write(tmp_path, text))


def test_missing_scene_file():
    with pytest.raises(SceneError, match="does not exist"):
        load_scene("no/such/scene.toml")


def test_missing_tag_fails_before_any_form_is_compiled(tmp_path, capsys):
    path = write(tmp_path, edited('tag = "bottom"', 'tag = "underside"'))
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "[contact] tag = 'underside' is not a facet tag" in err
    assert "bottom = 3" in err  # the available names are listed
    assert not out.exists()


def test_wrong_dimension_of_a_gmsh_mesh_is_reported(tmp_path):
    from fenics_contact.scene.build import build_problem

    text = (SCENES / "hertz_cylinder.toml").read_text()
    text = text.replace("dimension = 2", "dimension = 3").replace(
        "value = [0.0, -0.01]", "value = [0.0, -0.01, 0.0]"
    ).replace("normal = [0.0, 1.0]", "normal = [0.0, 1.0, 0.0]").replace(
        "point = [0.0, 0.0]", "point = [0.0, 0.0, 0.0]"
    ).replace('file = "../meshes/', f'file = "{SCENES.parent}/meshes/')
    scene = load_scene(write(tmp_path, text))
    with pytest.raises(SceneError, match=r"dimension = 3.*no 3D physical group"):
        build_problem(scene)


def _with_geo(tmp_path: Path, name: str, old: str, new: str) -> Path:
    """The shipped scene ``name`` on a copy of its .geo with ``old`` replaced by ``new``."""
    shipped = Path(__file__).parents[1] / "scenes" / f"{name}.toml"
    geo = (shipped.parents[1] / "meshes" / f"{name}.geo").read_text()
    assert old in geo
    (tmp_path / f"{name}.geo").write_text(geo.replace(old, new))
    scene_file = tmp_path / f"{name}.toml"
    scene_file.write_text(shipped.read_text().replace(f'"../meshes/{name}.geo"',
                                                      f'"{tmp_path}/{name}.geo"'))
    return scene_file


def test_shipped_scenes_are_valid():
    names = set()
    for path in sorted(SCENES.glob("*.toml")):
        scene = load_scene(path)
        names.add(scene.name)
    assert {"paper-ex1", "paper-ex2", "hertz-cylinder", "block-3d"} <= names


def test_geo_parameters_reach_the_mesh(tmp_path):
    """[mesh] parameters override the .geo file's DefineConstant defaults."""
    from fenics_contact.scene.build import build_mesh
    from fenics_contact.scene.schema import load_scene

    shipped = Path(__file__).parents[1] / "scenes" / "hertz_cylinder.toml"
    text = shipped.read_text().replace('"../meshes/', f'"{shipped.parents[1]}/meshes/')
    counts = {}
    for h in (0.004, 0.008):
        scene_file = tmp_path / f"h{h}.toml"
        scene_file.write_text(text.replace("h_contact = 0.004", f"h_contact = {h}"))
        domain = build_mesh(load_scene(scene_file)).domain
        counts[h] = domain.comm.allreduce(domain.topology.index_map(0).size_local)
    assert counts[0.008] < 0.6 * counts[0.004]


def test_unknown_geo_parameter_is_named(tmp_path):
    from fenics_contact.scene.build import build_mesh
    from fenics_contact.scene.schema import SceneError, load_scene

    shipped = Path(__file__).parents[1] / "scenes" / "hertz_cylinder.toml"
    text = shipped.read_text().replace('"../meshes/', f'"{shipped.parents[1]}/meshes/')
    scene_file = tmp_path / "bad.toml"
    scene_file.write_text(text.replace("h_contact = 0.004", "h_contct = 0.004"))
    with pytest.raises(SceneError, match=r"no parameter 'h_contct'.*h_contact"):
        build_mesh(load_scene(scene_file))


def test_a_geo_variable_of_another_parameter_name_is_pointed_to_that_name(tmp_path):
    """R = {1.0, Name "Parameters/radius"}: the scene sets radius, and is told so for R."""
    from fenics_contact.scene.build import build_mesh
    from fenics_contact.scene.schema import SceneError, load_scene

    shipped = Path(__file__).parents[1] / "scenes" / "hertz_cylinder.toml"
    text = shipped.read_text().replace('"../meshes/', f'"{shipped.parents[1]}/meshes/')
    scene_file = tmp_path / "bad.toml"
    scene_file.write_text(text.replace("h_contact = 0.004", "h_contact = 0.004, R = 1.0"))
    with pytest.raises(SceneError, match=r"'R' is the \.geo variable of the parameter "
                                         r"'radius': set radius = "):
        build_mesh(load_scene(scene_file))


@pytest.mark.parametrize(("parameters", "expected"), [
    ('R_out = 1.0, t = 0.25, n_t = 2', [
        "tube_crush.geo declares no parameter 'R_out', 't'; ",
        "'R_out' is the .geo variable of the parameter 'outer radius': set "
        '"outer radius" = 1.0; ',
        "'t' is the .geo variable of the parameter 'wall thickness': set "
        '"wall thickness" = 0.25 ',
        '(it declares: n_q, n_t, "outer radius", "wall thickness"; a name with a space is a '
        'quoted key in TOML, as written here: parameters = { "outer radius" = ... }).']),
    ("thickness = 0.25", [
        "tube_crush.geo declares no parameter 'thickness'; it declares: n_q, n_t, "
        '"outer radius", "wall thickness"; a name with a space is a quoted key in TOML']),
])
def test_a_geo_variable_of_a_parameter_named_with_a_space_is_pointed_to_it(
        tmp_path, parameters, expected):
    """t = {0.1, Name "Parameters/wall thickness"}: the variable named, the key quoted."""
    from mpi4py import MPI

    from fenics_contact.scene.build import build_mesh

    shipped = SCENES / "tube_crush.toml"
    text = shipped.read_text().replace('"../meshes/', f'"{shipped.parents[1]}/meshes/')
    scene_file = tmp_path / "tube.toml"
    scene_file.write_text(text.replace("n_t = 4, n_q = 54", parameters))
    with pytest.raises(SceneError) as raised:
        build_mesh(load_scene(scene_file), MPI.COMM_SELF)
    assert "\n" not in str(raised.value)
    for phrase in expected:
        assert phrase in str(raised.value), str(raised.value)


def test_geo_parameter_in_the_plain_form_is_named_with_the_form_to_use(tmp_path, capsys):
    """DefineConstant[h = 0.1] cannot be set from a scene: the message says how to declare it."""
    from fenics_contact.cli import main

    shipped = Path(__file__).parents[1] / "scenes" / "hertz_cylinder.toml"
    geo = (shipped.parents[1] / "meshes" / "hertz_cylinder.geo").read_text()
    plain = re.sub(r"(\w+) = \{([^,]+), Name \"Parameters/\w+\"\}", r"\1 = \2", geo)
    assert plain != geo and "Parameters/" not in plain
    (tmp_path / "plain.geo").write_text(plain)
    scene_file = tmp_path / "plain.toml"
    scene_file.write_text(shipped.read_text().replace('"../meshes/hertz_cylinder.geo"',
                                                      f'"{tmp_path}/plain.geo"'))
    assert main(["run", str(scene_file), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "gmsh cannot read" not in err
    form = r'DefineConstant\[h_contact = \{value, Name "Parameters/h_contact"\}\]'
    assert re.search(r"plain.geo declares no parameter 'h_contact'.*it declares: none.*" + form,
                     err), err


def test_a_geo_parameter_under_another_onelab_path_is_named(tmp_path):
    """h = {0.1, Name "P/h"}: gmsh reads it, a scene cannot set it; the message says why."""
    from fenics_contact.scene.build import build_mesh
    from fenics_contact.scene.schema import SceneError, load_scene

    scene_file = _with_geo(tmp_path, "hertz_cylinder", 'Name "Parameters/', 'Name "P/')
    with pytest.raises(SceneError, match=r"'h_contact' is declared with Name 'P/h_contact'; "
                       r"only names under \"Parameters/\" can be set from a scene: Name "
                       r"\"Parameters/h_contact\""):
        build_mesh(load_scene(scene_file))


def test_dirichlet_path_drives_a_one_body_scene(tmp_path):
    """A [[dirichlet]] path is followed knot by knot, not ramped to its end value."""
    import numpy as np
    from dolfinx import fem

    from fenics_contact.scene.build import build_problem

    text = (SCENES / "hertz_cylinder.toml").read_text().replace(
        "value = [0.0, -0.01]", "path = [[0.0, 0.0, 0.0], [0.5, 0.002, -0.01], [1.0, 0.0, -0.01]]"
    )
    scene = load_scene(write(tmp_path, text.replace('"../meshes/', f'"{SCENES.parent}/meshes/')))
    problem = build_problem(scene)
    for t, expected in ((0.25, (0.001, -0.005)), (0.5, (0.002, -0.01)), (0.75, (0.001, -0.01))):
        problem.set_load(t)
        u = fem.Function(problem.V)
        u.x.array[:] = np.nan
        for bc in problem.bcs:
            bc.set(u.x.array)
        values = u.x.array.reshape(-1, 2)
        for i in range(2):
            prescribed = values[~np.isnan(values[:, i]), i]
            assert prescribed.size > 0
            assert np.allclose(prescribed, expected[i], atol=1e-15), (t, i)


def test_overlapping_physical_groups_are_refused_before_meshing(tmp_path):
    """A curve in two physical groups would keep one tag only: named, with the fix."""
    from fenics_contact.scene.build import build_mesh
    from fenics_contact.scene.schema import SceneError, load_scene

    scene_file = _with_geo(tmp_path, "bridge", 'Physical Curve("bridge_top", 9) = {26};',
                           'Physical Curve("bridge_top", 9) = {26};\n'
                           'Physical Curve("bridge_ends", 10) = {25, 26, 27};')
    with pytest.raises(SceneError, match=r"bridge.geo: Curve 26 of the mesh file is in two "
                                         r"physical groups, 'bridge_top' and 'bridge_ends'.*"
                                         r"Make the groups disjoint"):
        build_mesh(load_scene(scene_file))


OPEN_LOOP_GEO = """Geometry.AutoCoherence = 0;
Point(1) = {0, 0, 0, 0.1}; Point(2) = {1, 0, 0, 0.1}; Point(3) = {1, 1, 0, 0.1};
Point(4) = {0, 1, 0, 0.1}; Point(5) = {0, 0, 0, 0.1};  // a second point where the first is
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Physical Surface("block", 1) = {1}; Physical Curve("bottom", 1) = {1};
Physical Curve("top", 2) = {3};
"""


def test_a_geometry_gmsh_cannot_mesh_is_named_without_a_traceback(tmp_path, capsys):
    """A loop that does not close (two points at one place) reads, but does not mesh."""
    from fenics_contact.cli import main

    (tmp_path / "open.geo").write_text(OPEN_LOOP_GEO)
    (tmp_path / "open.toml").write_text(
        '[scene]\nname = "open"\ndimension = 2\n[mesh]\nfile = "open.geo"\n[material]\n'
        'law = "linear"\nE = 100.0\nnu = 0.3\n[[dirichlet]]\ntag = "top"\n'
        'value = [0.0, -0.01]\n[obstacle]\ntype = "plane"\npoint = [0.0, 0.0]\n'
        'normal = [0.0, 1.0]\n[contact]\ntag = "bottom"\n')
    assert main(["run", str(tmp_path / "open.toml"), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert re.search(r"open.toml: \[mesh\] file = '.*open.geo': gmsh could not mesh it \(The "
                     r"1D mesh seems not to be forming a closed loop", err), err


EXTRUDED_APART_GEO = """Geometry.AutoCoherence = 0;  // two boxes kept apart, extruded
Point(1) = {0, 0, 0}; Point(2) = {1, 0, 0}; Point(3) = {1, 1, 0}; Point(4) = {0, 1, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Transfinite Curve {1, 2, 3, 4} = 3; Transfinite Surface {1}; Recombine Surface {1};
b[] = Extrude {0, 0, 0.5} { Surface{1}; Layers{2}; Recombine; };
Point(101) = {0, 0, 0.5}; Point(102) = {0.5, 0, 0.5}; Point(103) = {0.5, 0.5, 0.5};
Point(104) = {0, 0.5, 0.5};
Line(101) = {101, 102}; Line(102) = {102, 103}; Line(103) = {103, 104}; Line(104) = {104, 101};
Curve Loop(101) = {101, 102, 103, 104}; Plane Surface(101) = {101};
Transfinite Curve {101, 102, 103, 104} = 3; Transfinite Surface {101}; Recombine Surface {101};
a[] = Extrude {0, 0, 0.5} { Surface{101}; Layers{2}; Recombine; };
Physical Volume("lower", 1) = {b[1]}; Physical Volume("upper", 2) = {a[1]};
Physical Surface("bottom", 1) = {1}; Physical Surface("lower_top", 2) = {b[0]};
Physical Surface("upper_bottom", 3) = {101}; Physical Surface("upper_top", 4) = {a[0]};
Physical Surface("sym", 5) = {b[2], a[2]};
"""


def test_a_facet_group_off_the_cells_is_named_not_an_mpi_abort(tmp_path):
    """Extrude under AutoCoherence = 0: the side faces get nodes of their own.

    DOLFINx, handed such a tagged face, aborted the process with "Invalid
    rank has value 1" (a serial run, exit 6, no word about the mesh).
    """
    from mpi4py import MPI

    from fenics_contact.scene.build import build_mesh

    (tmp_path / "apart.geo").write_text(EXTRUDED_APART_GEO)
    (tmp_path / "apart.toml").write_text(
        '[scene]\nname = "apart"\ndimension = 3\n[mesh]\nfile = "apart.geo"\n'
        '[[body]]\nname = "lower"\ntag = "lower"\nlaw = "linear"\nE = 100.0\nnu = 0.3\n'
        '[[body]]\nname = "upper"\ntag = "upper"\nlaw = "linear"\nE = 100.0\nnu = 0.3\n'
        '[[pair]]\nstriker = "upper_bottom"\ntarget = "lower_top"\n'
        '[[dirichlet]]\ntag = "bottom"\nvalue = [0.0, 0.0, 0.0]\n'
        '[[dirichlet]]\ntag = "upper_top"\nvalue = [0.0, 0.0, -0.01]\n'
        '[[dirichlet]]\ntag = "sym"\nvalue = ["free", 0.0, "free"]\n')
    scene = load_scene(tmp_path / "apart.toml")
    with pytest.raises(SceneError, match=r"the physical group 'sym' holds Surface \d+, whose "
                       r"mesh has \d+ nodes that no 3D cell uses.*OpenCASCADE"):
        build_mesh(scene, MPI.COMM_SELF)


def test_a_msh_file_whose_nodes_are_numbered_with_gaps_runs(tmp_path):
    """gmsh numbers a file's nodes as it pleases (1 ... N with gaps after edits): renumbered."""
    import gmsh

    from fenics_contact import run_scene
    from fenics_contact.scene.schema import load_scene

    shipped = Path(__file__).parents[1] / "scenes" / "block_on_block.toml"
    geo = shipped.parents[1] / "meshes" / "block_on_block.geo"
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(str(geo))
        gmsh.model.mesh.generate(2)
        tags, _, _ = gmsh.model.mesh.getNodes()
        gmsh.model.mesh.renumberNodes(tags, 3 * tags + 7)  # gaps
        gmsh.option.setNumber("Mesh.SaveAll", 0)
        gmsh.write(str(tmp_path / "gaps.msh"))
    finally:
        gmsh.finalize()
    text = shipped.read_text().replace('file = "../meshes/block_on_block.geo"',
                                       f'file = "{tmp_path}/gaps.msh"')
    text = "\n".join(line for line in text.splitlines() if not line.startswith("parameters"))
    (tmp_path / "gaps.toml").write_text(text)
    outcome = run_scene(load_scene(tmp_path / "gaps.toml"), tmp_path / "run", pictures=False)
    assert outcome.path.converged
    assert outcome.problem.contact_state().contact_force == pytest.approx(
        -PATCH_PRESSURE, rel=1e-9)


PATCH_PRESSURE = -200.0 / (1 - 0.3**2) * 0.01
