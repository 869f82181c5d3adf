"""``fenics-contact render``: any field of any finished step, drawn from the run's files."""

from pathlib import Path

import numpy as np
import pytest

from mpi4py import MPI

from fenics_contact.cli import main
from fenics_contact.output.contact_view import body_label
from fenics_contact.output.pictures import deformed_contact_picture
from fenics_contact.output.render import draw_step, field_labels, render_step
from fenics_contact.runner import run_scene
from fenics_contact.scene.schema import FIELDS, FRICTION_FIELDS, load_scene

SCENES = Path(__file__).parent.parent / "scenes"


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """paper_ex2 (10 load steps), finished, without pictures."""
    out = tmp_path_factory.mktemp("ex2")
    assert run_scene(load_scene(SCENES / "paper_ex2.toml"), out, pictures=False,
                     comm=MPI.COMM_SELF).path.status == "converged"
    return out


def _colours(png: Path) -> int:
    from matplotlib.image import imread

    image = imread(str(png))[..., :3]
    return np.unique((image * 255).astype(np.uint8).reshape(-1, 3), axis=0).shape[0]


@pytest.mark.parametrize(("step", "field"), [(None, "contact_pressure"), (3, "von_mises"),
                                             (10, "displacement"), (6, "gap")])
def test_render_draws_a_step_and_field(run, tmp_path, step, field):
    png = render_step(run, step=step, field=field, path=tmp_path / "p.png")
    assert png.is_file()
    assert _colours(png) > 20  # a coloured body and its scale, not a blank frame


def test_render_default_name_is_the_last_step(run):
    png = render_step(run)
    assert png == run / "render_step_0010_contact_pressure.png" and png.is_file()


@pytest.mark.parametrize(("args", "words"), [
    (["--field", "stress"], "Field 'stress' is not in step 10"),
    (["--step", "11"], "Step 11 is not among the finished steps"),
])
def test_render_mistakes_are_named(run, capsys, args, words):
    assert main(["render", str(run), *args]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and words in err
    if "stress" in args:
        assert "available: active, contact_pressure, displacement, gap, von_mises" in err


def test_render_of_a_folder_without_a_run(tmp_path, capsys):
    assert main(["render", str(tmp_path)]) == 2
    assert "holds no finished load step" in capsys.readouterr().err


@pytest.mark.parametrize(("field", "vector", "panel", "bar"), [
    ("contact_pressure", False, "contact pressure -lam", "p = -lam"),
    ("displacement", True, "|displacement|", "|u|"),
    ("tangential_traction", True, "|tangential traction|", "|t_T|"),
    ("von_mises", False, "von mises", "von Mises"),
    ("gap", False, "gap", "gap"),
])
def test_field_labels_name_the_panel_in_full_and_the_bar_briefly(field, vector, panel, bar):
    assert field_labels(field, vector) == (panel, bar)


def test_every_written_field_has_a_bar_title_that_fits_a_3d_panel():
    """The bar stands in the right seventh of a 3D panel: "contact pressure -lam" was cut."""
    written = (*FIELDS, *FRICTION_FIELDS, "body_id", "target_contact_force")
    titles = {field: field_labels(field, vector=True)[1] for field in written}
    assert all(len(title) <= 12 for title in titles.values()), titles


@pytest.fixture(scope="module")
def three_blocks(tmp_path_factory):
    """three_blocks_3d (a column of three named blocks on a floor), finished."""
    out = tmp_path_factory.mktemp("blocks3d")
    outcome = run_scene(load_scene(SCENES / "three_blocks_3d.toml"), out, pictures=False,
                        comm=MPI.COMM_SELF)
    assert outcome.path.status == "converged"
    return outcome


def test_3d_render_names_the_pressed_surfaces_by_their_bodies(three_blocks, tmp_path):
    png, picture = draw_step(three_blocks.out, path=tmp_path / "p.png")
    assert png.is_file()
    assert [text for _, text in picture.view.labels] == ["bottom", "middle", "top"]
    assert picture.bar == "p = -lam"
    assert picture.panels[0] == "contact pressure -lam, seen from the partner along n"
    _, vm = draw_step(three_blocks.out, field="von_mises", path=tmp_path / "vm.png")
    assert vm.bar == "von Mises" and len(vm.view.labels) == 3


def test_deformed_png_names_the_pressed_surfaces_by_their_bodies(three_blocks, tmp_path):
    picture = deformed_contact_picture(three_blocks.problem, tmp_path / "deformed.png")
    assert [text for _, text in picture.view.labels] == ["bottom", "middle", "top"]
    assert picture.bar == "p = -lam"


def test_body_labels_without_names():
    assert (body_label(1, ()), body_label(None, ("a",)), body_label(1, ("a", "b"))) == (
        "body 1", "body", "b")


def test_2d_render_adds_a_window_on_a_small_contact_zone(tmp_path):
    """Hertz: the zone is a few per cent of the body; it gets a panel of its own (any field)."""
    out = tmp_path / "hertz"
    assert run_scene(load_scene(SCENES / "hertz_cylinder.toml"), out, pictures=False,
                     comm=MPI.COMM_SELF).path.converged
    _, picture = draw_step(out, path=tmp_path / "p.png")
    assert picture.panels == ["contact pressure -lam", "contact pressure -lam, contact zone"]
    _, picture = draw_step(out, field="von_mises", path=tmp_path / "v.png")
    assert picture.panels == ["von mises", "von mises, contact zone"]


def test_2d_render_of_a_wide_contact_zone_has_one_panel(run, tmp_path):
    """The bar of Example 2 presses along most of its length: no window."""
    _, picture = draw_step(run, path=tmp_path / "p.png")
    assert picture.panels == ["contact pressure -lam"]


def test_a_damaged_step_file_is_named_and_a_run_without_pressure_draws_displacement(run, tmp_path):
    """A truncated step file: one message naming it (exit 2); no pressure: the default field."""
    import shutil

    copy = tmp_path / "copy"
    shutil.copytree(run, copy)
    damaged = copy / "solution" / "step_0010.h5"
    damaged.write_bytes(damaged.read_bytes()[:200])
    with pytest.raises(ValueError, match=r"step_0010\.h5 cannot be read .*damaged"):
        render_step(copy, step=10)
    assert main(["render", str(copy), "--step", "10"]) == 2
    # the same run as if it had written the displacement only
    index = (copy / "solution" / "step_0009.xdmf")
    text = index.read_text()
    start = text.index('<Attribute Name="contact_pressure"')
    index.write_text(text[:start] + text[text.index("</Attribute>", start) + 12:])
    png = render_step(copy, step=9)
    assert png.name == "render_step_0009_displacement.png" and png.is_file()



def test_render_draws_the_obstacle_where_the_step_put_it(tmp_path):
    """block_slide_friction: the plane rises 0.01 by t = 0.4, then slides 0.02 (its
    schedule); summary.json gives its point at every step and render draws it there."""
    import json

    from fenics_contact.output.render import obstacle_outlines

    out = tmp_path / "slide"
    assert run_scene(load_scene(SCENES / "block_slide_friction.toml"), out, pictures=False,
                     comm=MPI.COMM_SELF).path.converged
    (plane,) = json.loads((out / "summary.json").read_text())["obstacles"]
    assert (plane["type"], plane["normal"]) == ("plane", [0.0, 1.0])
    points = {s["step"]: s["point"] for s in plane["steps"]}
    np.testing.assert_allclose(points[8], [0.0, 0.01], atol=1e-14)  # t = 0.4
    np.testing.assert_allclose(points[20], [0.02, 0.01], atol=1e-14)
    bounds = np.array([[0.0, 0.0, 0.0], [1.0, 0.5, 0.0]])
    (line,) = obstacle_outlines(out, 8, bounds)
    np.testing.assert_allclose(np.asarray(line.points)[:, 1], 0.01, atol=1e-12)
    assert obstacle_outlines(tmp_path, 8, bounds) == []  # no run there: nothing drawn


def test_2d_stick_slip_is_drawn_on_the_nodes_by_category(tmp_path):
    """block_slide_friction at full sliding: every contact node red (slip), nothing smeared
    over the cells (the map was a continuous colour field across the bottom row)."""
    from matplotlib.image import imread

    out = tmp_path / "slide"
    assert run_scene(load_scene(SCENES / "block_slide_friction.toml"), out, pictures=False,
                     comm=MPI.COMM_SELF).path.converged
    png, _ = draw_step(out, field="stick_slip", path=tmp_path / "s.png")
    image = imread(png)[..., :3]
    red = np.all(np.abs(image - np.array([0xd6, 0x27, 0x28]) / 255.0) < 0.08, axis=2)
    blue = np.all(np.abs(image - np.array([0x1f, 0x77, 0xb4]) / 255.0) < 0.08, axis=2)
    # the slip nodes, and the bar's three swatches; no stick node at full sliding
    assert red.sum() > blue.sum() > 0
