"""``fenics-contact render``: any field of any finished step, drawn from the run's files."""

from pathlib import Path

import numpy as np
import pytest

from mpi4py import MPI

from fenics_contact.cli import main
from fenics_contact.output.render import render_step
from fenics_contact.runner import run_scene
from fenics_contact.scene.schema import load_scene

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
