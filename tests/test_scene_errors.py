"""Every raise site of scene validation (schema.py) and building (build.py) has a case here.

Each case is a small TOML scene (a valid base with one edit) and the words the
message must contain: the key, the bad value or the fix. Building cases use a
4 x 2 generated mesh or a tiny gmsh file, and fail before any form is compiled.
"""

import math
import re
import warnings
from pathlib import Path

import numpy as np
import pytest

from fenics_contact.cli import main
from fenics_contact.scene.reader import _Reader
from fenics_contact.scene.schema import SceneError, load_scene

MESHES = Path(__file__).parent.parent / "meshes"


def base() -> dict:
    """A valid 2D scene: a block held on top, pressed onto a plane below."""
    return {
        "scene": {"name": "s", "dimension": 2},
        "mesh": {"generator": "rectangle", "size": [1.0, 0.5], "cells": [4, 2]},
        "material": {"law": "svk", "E": 210.0, "nu": 0.3},
        "dirichlet": [{"tag": "top", "value": [0.0, -0.05]}],
        "obstacle": {"type": "plane", "point": [0.0, 0.0], "normal": [0.0, 1.0]},
        "contact": {"tag": "bottom", "r": 1.0},
        "solver": {"steps": 1},
        "output": {"pictures": False},
    }


def _value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v + '"'
    if isinstance(v, float) and math.isinf(v):
        return "inf" if v > 0 else "-inf"
    if isinstance(v, float) and math.isnan(v):
        return "nan"
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {_value(x)}" for k, x in v.items()) + " }"
    return repr(v)


def to_toml(scene: dict) -> str:
    """A tiny TOML writer for these tests (tables, arrays of tables, scalars)."""
    top = [f"{k} = {_value(v)}" for k, v in scene.items() if not isinstance(v, dict | list)
           or (isinstance(v, list) and not all(isinstance(t, dict) for t in v))]
    lines = top[:]
    for name, table in scene.items():
        if isinstance(table, dict):
            lines.append(f"[{name}]")
            lines += [f"{k} = {_value(v)}" for k, v in table.items()]
        elif isinstance(table, list) and table and all(isinstance(t, dict) for t in table):
            for t in table:
                lines.append(f"[[{name}]]")
                lines += [f"{k} = {_value(v)}" for k, v in t.items()]
    return "\n".join(lines) + "\n"


def write(tmp_path: Path, scene: dict | str, name: str = "scene.toml") -> Path:
    path = tmp_path / name
    path.write_text(scene if isinstance(scene, str) else to_toml(scene))
    return path


def edit(**changes):
    """A scene editor: section=value replaces a table, "section.key"=value sets a key
    (None deletes it)."""

    def apply(scene: dict) -> dict:
        for where, value in changes.items():
            section, _, key = where.partition("__")
            if not key:
                if value is None:
                    scene.pop(section, None)
                else:
                    scene[section] = value
                continue
            table = scene[section][0] if isinstance(scene[section], list) else scene[section]
            if value is None:
                table.pop(key, None)
            else:
                table[key] = value
        return scene

    return apply


# (id, edit of the base scene, regex the SceneError message must match)
SCHEMA_CASES = [
    ("number-missing", edit(material__E=None), r"\[material\] E is missing: give a number"),
    ("number-type", edit(material__E="big"), r"\[material\] E = 'big': must be a number"),
    ("number-finite", edit(material__E=math.inf),
     r"\[material\] E = inf: holds a NaN or infinite number; give finite numbers"),
    ("path-nan", edit(dirichlet__path=[[0.0, 0.0, 0.0], [1.0, 0.0, math.nan]],
                      dirichlet__value=None),
     r"\[dirichlet 1\] path = .*nan\]\]: holds a NaN or infinite number at \[1\]\[2\]"),
    ("vector-inf", edit(obstacle__normal=[0.0, -math.inf]),
     r"\[obstacle\] normal = \[0.0, -inf\]: holds a NaN or infinite number at \[1\]"),
    ("parameter-nan", edit(mesh__parameters={"h": math.nan}),
     r"\[mesh\] parameters = \{'h': nan\}: holds a NaN"),
    ("steps-bound", edit(solver__steps=10**9),
     r"\[solver\] steps = 1000000000: must be at most 100000"),
    ("iterations-bound", edit(solver__max_iterations=10**9), r"must be at most 100000"),
    ("friction-key-alone", edit(contact__tangential_r_max=1.0),
     r"\[contact\] tangential_r_max = 1.0: is a friction setting, but there is no mu"),
    ("number-positive", edit(contact__r=0.0), r"\[contact\] r = 0.0: must be finite and > 0"),
    ("integer", edit(solver__steps=0), r"\[solver\] steps = 0: must be an integer >= 1"),
    ("integer-type", edit(solver__max_cutbacks=1.5), r"max_cutbacks = 1.5: must be an integer"),
    ("flag", edit(contact__relative="yes"), r"\[contact\] relative = 'yes': must be true or"),
    ("choice", edit(solver__method="newton"), r"method = 'newton': choose one of penalty"),
    ("vector-missing", edit(obstacle__point=None), r"\[obstacle\] point is missing: give 2"),
    ("vector-length", edit(obstacle__normal=[0.0, 1.0, 0.0]), r"normal.*list of 2 numbers"),
    ("vector-entry", edit(dirichlet__value=[0.0, "x"]), r'entries must be finite numbers or "'),
    ("tag-type", edit(contact__tag=1.5), r"\[contact\] tag = 1.5: give a facet tag number or a"),
    ("unknown-key", edit(solver__stpes=3), r"unknown key 'stpes'.*Did you mean 'steps'"),
    ("unknown-top", edit(solvers={"steps": 1}), r"unknown key 'solvers' at top level"),
    ("key-of-another-block", edit(contact__interference_until=1.0),
     r"unknown key 'interference_until' at \[contact\]\. It belongs to \[\[pair\]\]\."),
    ("table-missing", edit(material=None), r"the \[material\] table is missing; add it"),
    ("table-type", edit(obstacle=[1, 2]), r"\[obstacle\] must be a table or \[\[obstacle"),
    ("table-type-solver", edit(solver=[1, 2]), r"\[solver\] must be a table, not list"),
    ("array-type", edit(dirichlet={"tag": "top", "value": [0.0, 0.0]}), r"use \[\[dirichlet\]\]"),
    ("mesh-both", edit(mesh__file="x.msh"), r"\[mesh\] needs exactly one of 'file'"),
    ("mesh-none", edit(mesh={"size": [1.0, 1.0]}), r"\[mesh\] needs exactly one of 'file'"),
    ("parameters", edit(mesh__parameters={"h": "fine"}), r"parameters.*must be a table of numbers"),
    ("generator-dim", edit(mesh__generator="box"), r"makes a 3D mesh but \[scene\] dimension = 2"),
    ("size", edit(mesh__size=[1.0, 0.0]), r"\[mesh\] size.*every side length must be > 0"),
    ("cells", edit(mesh__cells=[4, 0]), r"\[mesh\] cells = \[4, 0\]: must be 2 positive integers"),
    ("bounds", edit(dirichlet__x=[1.0, 0.0]), r"x = \[1.0, 0.0\]: must be \[min, max\]"),
    ("normal-zero", edit(obstacle__normal=[0.0, 0.0]), r"normal.*must be a nonzero vector"),
    ("ball-radius", edit(obstacle={"type": "ball", "centre": [0.5, -1.0], "radius": -1.0}),
     r"\[obstacle\] radius = -1.0: must be > 0"),
    ("contact-both", edit(contact__detect=True), r"either 'tag'.*or 'detect = true'"),
    ("contact-neither", edit(contact__tag=None), r"either 'tag'.*not both or neither"),
    ("dimension", edit(scene__dimension=4), r"dimension = 4: use 2 \(plane strain\) or 3"),
    ("dimension-missing", edit(scene__dimension=None),
     r"\[scene\] needs .dimension.: 2 \(plane strain\) or 3"),
    ("kinematics", edit(material__kinematics="small"), r"kinematics.*small strain is law"),
    ("fields", edit(output__fields=["stress"]), r"\[output\] fields = \['stress'\]: choose from"),
    ("nu-high", edit(material__nu=0.5), r"nu = 0.5: must be < 0.5.*0.4999"),
    ("nu-low", edit(material__nu=-1.0), r"nu = -1.0: must be > -1"),
]


@pytest.mark.parametrize(("edit_scene", "message"), [c[1:] for c in SCHEMA_CASES],
                         ids=[c[0] for c in SCHEMA_CASES])
def test_schema_mistake_is_named(tmp_path, edit_scene, message):
    path = write(tmp_path, edit_scene(base()))
    with pytest.raises(SceneError, match=message) as info:
        load_scene(path)
    assert "\n" not in str(info.value)


def test_base_scene_is_valid(tmp_path):
    scene = load_scene(write(tmp_path, base()))
    assert (scene.dimension, scene.E, scene.solver.steps) == (2, 210.0, 1)


def test_number_below_bound_is_named():
    reader = _Reader(Path("s.toml"), "material", {"nu": 0.7})
    with pytest.raises(SceneError, match=r"\[material\] nu = 0.7: must be < 0.5"):
        reader.number("nu", below=0.5)


def test_scene_file_missing_directory_toml_and_binary(tmp_path):
    with pytest.raises(SceneError, match="does not exist; check the path"):
        load_scene(tmp_path / "nothing.toml")
    with pytest.raises(SceneError, match="is not a file"):
        load_scene(tmp_path)
    with pytest.raises(SceneError, match="not valid TOML"):
        load_scene(write(tmp_path, "[scene\nname = 1\n"))
    binary = tmp_path / "b.toml"
    binary.write_bytes(b"\xff\xfe\x00\x81")
    with pytest.raises(SceneError, match="not a text file"):
        load_scene(binary)


def test_unreadable_scene_file(tmp_path, monkeypatch):
    path = write(tmp_path, base())

    def refuse(self, *args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(Path, "read_text", refuse)
    with pytest.raises(SceneError, match=r"scene.toml cannot be read \(Permission denied\)"):
        load_scene(path)


# -- mesh files ----------------------------------------------------------------------
def _file_scene(tmp_path, name, content: bytes | None, **extra):
    if content is not None:
        (tmp_path / name).write_bytes(content)
    scene = base()
    scene["mesh"] = {"file": name, **extra}
    return write(tmp_path, scene)


@pytest.mark.parametrize(
    ("name", "content", "message"),
    [
        ("gone.msh", None, r"no such mesh file"),
        ("mesh.txt", b"x", r"must be a gmsh .geo or .msh file"),
        ("empty.msh", b"", r"empty.msh is empty; regenerate it"),
        ("blank.geo", b"  \n", r"blank.geo is empty"),
        ("fake.msh", b"solid ascii\nendsolid\n", r"no \$MeshFormat header"),
    ],
)
def test_mesh_file_mistake_is_named(tmp_path, name, content, message):
    with pytest.raises(SceneError, match=message):
        load_scene(_file_scene(tmp_path, name, content))


def test_mesh_file_that_is_a_folder(tmp_path):
    (tmp_path / "dir.msh").mkdir()
    with pytest.raises(SceneError, match=r"dir.msh is not a file"):
        load_scene(_file_scene(tmp_path, "dir.msh", None))


def test_unreadable_mesh_file(tmp_path, monkeypatch):
    path = _file_scene(tmp_path, "m.msh", b"$MeshFormat\n")

    real_open = Path.open

    def refuse(self, *args, **kwargs):
        if self.suffix == ".msh":
            raise PermissionError(13, "Permission denied")
        return real_open(self, *args, **kwargs)

    monkeypatch.setattr(Path, "open", refuse)
    with pytest.raises(SceneError, match=r"cannot read .*m.msh \(Permission denied\)"):
        load_scene(path)


CORRUPT_MSH = b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\ngarbage\n"


@pytest.mark.parametrize("how", ["main", "subprocess"])
def test_corrupt_mesh_exits_2_with_one_line(tmp_path, capsys, how):
    import subprocess
    import sys

    path = _file_scene(tmp_path, "bad.msh", CORRUPT_MSH)
    out = tmp_path / "out"
    if how == "main":
        code = main(["run", str(path), "--out", str(out), "--quiet"])
        err = capsys.readouterr().err.strip()
    else:
        done = subprocess.run(
            [sys.executable, "-m", "fenics_contact.cli", "run", str(path), "--out", str(out),
             "--quiet"], capture_output=True, text=True, timeout=120,
        )
        code, err = done.returncode, done.stderr.strip()
    assert code == 2
    assert len(err.splitlines()) == 1, err
    assert re.search(r"bad.msh.*gmsh cannot read it \(Could not read nodes\)", err)
    assert not out.exists()


def test_geo_with_a_syntax_error_exits_2(tmp_path, capsys):
    path = _file_scene(tmp_path, "broken.geo", b"Point(1) = {0, 0, 0;\nnot geo\n")
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert re.search(r"broken.geo.*gmsh cannot read it \(.*line 1: syntax error", err), err


# -- building (needs the mesh, still before any form) ----------------------------------
def _build(path):
    from fenics_contact.scene.build import build_problem

    return build_problem(load_scene(path))


def test_geo_without_body_of_scene_dimension(tmp_path):
    geo = tmp_path / "curves.geo"
    geo.write_text(
        'SetFactory("OpenCASCADE");\nRectangle(1) = {0, 0, 0, 1, 0.5};\n'
        "Physical Curve(3) = {1};\n"
    )
    scene = base()
    scene["mesh"] = {"file": "curves.geo"}
    with pytest.raises(SceneError, match=r"has no 2D physical group"):
        _build(write(tmp_path, scene))


def test_tag_mistake_found_before_meshing(tmp_path, monkeypatch):
    """The .geo names its groups: a wrong tag fails before gmsh generates a mesh."""
    import fenics_contact.scene.build as build

    def no_meshing(*args, **kwargs):
        raise AssertionError("the mesh was generated")

    monkeypatch.setattr(build, "mesh_on_rank", no_meshing)
    scene = base()
    scene["mesh"] = {"file": str(MESHES / "hertz_cylinder.geo")}
    scene["contact"]["tag"] = "underside"
    with pytest.raises(SceneError, match=r"\[contact\] tag = 'underside' is not a 1D physical "
                       r"group of hertz_cylinder.geo; available: .*top = 2.*contact = 3"):
        _build(write(tmp_path, scene))
    scene["contact"]["tag"] = "contact"
    scene["dirichlet"][0]["tag"] = 7
    with pytest.raises(SceneError, match=r"\[dirichlet 1\] tag = 7 is not a 1D physical"):
        _build(write(tmp_path, scene))


def test_mesh_without_boundary_groups(tmp_path):
    geo = tmp_path / "plain.geo"
    geo.write_text(
        'SetFactory("OpenCASCADE");\nRectangle(1) = {0, 0, 0, 1, 0.5};\n'
        "Physical Surface(1) = {1};\nMesh.MeshSizeMax = 0.25;\n"
    )
    scene = base()
    scene["mesh"] = {"file": "plain.geo"}
    scene["dirichlet"] = []
    scene["contact"] = {"detect": True, "margin": 0.1}
    with pytest.raises(SceneError, match=r"the mesh has no physical groups on its boundary"):
        _build(write(tmp_path, scene))


def test_generated_mesh_tag_mistake_lists_names(tmp_path):
    scene = base()
    scene["contact"]["tag"] = "underside"
    with pytest.raises(SceneError, match=r"\[contact\] tag = 'underside' is not a facet tag.*"
                       r"left = 1, right = 2, bottom = 3, top = 4"):
        _build(write(tmp_path, scene))


def test_mesh_dimension_disagreeing_with_scene(tmp_path, monkeypatch):
    from dolfinx import mesh

    from mpi4py import MPI

    import fenics_contact.scene.build as build

    def cube(scene, comm):
        domain = mesh.create_unit_cube(MPI.COMM_WORLD, 1, 1, 1)
        tags = mesh.meshtags(domain, 2, np.zeros(0, np.int32), np.zeros(0, np.int32))
        return build.BodyMesh(domain, tags, {})

    monkeypatch.setattr(build, "build_mesh", cube)
    with pytest.raises(SceneError, match=r"dimension = 2 but the mesh is 3D"):
        _build(write(tmp_path, base()))


def test_dirichlet_bounds_selecting_nothing(tmp_path):
    scene = base()
    scene["dirichlet"][0]["x"] = [5.0, 6.0]
    with pytest.raises(SceneError, match=r"\[\[dirichlet\]\] 1 selects no facet; widen"):
        _build(write(tmp_path, scene))


@pytest.mark.mpi
def test_two_supports_disagreeing_at_a_shared_node(tmp_path):
    """The top pushed down and the left side clamped share the top-left corner."""
    scene = base()
    scene["dirichlet"].append({"tag": "left", "value": [0.0, 0.0]})
    with pytest.raises(SceneError, match=re.escape(
            "hold u_y at the node [0.0, 0.5] with different values: 'top' gives -0.05 and "
            "'left' gives 0.0")):
        _build(write(tmp_path, scene))
    scene["dirichlet"][1]["value"] = [0.0, "free"]  # agree on x at the corner: accepted
    _build(write(tmp_path, scene))


@pytest.mark.mpi
@pytest.mark.parametrize(
    ("dirichlet", "free"),
    [
        ([], "translation in x; translation in y; rotation in the x-y plane about (0.5, 0.25)"),
        ([{"tag": "bottom", "value": ["free", 0.0]}], "translation in x"),
        ([{"tag": "top", "value": [0.0, "free"]}, {"tag": "bottom", "value": [0.0, "free"]}],
         "translation in y"),
    ],
    ids=["none", "roller", "two-rollers"],
)
def test_rigid_motions_left_free_are_named(tmp_path, dirichlet, free):
    scene = base()
    scene["dirichlet"] = dirichlet
    scene["traction"] = [{"tag": "top", "value": [0.0, -1.0]}] if not dirichlet else []
    if not dirichlet:
        scene.pop("dirichlet")
    with pytest.raises(SceneError, match=re.escape(f"free ({free}); contact does not hold")):
        _build(write(tmp_path, scene))


@pytest.mark.mpi
def test_free_rigid_motions_3d_and_pin():
    from dolfinx import mesh

    from mpi4py import MPI

    from fenics_contact.model.rigid import free_rigid_motions

    box = mesh.create_box(MPI.COMM_WORLD, [[0, 0, 0], [1, 1, 1]], [2, 2, 2])
    box.topology.create_connectivity(2, 3)
    base_facets = mesh.locate_entities_boundary(box, 2, lambda x: np.isclose(x[2], 0.0))
    assert free_rigid_motions(box, [(base_facets, (0.0, 0.0, 0.0))]) == []
    assert free_rigid_motions(box, [(base_facets, (None, None, 0.0))]) == [
        "translation in x", "translation in y", "rotation about the z axis"]
    # 2D: x and y held on the left side only near its lower end: all held
    square = mesh.create_unit_square(MPI.COMM_WORLD, 4, 4)
    left = mesh.locate_entities_boundary(square, 1, lambda x: np.isclose(x[0], 0.0))
    assert free_rigid_motions(square, [(left, (0.0, 0.0))]) == []
    # x held on the left side only: y translation free, rotation held
    assert free_rigid_motions(square, [(left, (0.0, None))]) == ["translation in y"]
    # y held on the left side only: rotation about a point of that side is free
    free = free_rigid_motions(square, [(left, (None, 0.0))])
    assert free == ["translation in x", "rotation in the x-y plane about (0, 0.5)"] or (
        len(free) == 2 and "translation in x" in free[0]), free


def test_initial_penetration_beyond_facet_size_warns(tmp_path):
    from fenics_contact.scene.build import SceneWarning

    scene = base()
    scene["obstacle"]["point"] = [0.0, 0.6]  # base at y = 0: 0.6 inside; h = 0.25
    scene["dirichlet"][0]["value"] = [0.0, 0.0]
    with pytest.warns(SceneWarning, match=r"starts 0.6 inside the obstacle, more than the "
                      r"contact facet size h = 0.25 \(2.4 h\)"):
        _build(write(tmp_path, scene))
    scene["obstacle"]["point"] = [0.0, 0.2]  # 0.2 < h: pushed out by the first step
    with pytest.warns(SceneWarning, match=r"starts 0.2 \(0.8 h\) inside the obstacle; the "
                      r"first load step pushes it out") as seen:
        _build(write(tmp_path, scene))
    assert not any("more than the contact facet size" in str(w.message) for w in seen)
    scene["obstacle"]["point"] = [0.0, 0.0]  # touching: no warning
    with warnings.catch_warnings():
        warnings.simplefilter("error", SceneWarning)
        _build(write(tmp_path, scene))


def test_a_run_that_fails_after_starting_inside_an_obstacle_says_so_first(tmp_path, capsys):
    scene = base()
    scene["obstacle"]["point"] = [0.0, 0.6]  # the clamped top itself is 0.1 inside
    scene["dirichlet"][0]["value"] = [0.0, 0.0]
    code = main(["run", str(write(tmp_path, scene)), "--out", str(tmp_path / "out"), "--quiet"])
    assert code == 1
    assert ("To try: first the start: the body starts 0.6 inside the obstacle (2.4 h, the "
            "warning at the start)") in capsys.readouterr().err
    import json

    kept = json.loads((tmp_path / "out" / "summary.json").read_text())["warnings"]
    assert any("starts 0.6 inside the obstacle" in w for w in kept)  # in summary.json too


@pytest.mark.parametrize("change, fix", [
    (edit(obstacle__normal=[0.0, -1.0]), r"normal = \[0.0, 1.0\]\?"),
    (edit(obstacle={"type": "ball", "centre": [0.5, -1.0], "radius": 1.0, "inside": True}),
     r"or inside = true should go"),
    (edit(contact__tag="top"), r"tag the face that meets it"),
], ids=["plane", "ball", "tag"])
def test_obstacle_no_candidate_facet_faces_is_refused(tmp_path, change, fix):
    """A plane normal given the wrong way round: the body sits inside the obstacle's side."""
    with pytest.raises(SceneError, match=r"\[\[obstacle\]\] 'obstacle': none of its candidate "
                       r"facets faces it .*nothing can touch it; .*" + fix):
        _build(write(tmp_path, change(base())))


# -- output folders -----------------------------------------------------------------------
def test_output_folder_that_cannot_be_created_exits_2(tmp_path, capsys):
    path = write(tmp_path, base())
    blocker = tmp_path / "file"
    blocker.write_text("x")
    for out, words in [(blocker / "out", "below the file"), (blocker, "an existing file")]:
        assert main(["run", str(path), "--out", str(out), "--quiet"]) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1, err
        assert f"cannot create output folder {out}: it is {words}" in err


def test_resume_of_a_file_names_the_resume_option(tmp_path, capsys):
    path = write(tmp_path, base())
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert main(["run", str(path), "--resume", str(blocker), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert f"cannot create output folder {blocker}: it is an existing file" in err
    assert err.endswith("choose another --resume."), err


@pytest.mark.mpi
def test_a_scene_error_is_printed_once_on_two_processes(tmp_path, capsys):
    from mpi4py import MPI

    folder = Path(MPI.COMM_WORLD.bcast(str(tmp_path), root=0))
    path = folder / "bad.toml"
    if MPI.COMM_WORLD.rank == 0:
        write(folder, edit(solver__stpes=3)(base()), name="bad.toml")
    MPI.COMM_WORLD.barrier()
    assert main(["run", str(path), "--out", str(folder / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    expected = 1 if MPI.COMM_WORLD.rank == 0 else 0
    assert len(err) == expected, err
    assert all("unknown key 'stpes'" in line for line in err)


@pytest.mark.mpi
def test_a_failed_load_step_is_printed_once_on_two_processes(tmp_path, capsys):
    from mpi4py import MPI

    folder = Path(MPI.COMM_WORLD.bcast(str(tmp_path), root=0))
    path = folder / "stiff.toml"
    if MPI.COMM_WORLD.rank == 0:  # one Newton iteration and no cut-back cannot converge
        write(folder, edit(solver__max_iterations=1, solver__max_cutbacks=0)(base()),
              name="stiff.toml")
    MPI.COMM_WORLD.barrier()
    assert main(["run", str(path), "--out", str(folder / "out"), "--quiet"]) == 1
    err = [line for line in capsys.readouterr().err.strip().splitlines()
           if "did not converge" in line]
    assert len(err) == (1 if MPI.COMM_WORLD.rank == 0 else 0), err
    assert all(line.startswith("fenics-contact: load step 1 of 1 did not converge")
               for line in err)


def test_output_folder_not_writable(tmp_path, monkeypatch):
    import tempfile

    from fenics_contact.output.folders import OutputFolderError, prepare_output_folder

    def refuse(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(tempfile, "mkdtemp", refuse)
    with pytest.raises(OutputFolderError, match=r"cannot write to output folder .*a/b "
                       r"\(.*: Permission denied\); choose a writable --out"):
        prepare_output_folder(tmp_path / "a" / "b")
    assert not (tmp_path / "a").exists()


# -- checks that need the mesh (scene/checks.py) ------------------------------------------
def test_3d_mesh_in_a_2d_scene_names_the_dimensions(tmp_path):
    """Not "tag 'zmax' is not a 1D physical group": the dimensions disagree."""
    scene = base()
    scene["mesh"] = {"file": str(MESHES / "block.geo")}
    scene["dirichlet"][0]["tag"] = "zmax"
    scene["contact"]["tag"] = "zmin"
    with pytest.raises(SceneError, match=r"\[scene\] dimension = 2, but block.geo is a 3D mesh "
                       r"\(it has 3D physical groups\); set dimension = 3"):
        _build(write(tmp_path, scene))


@pytest.mark.mpi
def test_degenerate_cell_is_named_with_its_place(tmp_path, monkeypatch):
    from dolfinx import mesh

    from mpi4py import MPI

    import fenics_contact.scene.build as build

    generated = build.build_mesh

    def collapsed(scene, comm):
        body = generated(scene, comm)
        x = body.domain.geometry.x
        # the vertex at (0.25, 0.25) moved onto (0.5, 0.25): its cells lose their area
        x[np.isclose(x[:, 0], 0.25) & np.isclose(x[:, 1], 0.25), 0] = 0.5
        return body

    monkeypatch.setattr(build, "build_mesh", collapsed)
    with pytest.raises(SceneError, match=r"the mesh has [1-9] degenerate cell\(s\) \(zero area\), "
                       r"e.g. near \(0\.[0-9]+, 0\.[0-9]+\).*Fix the mesh"):
        _build(write(tmp_path, base()))
    assert mesh is not None and MPI is not None


BLOCKS = (Path(__file__).parent.parent / "scenes"
          / "block_on_block_node_to_segment.toml").read_text()


def _blocks(tmp_path, text=BLOCKS, geo=None):
    """block_on_block.toml (two blocks, a pair) with the mesh path made absolute."""
    geo = geo or MESHES / "block_on_block.geo"
    path = tmp_path / "blocks.toml"
    path.write_text(text.replace('"../meshes/block_on_block.geo"', f'"{geo}"'))
    return path


@pytest.mark.parametrize("swap", [False, True], ids=["same", "swapped"])
def test_two_pairs_on_the_same_surfaces_are_refused(tmp_path, swap):
    second = ('[[pair]]\nname = "again"\nstriker = "target_face"\ntarget = "striker_face"\n'
              if swap else '[[pair]]\nname = "again"\nstriker = "striker_face"\n'
              'target = "target_face"\n')
    text = BLOCKS.replace("[[dirichlet]]", second + "\n[[dirichlet]]", 1)
    with pytest.raises(SceneError, match=r"\[\[pair\]\] 'again' joins the same .*as \[\[pair\]\] "
                       r"'pair1'.*constrained twice"):
        load_scene(_blocks(tmp_path, text))


def test_pair_on_one_body_is_refused(tmp_path):
    text = BLOCKS.replace('target = "target_face"', 'target = "top"')
    with pytest.raises(SceneError, match=r"\[\[pair\]\] striker = 'striker_face' and target = "
                       r"'top' both lie on body 'upper'; a pair joins two bodies"):
        _build(_blocks(tmp_path, text))


def test_pair_facets_inside_the_mesh_are_refused(tmp_path):
    """Bodies meshed with shared nodes: the interface is interior, no contact surface."""
    (tmp_path / "shared.geo").write_text(
        "Point(1) = {0, 0, 0}; Point(2) = {1, 0, 0}; Point(3) = {1, 0.5, 0};\n"
        "Point(4) = {0, 0.5, 0}; Point(5) = {1, 1, 0}; Point(6) = {0, 1, 0};\n"
        "Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};\n"
        "Line(5) = {3, 5}; Line(6) = {5, 6}; Line(7) = {6, 4};\n"
        "Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};\n"
        "Curve Loop(2) = {-3, 5, 6, 7}; Plane Surface(2) = {2};\n"
        "Mesh.MeshSizeMax = 0.25;\n"
        'Physical Surface("striker", 1) = {2}; Physical Surface("target", 2) = {1};\n'
        'Physical Curve("top", 2) = {6}; Physical Curve("striker_face", 3) = {3};\n'
        'Physical Curve("target_face", 4) = {2}; Physical Curve("bottom", 5) = {1};\n'
        'Physical Curve("symmetry", 6) = {4, 7};\n'
    )
    text = BLOCKS.replace("parameters = { n_upper = 8, n_lower = 11 }\n", "")
    with pytest.raises(SceneError, match=r"\[\[pair\]\] striker = 'striker_face': [0-9]+ of its "
                       r"facets are inside the mesh.*Mesh the bodies apart"):
        _build(_blocks(tmp_path, text, tmp_path / "shared.geo"))


@pytest.mark.mpi
def test_floating_body_of_a_pair_is_named(tmp_path):
    text = BLOCKS.replace('[[dirichlet]]\ntag = "bottom"\nvalue = ["free", 0.0]\n', "")
    with pytest.raises(SceneError, match=r"\[\[body\]\] 'lower' can move rigidly \(translation "
                       r"in y\): no \[\[dirichlet\]\] condition holds that motion"):
        _build(_blocks(tmp_path, text))


def _overlapping(tmp_path, depth: float) -> Path:
    """The blocks with the upper one ``depth`` lower: its face that far inside the lower one."""
    geo = (MESHES / "block_on_block.geo").read_text()
    upper = ("Point(5) = {x0, H, 0}; Point(6) = {x0 + Wu, H, 0}; Point(7) = {x0 + Wu, 2 * H, 0};\n"
             "Point(8) = {x0, 2 * H, 0};")
    assert upper in geo
    geo = geo.replace(upper, upper.replace("H, 0}", f"H - {depth}, 0}}"))
    (tmp_path / "overlap.geo").write_text(geo)
    return _blocks(tmp_path, BLOCKS, tmp_path / "overlap.geo")


@pytest.mark.mpi
def test_bodies_starting_deep_inside_each_other_are_refused(tmp_path):
    # h = 1/8 on the striker face: 0.2 is 1.6 h
    with pytest.raises(SceneError, match=r"\[\[pair\]\] '[^']+': the bodies '[^']+' and "
                       r"'[^']+' start 0.2 inside each other near "
                       r"\([0-9.]+, 0.3\), more than the striker facet size h = 0.125"):
        _build(_overlapping(tmp_path, 0.2))


def test_mortar_bodies_starting_deep_inside_each_other_are_refused(tmp_path):
    """The weighted gaps of a mortar pair measure the overlap (0.2 = 1.6 h)."""
    path = _overlapping(tmp_path, 0.2)
    text = path.read_text().replace('discretisation = "node-to-segment"',
                                    'discretisation = "mortar"')
    path.write_text(text)
    with pytest.raises(SceneError, match=r"\[\[pair\]\] '[^']+': the bodies '[^']+' and "
                       r"'[^']+' start 0.2 inside each other near "
                       r"\([0-9.]+, 0.3\), more than the striker facet size h = 0.125"):
        _build(path)


def test_mortar_bodies_overlapping_beyond_the_segment_search_are_refused(tmp_path):
    """0.3 = 2.4 h, past the reach 2 h = 0.25: no segment, the weighted gaps read open.

    The depth by closest point refuses it before any Newton iteration (the
    scene used to run 218 iterations and fail on the surface check).
    """
    path = _overlapping(tmp_path, 0.3)
    path.write_text(path.read_text().replace(
        'discretisation = "node-to-segment"', 'discretisation = "mortar"'))
    with pytest.raises(SceneError, match=r"the bodies 'upper' and 'lower' start 0.3 inside each "
                       r"other near \([0-9.]+, 0.2\), more than the striker facet size "
                       r"h = 0.125"):
        _build(path)


def test_3d_mortar_bodies_overlapping_beyond_the_segment_search_are_refused(tmp_path):
    """block_on_block_3d.geo, the upper block 0.4 down (3.9 h, past the reach 0.25)."""
    geo = (MESHES / "block_on_block_3d.geo").read_text()
    for old in ("Box(1) = {0, 0, H, W, W, H};", "2 * H - e, W + e, W + e, 2 * H + e}"):
        assert old in geo
    geo = geo.replace("Box(1) = {0, 0, H, W, W, H};", "Box(1) = {0, 0, H - 0.4, W, W, H};")
    geo = geo.replace("2 * H - e, W + e, W + e, 2 * H + e}",
                      "2 * H - 0.4 - e, W + e, W + e, 2 * H - 0.4 + e}")
    (tmp_path / "overlap3d.geo").write_text(geo)
    text = (MESHES.parent / "scenes" / "block_on_block_3d.toml").read_text()
    text = text.replace('"../meshes/block_on_block_3d.geo"', f'"{tmp_path / "overlap3d.geo"}"')
    text = text.replace("h_upper = 0.125, h_lower = 0.17", "h_upper = 0.1, h_lower = 0.1")
    with pytest.raises(SceneError, match=r"the bodies 'upper' and 'lower' start 0.4 inside each "
                       r"other near \(.*, 0.1\), more than the striker facet size h = 0.1"):
        _build(write(tmp_path, text, name="overlap3d.toml"))


def test_shallow_initial_overlap_is_reported_and_runs(tmp_path):
    from fenics_contact.scene.checks import SceneWarning

    with pytest.warns(SceneWarning, match=r"the bodies '[^']+' and '[^']+' start 0.01 "
                                            r"\(0.08 h\) inside each other"):
        _build(_overlapping(tmp_path, 0.01))


def test_a_run_that_finishes_no_step_does_not_check_its_start_as_an_answer(tmp_path):
    """Bodies that start inside each other, and a first step that fails (NUA, 3 iterations).

    The start is reported before the first step; the end-of-run checks
    describe an answer and there is none: before, the overlap of the start
    was named again as "a boundary node ... lies inside", with the advice
    to refine or retag, which does not apply.
    """
    from fenics_contact import run_scene
    from fenics_contact.scene.checks import SceneWarning

    path = _overlapping(tmp_path, 0.05)
    path.write_text(path.read_text().replace(
        'method = "gnrm"', 'method = "nua"\nmax_iterations = 3\nmax_cutbacks = 1'))
    with pytest.warns(SceneWarning, match="start 0.05 .* inside each other"):
        outcome = run_scene(load_scene(path), tmp_path / "run", pictures=False)
    assert not outcome.path.converged
    assert not any(s["status"] == "converged" for s in outcome.summary["steps"])
    assert len(outcome.summary["warnings"]) == 1
    assert "inside each other" in outcome.summary["warnings"][0]


@pytest.mark.parametrize("nu", [0.48, 0.49, 0.4999])
def test_near_incompressible_linear_elements_are_warned_about(tmp_path, nu):
    """From nu = 0.48 on P1 elements lock: built, with a warning naming the effect and the fix.

    (2D Hertz, a soft half-disk on a stiff block: peak +4 % at 0.48, +6 to +9 % at 0.49 with
    neighbouring nodes up to 30 % of the peak apart; within 2 % at 0.45.)
    """
    from fenics_contact.scene.checks import SceneWarning

    with pytest.warns(SceneWarning, match=rf"\[material\] nu = {nu}: the linear elements lock "
                      r".*jumps from node to node.*\+6 to \+9 % at 0\.49.*No mixed or "
                      r"locking-free formulation is offered: where contact pressures matter "
                      r"use nu <= 0\.45"):
        _build(write(tmp_path, edit(material__nu=nu)(base())))


def test_nu_below_the_locking_threshold_is_not_warned_about(tmp_path):
    from fenics_contact.scene.checks import LOCKING_NU, SceneWarning

    assert LOCKING_NU == 0.48
    with warnings.catch_warnings():
        warnings.simplefilter("error", SceneWarning)
        _build(write(tmp_path, edit(material__nu=0.47)(base()), name="ok.toml"))


def test_boundary_nodes_outside_the_tag_inside_an_obstacle_are_warned_about(tmp_path):
    """Only the tagged facets are held: sides pushed through the plane are named."""
    from fenics_contact.scene.checks import SceneWarning, warn_untagged_penetration

    problem = _build(write(tmp_path, base()))
    gdim = 2
    problem.u.x.array.reshape(-1, gdim)[:, 1] = -0.3  # the block 0.3 into the floor
    with pytest.warns(SceneWarning, match=r"\[\[obstacle\]\] 'obstacle': 2 boundary nodes "
                      r"outside its candidate facets are inside it, the deepest 0.05 .*add "
                      r"those faces to its tag, or use detect = true"):
        assert warn_untagged_penetration(load_scene(tmp_path / "scene.toml"), problem) == 2
    problem.u.x.array[:] = 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("error", SceneWarning)
        assert warn_untagged_penetration(load_scene(tmp_path / "scene.toml"), problem) == 0


def test_a_pair_tag_mistake_names_the_pair(tmp_path):
    """Of two pairs, the one whose striker tag is wrong is named."""
    from fenics_contact.scene.build import build_problem

    shipped = Path(__file__).parents[1] / "scenes" / "bridge.toml"
    text = shipped.read_text().replace('"../meshes/', f'"{shipped.parents[1]}/meshes/')
    (tmp_path / "bridge.toml").write_text(
        text.replace('striker = "bridge_under_right"', 'striker = "bridge_under_rihgt"'))
    with pytest.raises(SceneError, match=r"\[\[pair\]\] 'on-right' striker tag = "
                                         r"'bridge_under_rihgt' is not a facet tag"):
        build_problem(load_scene(tmp_path / "bridge.toml"))


def test_load_steps_that_pass_over_a_knot_of_a_frictional_path_are_warned(tmp_path):
    """Press to t = 0.4, then drag: one step would press and drag along a diagonal."""
    from fenics_contact.scene.build import SceneWarning

    scene = base()
    scene["contact"]["mu"] = 0.3
    scene["dirichlet"][0] = {"tag": "top", "path": [[0.0, 0.0, 0.0], [0.4, 0.0, -0.05],
                                                    [1.0, 0.02, -0.05]]}
    scene["solver"]["steps"] = 1
    with pytest.warns(SceneWarning, match=r"the 1 load steps \(t = k/1\) pass over the path "
                      r"knot\(s\) t = 0.4: .* \(e.g. 5\)"):
        _build(write(tmp_path, scene))
    scene["solver"]["steps"] = 10  # lands on 0.4
    with warnings.catch_warnings():
        warnings.simplefilter("error", SceneWarning)
        _build(write(tmp_path, scene))


def test_cells_that_belong_to_no_body_are_named_before_the_solve(tmp_path):
    """A [[body]] scene on a mesh holding a second body that no [[body]] declares (the
    ironing mesh's indenter, to be replaced by a rigid ball) failed at the first linear
    solve with a singular Jacobian and advice about contact conditions."""
    from fenics_contact.scene.build import build_problem

    root = Path(__file__).resolve().parents[1]
    text = (root / "scenes" / "ironing.toml").read_text().replace(
        '"../meshes/', f'"{root / "meshes"}/')
    text = re.sub(r'^\[\[body\]\]\nname = "indenter".*?\n\n', "", text, flags=re.S | re.M)
    text = re.sub(r"^\[\[pair\]\]\n.*?\n\n", "[[obstacle]]\ntype = \"ball\"\n"
                  "centre = [0.0, 0.5]\nradius = 0.5\ntag = \"target_face\"\n\n", text,
                  flags=re.S | re.M)
    path = tmp_path / "block_alone.toml"
    path.write_text(text)
    scene = load_scene(path)
    assert [b.name for b in scene.bodies] == ["block"]
    with pytest.raises(SceneError, match=r"block_alone.toml: the mesh's \d+ cells tagged 1 "
                       r"\('striker'\) belong to no \[\[body\]\] \(declared: 'block' \(tag 2\)\)"
                       r".*Add a \[\[body\]\] with their tag"):
        build_problem(scene)


def test_a_solid_refuses_cells_of_no_body():
    """The library's Solid says the same (tag numbers, as it knows no names)."""
    from dolfinx import mesh as dmesh

    from mpi4py import MPI

    from fenics_contact.model.materials import material
    from fenics_contact.model.problem import Body, Solid

    domain = dmesh.create_unit_square(MPI.COMM_WORLD, 4, 4)
    cells = np.arange(domain.topology.index_map(2).size_local, dtype=np.int32)
    midpoints = domain.geometry.x[domain.geometry.dofmaps[0][cells]].mean(axis=1)
    tags = dmesh.meshtags(domain, 2, cells, np.where(midpoints[:, 0] < 0.5, 1, 2).astype(np.int32))
    law = material("linear", 100.0, 0.3)
    with pytest.raises(ValueError, match=r"The mesh's 16 cells tagged 2 belong to no body"):
        Solid(domain, [Body("left", 1, law)], cell_tags=tags)
    Solid(domain, [Body("left", 1, law), Body("right", 2, law)], cell_tags=tags)


@pytest.mark.parametrize("edit, named", [
    (('target = "bottom_topside"', 'target = "floor_face"'),
     r"striker = 'middle_underside' and target = 'floor_face' nowhere face each other.*"
     r"target = 'bottom_topside' faces the striker\."),
    (('striker = "middle_underside"', 'striker = "middle_topside"'),
     r"striker = 'middle_topside' and target = 'bottom_topside' nowhere face each other.*"
     r"striker = 'middle_underside' faces the target\."),
])
def test_a_pair_tag_on_the_far_side_of_its_body_is_named(tmp_path, edit, named):
    """A target (or striker) given as the far face of the right body read as bodies "0.4
    inside each other", or, with nothing else holding a body, as a free translation. It is
    refused as surfaces that nowhere face each other (normals opposed and each in front of
    the other), naming the surface of that body that does face the other one."""
    from fenics_contact.scene.build import build_problem

    root = Path(__file__).resolve().parents[1]
    text = (root / "scenes" / "stack_3_blocks.toml").read_text().replace(
        '"../meshes/', f'"{root / "meshes"}/')
    path = tmp_path / "far_side.toml"
    path.write_text(text.replace(*edit))
    with pytest.raises(SceneError, match=r"far_side.toml: \[\[pair\]\] 'middle-on-bottom': "
                       + named):
        build_problem(load_scene(path))
