"""Pictures that show the contact: the 3D camera along the contact normal, the pressed
nodes in the contact panel, stick/slip with friction, 2D zone windows, the ParaView script."""

import copy
import os
import shutil
import subprocess
import tomllib
from pathlib import Path
from xml.etree import ElementTree

import numpy as np
import pytest

from mpi4py import MPI

from fenics_contact.output.contact_view import PRESSURE, STICK_SLIP
from fenics_contact.output.paraview import SCRIPT
from fenics_contact.output.pictures import _gathered_grid, deformed_contact_picture
from fenics_contact.output.render import draw_step
from fenics_contact.runner import run_scene
from fenics_contact.scene.schema import load_scene, scene_from_data

SCENES = Path(__file__).parent.parent / "scenes"
DOWN = np.array([0.0, 0.0, -1.0])


def _scene(name: str, **changes):
    """A shipped scene with ``changes`` ({"section.key": value}) applied."""
    data = copy.deepcopy(tomllib.loads((SCENES / f"{name}.toml").read_text()))
    for key, value in changes.items():
        *sections, last = key.split(".")
        table = data
        for section in sections:
            table = table[section]
        table[last] = value
    return scene_from_data(data, SCENES / f"{name}.toml")


def _image_width(png: Path) -> int:
    from matplotlib.image import imread

    return imread(str(png)).shape[1]


@pytest.fixture(scope="module")
def ball_friction(tmp_path_factory):
    """block_3d, coarse (6 x 6 x 3 hexahedra, 2 steps), the ball with mu = 0.3."""
    out = tmp_path_factory.mktemp("ball")
    scene = _scene("block_3d", **{"mesh.cells": [6, 6, 3], "solver.steps": 2,
                                  "contact.mu": 0.3})
    outcome = run_scene(scene, out, pictures=False, comm=MPI.COMM_SELF)
    assert outcome.path.status == "converged"
    picture = deformed_contact_picture(outcome.problem, out / "deformed.png", title="ball")
    return outcome, picture


def test_3d_picture_looks_along_the_contact_normal(ball_friction):
    _, picture = ball_friction
    # the ball pushes the block's base up: the pressed face looks down, towards the ball
    assert picture.view is not None
    assert picture.view.normal @ DOWN > 0.999
    contact_panel = picture.panels[0]
    assert "contact pressure" in contact_panel
    assert picture.directions[contact_panel] @ DOWN > 0.999
    assert picture.panels[-1] == "deformed body"


def test_contact_panel_holds_every_pressed_node(ball_friction):
    outcome, picture = ball_friction
    grid = _gathered_grid(outcome.problem)
    expected = np.sort(grid.point_data[PRESSURE][grid.point_data[PRESSURE] > 0])
    shown = np.asarray(picture.view.surface.point_data[PRESSURE])
    assert expected.size >= 9
    assert np.sort(shown[shown > 0]) == pytest.approx(expected, rel=0, abs=0)


def test_frictional_3d_picture_has_a_stick_slip_panel(ball_friction):
    outcome, picture = ball_friction
    out = outcome.out
    assert [p.split(",")[0] for p in picture.panels] == [
        "contact pressure", "stick/slip", "deformed body"]
    states = np.asarray(picture.view.surface.point_data[STICK_SLIP])
    assert set(np.unique(states)) <= {0.0, 1.0, 2.0} and np.any(states == 1.0)
    assert _image_width(out / "deformed.png") == 3 * 700


def test_3d_friction_profile_is_drawn_against_the_distance_from_the_zone_centre(ball_friction):
    """In 3D the nodes have no order along one axis: joined in x order they drew a sawtooth.

    Each node is placed at its distance from the mu p weighted centre of the
    zone (the ball presses the middle of the base): the limit mu p falls
    with that distance, as the pressure under a ball does.
    """
    from fenics_contact.output.friction_plot import friction_profile, friction_profile_data

    outcome, _ = ball_friction
    data = friction_profile_data(outcome.problem)
    (profile,) = data.values()
    assert profile["axis"] == "r"
    s, limit = profile["s"], profile["limit"]
    assert np.all(np.diff(s) >= 0.0) and s[0] >= 0.0
    touching = limit > 0.0
    assert touching.sum() >= 5
    assert s[touching].min() < 0.1 * s.max()  # the zone's centre sits on a pressed node
    assert limit[np.argmin(s)] == pytest.approx(limit.max())  # the peak at the centre
    friction_profile(outcome.problem, outcome.out / "friction.png", title="ball")
    assert (outcome.out / "friction.png").stat().st_size > 0


def test_render_in_3d_uses_the_same_contact_view(ball_friction):
    outcome, picture = ball_friction
    png, drawn = draw_step(outcome.out, field="von_mises", path=outcome.out / "vm.png")
    assert png.is_file() and drawn.view is not None
    assert drawn.view.normal @ picture.view.normal > 0.999
    assert drawn.directions[drawn.panels[0]] @ DOWN > 0.999
    _, states = draw_step(outcome.out, field="stick_slip", path=outcome.out / "ss.png")
    assert states.panels[0].startswith("stick slip")


def test_two_bodies_are_seen_from_the_target_side(tmp_path):
    """Two hemispheres (coarse): the striker's cap is seen from below, where the target is."""
    scene = _scene("two_hemispheres_3d_node_to_segment", **{
        "mesh.parameters": {"h_contact": 0.06, "h_far": 0.4}, "solver.steps": 2})
    outcome = run_scene(scene, tmp_path, pictures=False, comm=MPI.COMM_SELF)
    assert outcome.path.status == "converged"
    picture = deformed_contact_picture(outcome.problem, tmp_path / "deformed.png")
    assert picture.view.normal @ DOWN > 0.99
    assert picture.directions[picture.panels[0]] @ DOWN > 0.99
    assert picture.panels[-1] == "deformed bodies"
    # only the striker carries pressure, so the panel shows the upper body alone
    assert not picture.view.labels


def test_2d_picture_has_a_window_on_each_small_contact_zone(tmp_path):
    outcome = run_scene(load_scene(SCENES / "cylinder_between_plates.toml"), tmp_path,
                        pictures=False, comm=MPI.COMM_SELF)
    picture = deformed_contact_picture(outcome.problem, tmp_path / "deformed.png")
    assert picture.panels == ["whole body", "contact zone 1", "contact zone 2",
                              "contact zone 3"]
    assert _image_width(tmp_path / "deformed.png") == 4 * 700


@pytest.fixture(scope="module")
def ex2(tmp_path_factory):
    out = tmp_path_factory.mktemp("ex2")
    assert run_scene(load_scene(SCENES / "paper_ex2.toml"), out, pictures=False,
                     comm=MPI.COMM_SELF).path.status == "converged"
    return out


def test_paraview_script_names_the_run_files_and_fields(ex2):
    script = ex2 / SCRIPT
    text = script.read_text()
    compile(text, str(script), "exec")
    names = {}
    exec(compile("\n".join(line for line in text.splitlines()  # the constants only
                           if line.split(" = ")[0] in ("INDEX", "DISPLACEMENT", "PRESSURE",
                                                       "DIMENSION")), "c", "exec"), names)
    assert (ex2 / names["INDEX"]).is_file() and names["DIMENSION"] == 2
    step = ElementTree.parse(ex2 / "solution" / "step_0010.xdmf").getroot()
    fields = {a.get("Name") for a in step.iter("Attribute")}
    assert {names["DISPLACEMENT"], names["PRESSURE"]} <= fields


def test_paraview_script_runs_in_pvpython(ex2, tmp_path):
    pvpython = shutil.which("pvpython")
    if pvpython is None:
        pytest.skip("pvpython is not on PATH (ParaView not installed): the script is only "
                    "compiled and its names checked")
    png = tmp_path / "pv.png"
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTHON", "OMPI", "PMI"))}
    done = subprocess.run([pvpython, "--force-offscreen-rendering", str(ex2 / SCRIPT),
                           "--png", str(png)], capture_output=True, text=True, timeout=120,
                          env=env)
    assert done.returncode == 0, done.stderr
    assert png.stat().st_size > 5_000


@pytest.mark.mpi
def test_3d_picture_on_every_process_count(tmp_path_factory):
    """Gathered to rank 0: each node once, every pressed node in the contact panel."""
    comm = MPI.COMM_WORLD
    out = Path(comm.bcast(str(tmp_path_factory.mktemp("mpi")) if comm.rank == 0 else None))
    scene = _scene("block_3d", **{"mesh.cells": [6, 6, 3], "solver.steps": 2,
                                  "contact.mu": 0.3})
    outcome = run_scene(scene, out, pictures=False, comm=comm)
    problem = outcome.problem
    picture = deformed_contact_picture(problem, out / "deformed.png")
    owned = problem.V.dofmap.index_map.size_local
    pressures = [-c.contact_state().pressure for c in problem.contacts]
    from fenics_contact.output.io import ContactsToBody

    field = ContactsToBody(problem).field("p", pressures, add=True).x.array[:owned]
    pressed = comm.allreduce(int(np.count_nonzero(field > 0)), op=MPI.SUM)
    nodes = comm.allreduce(owned, op=MPI.SUM)
    if comm.rank == 0:
        assert picture.view.normal @ DOWN > 0.999
        shown = np.asarray(picture.view.surface.point_data[PRESSURE])
        assert np.count_nonzero(shown > 0) == pressed
        assert _gathered_grid(problem).n_points == nodes
    else:
        assert picture is None
        _gathered_grid(problem)


_STAND_IN = '''
"""A stand-in for paraview.simple that records what the script asks of it."""
import json, os

calls = []


class Proxy:
    def __init__(self, name, **kw):
        self.__dict__["name"] = name
        self.__dict__["props"] = dict(kw)
        calls.append([name, {k: str(v) for k, v in kw.items()}])

    def __setattr__(self, key, value):
        calls.append([self.name + "." + key, str(value)])

    def __getattr__(self, key):
        return lambda *a, **k: calls.append([self.name + "." + key, [str(x) for x in a]])


def OpenDataFile(path):
    assert os.path.isfile(path), path
    proxy = Proxy("reader", path=path)
    proxy.__dict__["TimestepValues"] = [0.1 * k for k in range(1, 11)]
    return proxy


def _factory(name):
    return lambda *a, **kw: Proxy(name, **kw)


for _name in ("Calculator", "WarpByVector", "GetAnimationScene", "GetActiveViewOrCreate",
              "Show"):
    globals()[_name] = _factory(_name)


def ColorBy(display, what):
    calls.append(["ColorBy", list(what)])


def ResetCamera(view):
    calls.append(["ResetCamera", []])


def Render(view):
    with open(os.environ["CALLS"], "w") as f:
        json.dump(calls, f)


def SaveScreenshot(path, view, **kw):
    calls.append(["SaveScreenshot", path])
    with open(os.environ["CALLS"], "w") as f:
        json.dump(calls, f)
'''


def test_paraview_script_asks_for_the_warp_the_colour_and_the_step(ex2, tmp_path):
    """Run against a stand-in paraview.simple: the calls it makes, default and --step."""
    import json
    import sys

    (tmp_path / "paraview").mkdir()
    (tmp_path / "paraview" / "__init__.py").write_text("")
    (tmp_path / "paraview" / "simple.py").write_text(_STAND_IN)
    record = tmp_path / "calls.json"
    env = {**os.environ, "PYTHONPATH": str(tmp_path), "CALLS": str(record)}
    for extra, time in (([], "1.0"), (["--step", "3", "--png", "x.png"], "0.30000000000000004")):
        done = subprocess.run([sys.executable, str(ex2 / SCRIPT), *extra], env=env,
                              capture_output=True, text=True, timeout=60)
        assert done.returncode == 0, done.stderr
        calls = json.loads(record.read_text())
        assert ["WarpByVector.Vectors", "['POINTS', 'displacement']"] in calls
        assert not any(call[0].startswith("Calculator") for call in calls)
        assert ["ColorBy", ["POINTS", "contact_pressure"]] in calls
        assert ["GetAnimationScene.AnimationTime", time] in calls
    assert ["SaveScreenshot", "x.png"] in calls
    done = subprocess.run([sys.executable, str(ex2 / SCRIPT), "--step", "11"], env=env,
                          capture_output=True, text=True, timeout=60)
    assert done.returncode != 0 and "load steps 1-10" in done.stderr


def test_surfaces_pressed_on_both_sides_are_laid_side_by_side():
    """Two cubes, one pressed on its base (-z), the other, less, on its top (+z): n = -z,
    the second is turned over, both are shown whole and do not overlap on the screen."""
    import pyvista

    from fenics_contact.output.contact_view import BODY, contact_view

    cubes = []
    for body, (shift, pressed_z) in enumerate([((0.0, 0.0, 0.0), 0.0), ((3.0, 0.0, 0.0), 1.0)]):
        cube = pyvista.ImageData(dimensions=(4, 4, 4), spacing=(1 / 3,) * 3,
                                 origin=shift).cast_to_unstructured_grid()
        z = np.asarray(cube.points)[:, 2]
        cube.point_data[PRESSURE] = np.where(np.isclose(z, pressed_z), 2.0 - body, 0.0)
        cube.cell_data[BODY] = np.full(cube.n_cells, float(body))
        cubes.append(cube)
    grid = cubes[0].merge(cubes[1], merge_points=False)
    view = contact_view(grid)
    assert view.normal @ DOWN > 0.999
    assert [text for _, text in view.labels] == ["body 0", "body 1, pressed on -n (turned over)"]
    shown = np.asarray(view.surface.point_data[PRESSURE])
    assert np.count_nonzero(shown == 2.0) == 16 and np.count_nonzero(shown == 1.0) == 16
    across = np.asarray(view.surface.points) @ view.right
    first, second = across[shown == 2.0], across[shown == 1.0]
    assert first.max() < second.min() or second.max() < first.min()
    depth = np.asarray(view.surface.points) @ view.normal
    assert np.ptp(depth[shown > 0]) < 1e-12  # both pressed faces in one plane facing the camera


def test_2d_bodies_get_their_own_fill():
    import pyvista

    from fenics_contact.output.contact_view import BODY
    from fenics_contact.output.pictures import BODY_FILLS, _body_style

    grid = pyvista.ImageData(dimensions=(3, 3, 1)).cast_to_unstructured_grid()
    assert _body_style(grid) == {"color": BODY_FILLS[0]}
    grid.cell_data[BODY] = np.array([0.0, 0.0, 1.0, 1.0])
    style = _body_style(grid)
    assert style["scalars"] == BODY and style["cmap"] == list(BODY_FILLS[:2])
    assert not style["show_scalar_bar"]


def test_friction_profile_zooms_on_a_narrow_zone():
    from fenics_contact.output.friction_plot import contact_window

    s = np.linspace(-1.0, 3.0, 81)  # spacing 0.05
    touching = (s > 1.0) & (s < 1.4)
    lo, hi = contact_window(s, touching)
    assert lo < s[touching].min() and hi > s[touching].max() and hi - lo < 1.0
    assert contact_window(s, np.abs(s - 1.0) < 1.5) is None  # wide: the whole surface
    assert contact_window(s, np.zeros_like(s, dtype=bool)) is None


def test_screen_axes_do_not_turn_with_round_off():
    """A normal along z read with round-off in x or y gives the same screen axes.

    The pressed face of a symmetric quarter model is seen along z; its normal
    comes out as (+-1e-17, -+1e-17, 1) depending on the mesh partition. The
    axes must not swap (a picture turned by a quarter on 2 processes).
    """
    from fenics_contact.output.contact_view import screen_axes

    up_a, right_a = screen_axes(np.array([1e-17, -2e-17, 1.0]))
    up_b, right_b = screen_axes(np.array([-3e-17, 1e-17, 1.0]))
    np.testing.assert_allclose(up_a, up_b, atol=1e-12)
    np.testing.assert_allclose(right_a, right_b, atol=1e-12)
    assert abs(up_a[1]) > 0.999  # y, the first of the global axes least along n (z excluded)


def test_the_friction_profile_draws_the_traction_on_the_body_along_the_axis(tmp_path):
    """A plane moving +x drags the block's face +x: the drawn traction is positive where
    the nodes slip. The same vector for a pair: its own tangent frame (which turned the
    sign of pairs before) no longer enters."""
    from fenics_contact import load_scene, run_scene
    from fenics_contact.output.friction_plot import friction_profile_data

    scenes = Path(__file__).parents[1] / "scenes"
    outcome = run_scene(load_scene(scenes / "block_slide_friction.toml"), tmp_path / "slide",
                        pictures=False)
    data = friction_profile_data(outcome.problem)
    if data is None:  # not process 0
        return
    (profile,) = data.values()
    slipping = profile["state"] == 2
    assert slipping.sum() > 5
    assert np.all(profile["traction"][slipping] > 0.0)
    assert np.allclose(profile["traction"][slipping], profile["limit"][slipping], rtol=1e-6)


def test_a_nodal_state_is_not_interpolated_over_the_3d_bodies():
    """Stick/slip (0 open, 1 stick, 2 slip) on the deformed bodies' panel: interpolated over
    the faces, the side of a block whose base slips and whose top is open showed a band of
    "stick". The bodies are now grey and the states dots on the nodes that carry one."""
    import pyvista

    from fenics_contact.output.contact_view import draw_solid, stick_slip_style

    grid = pyvista.ImageData(dimensions=(3, 3, 3)).cast_to_unstructured_grid()
    states = np.where(np.asarray(grid.points)[:, 2] == 0.0, 2.0, 0.0)
    grid.point_data[STICK_SLIP] = states
    grid.point_data[PRESSURE] = np.zeros(grid.n_points)  # no pressed surface: one panel
    _, plotter = draw_solid(grid, stick_slip_style(), name="stick slip", nodal=True)
    drawn = [(a.mapper.dataset, bool(a.mapper.scalar_visibility))
             for a in plotter.renderers[-1].actors.values()
             if isinstance(a, pyvista.Actor) and a.mapper.dataset is not None]
    plotter.close()
    body, coloured = max(drawn, key=lambda d: d[0].n_points)
    dots = [m for m, _ in drawn if m is not body]
    assert not coloured  # the body itself is one grey
    assert [m.n_points for m in dots] == [9]  # the 9 slipping base nodes, nothing between
