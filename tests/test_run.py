"""`fenics-contact run` on shipped scenes: files on disk, XDMF read back with VTK."""

import json
import re
from pathlib import Path

import numpy as np
import pytest

from mpi4py import MPI

from fenics_contact.cli import main
from fenics_contact.runner import run_scene
from fenics_contact.scene.schema import load_scene

SCENES = Path(__file__).parent.parent / "scenes"
FIELDS = {"displacement", "contact_pressure", "gap", "active"}


def read_xdmf(path):
    """All time steps of an XDMF file through VTK's XDMF reader (via PyVista)."""
    import pyvista

    reader = pyvista.XdmfReader(str(path))
    steps = []
    for t in reader.time_values:
        reader.set_active_time_value(t)
        steps.append((t, reader.read()))
    return steps


@pytest.mark.parametrize("name", ["paper_ex1", "paper_ex2", "hertz_cylinder", "block_3d"])
def test_every_shipped_scene_runs_and_writes_xdmf_json_and_pictures(tmp_path, name):
    out = tmp_path / name
    assert main(["run", str(SCENES / f"{name}.toml"), "--out", str(out), "--quiet"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "converged"
    assert summary["steps_completed"] == summary["load_steps"] == len(summary["steps"])
    for png in ("deformed.png", "residuals.png"):
        assert (out / png).stat().st_size > 5_000
    steps = read_xdmf(out / "solution.xdmf")
    assert len(steps) == summary["load_steps"]
    assert [t for t, _ in steps] == pytest.approx([s["load_factor"] for s in summary["steps"]])
    last = steps[-1][1]
    assert FIELDS <= set(last.point_data.keys())
    assert "von_mises" in last.cell_data.keys()
    for grid in (g for _, g in steps):
        for key in grid.array_names:
            assert np.all(np.isfinite(grid[key]))


def test_xdmf_values_match_the_solution(tmp_path):
    scene = load_scene(SCENES / "paper_ex2.toml")
    outcome = run_scene(scene, tmp_path, pictures=False, comm=MPI.COMM_SELF)
    problem = outcome.problem
    grid = read_xdmf(tmp_path / "solution.xdmf")[-1][1]
    # match points by coordinates: displacement, pressure and the active set
    coords = problem.V.tabulate_dof_coordinates()
    u = problem.u.x.array.reshape(-1, 2)
    index = {tuple(np.round(p[:2], 9)): i for i, p in enumerate(grid.points)}
    rows = [index[tuple(np.round(c[:2], 9))] for c in coords]
    assert np.allclose(grid.point_data["displacement"][rows, :2], u, atol=1e-12)
    state = problem.contact_state()
    q_coords = problem.nodal_coordinates()
    q_rows = [index[tuple(np.round(c[:2], 9))] for c in q_coords]
    assert np.allclose(grid.point_data["contact_pressure"][q_rows], -state.pressure, atol=1e-12)
    assert np.array_equal(grid.point_data["active"][q_rows] > 0.5, state.active)
    assert grid.point_data["contact_pressure"].max() == pytest.approx(-state.pressure.min())
    # von Mises is positive wherever the bar is loaded
    assert grid.cell_data["von_mises"].max() > 1.0


def _last_step_h5(out, name):
    """Points and nodal values of field ``name`` in the last step file, in double precision.

    (VTK's XDMF reader hands the values over in single precision.)
    """
    import h5py

    last = sorted((out / "solution").glob("step_*.h5"))[-1]
    with h5py.File(last, "r") as f:
        group = f[f"Function/{name}"]
        values = group[next(iter(group))][()].ravel()
        return f["Mesh/mesh/geometry"][()], values


def test_written_pressure_is_the_multiplier_at_huge_r(tmp_path):
    """At r = 1e12 E/h the written pressure is the converged multiplier, not min(lam + r g, 0).

    The nodal answer does not depend on r, so the field written at 1e12 E/h
    equals the one at 1 E/h; the round-off of r g (measured: 0.9 % at the
    peak node and 0.6 % on the integral before the fix) must not reach it.
    """
    text = (SCENES / "paper_ex2.toml").read_text()
    fields = {}
    for r, method in ((1.0, "gnrm"), (1e12, "auto")):
        path = tmp_path / f"r{r:g}.toml"
        path.write_text(text.replace("r = 100.0\nrelative = false", f"r = {r}\nrelative = true")
                        .replace('method = "gnrm"', f'method = "{method}"'))
        out = tmp_path / f"out{r:g}"
        outcome = run_scene(load_scene(path), out, pictures=False, comm=MPI.COMM_SELF)
        assert outcome.path.status == "converged"
        problem = outcome.problem
        points, pressure = _last_step_h5(out, "contact_pressure")
        _, active = _last_step_h5(out, "active")
        index = {tuple(np.round(p[:2], 9)): i for i, p in enumerate(points)}
        rows = [index[tuple(np.round(c[:2], 9))] for c in problem.nodal_coordinates()]
        pressure, active = pressure[rows], active[rows] > 0.5
        # the written field integrates to the reported force (lumped nodal areas)
        force = float(np.sum(pressure * problem.surface.lumped_area))
        assert force == pytest.approx(outcome.path.steps[-1].contact_force, rel=1e-12)
        assert np.array_equal(active, pressure > 0.0)
        fields[r] = pressure
    peak = float(np.max(np.abs(fields[1.0])))
    assert np.max(np.abs(fields[1e12] - fields[1.0])) <= 1e-8 * peak


@pytest.mark.parametrize(("cutbacks", "attempts"), [
    (0, "1 attempt, no cut-back"),
    (1, "2 attempts, the increment halved once"),
    (2, "3 attempts, the increment halved 2 times"),
])
def test_failed_first_step_is_worded_truthfully(tmp_path, capsys, cutbacks, attempts):
    """No "steps 1-0", and the attempts and halvings counted alike (both once "5 and 4")."""
    text = (SCENES / "paper_ex2.toml").read_text()
    text = text.replace('method = "gnrm"', 'method = "sua"').replace(
        "max_iterations = 50", f"max_iterations = 3\nmax_cutbacks = {cutbacks}"
    )
    scene = tmp_path / "failing.toml"
    scene.write_text(text)
    out = tmp_path / "out"
    assert main(["run", str(scene), "--out", str(out), "--quiet"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert err[0].startswith("fenics-contact: load step 1 of 10 did not converge (max_iterations")
    assert err[0].endswith(
        f"after {attempts}); no load step finished, so {out} holds no solution.xdmf. To try: "
        "a larger [solver] max_iterations (now 3: SUA counts every multiplier update as an "
        "iteration and may need hundreds per load step); "
        'method = "auto" (Newton on both unknowns; it lowers its working r and line-searches '
        "where plain Newton cycles); more "
        "[solver] steps or max_cutbacks (smaller increments near the failure)."
    )
    summary = json.loads((out / "summary.json").read_text())
    assert summary["steps"][0]["cutbacks"] == cutbacks
    assert summary["message"].startswith("load step 1: max_iterations at load factor")
    # the record holds the state the run stopped in (the last converged increment of
    # step 1, if any), and no viewer files: no step is on disk
    stopped = summary["steps"][0]
    assert 0.0 <= stopped["load_factor"] < 0.1 and 0.5 < stopped["min_det_F"] <= 1.0
    assert stopped["load_factor"] == 0.0 or cutbacks > 0
    assert set(summary["steps"][0]["reactions"]) == {"top"}
    assert not (out / "paraview_state.py").exists() and not (out / "deformed.png").exists()


def test_failing_run_exits_nonzero_and_keeps_finished_steps(tmp_path, capsys):
    text = (SCENES / "paper_ex2.toml").read_text()
    text = text.replace('method = "gnrm"', 'method = "sua"').replace(
        "max_iterations = 50", "max_iterations = 60\nmax_cutbacks = 0"
    ).replace("r = 100.0", "r = 10.0")
    scene = tmp_path / "failing.toml"
    scene.write_text(text)
    out = tmp_path / "out"
    assert main(["run", str(scene), "--out", str(out), "--quiet"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "did not converge" in err[0]
    summary = json.loads((out / "summary.json").read_text())
    done = summary["steps_completed"]
    assert 0 < done < 10
    assert len(read_xdmf(out / "solution.xdmf")) == done


def test_demo_scene_files_describe_the_demo_problems(tmp_path):
    """scenes/paper_ex2.toml and the laboratory's bar_on_cradle case give one answer."""
    from benchmarks import cases
    from fenics_contact.solvers import make_strategy
    from fenics_contact.solvers.diagnostics import SolverSettings
    from fenics_contact.solvers.stepping import solve_load_path

    text = (SCENES / "paper_ex2.toml").read_text().replace(
        "[solver]", '[solver]\npredictor = "previous"\ncontact_set = "sign"'
    )
    (tmp_path / "ex2.toml").write_text(text)
    outcome = run_scene(load_scene(tmp_path / "ex2.toml"), tmp_path, pictures=False)
    example = cases.bar_on_cradle()
    problem = cases.build(example, 100.0, relative=False)
    path = solve_load_path(make_strategy("gnrm", problem, SolverSettings()),
                           example.solver.steps)
    assert [s.iterations for s in outcome.path.steps] == [s.iterations for s in path.steps]
    assert outcome.path.steps[-1].contact_force == pytest.approx(
        path.steps[-1].contact_force, rel=1e-10
    )


def test_scene_solver_options_give_the_same_answer(tmp_path):
    """Predictor and iterative linear solver change the cost, not the solution."""
    base = (SCENES / "block_3d.toml").read_text()
    forces, iterations = {}, {}
    for name, extra in (
        ("plain", 'predictor = "previous"'),
        ("extrapolated", 'predictor = "extrapolate"'),
        ("iterative", 'linear_solver = "iterative"'),
        ("inexact", 'linear_solver = "iterative"\nforcing = "eisenstat-walker"\n'
                    'reuse_preconditioner = "step"'),
    ):
        (tmp_path / f"{name}.toml").write_text(base.replace("[solver]", f"[solver]\n{extra}"))
        outcome = run_scene(
            load_scene(tmp_path / f"{name}.toml"), tmp_path / name, pictures=False
        )
        assert outcome.path.converged
        forces[name] = outcome.path.steps[-1].contact_force
        iterations[name] = outcome.path.iterations
    assert forces["extrapolated"] == pytest.approx(forces["plain"], rel=1e-8)
    assert forces["iterative"] == pytest.approx(forces["plain"], rel=1e-8)
    assert forces["inexact"] == pytest.approx(forces["plain"], rel=1e-8)
    assert iterations["inexact"] <= iterations["iterative"] + 1
    assert iterations["extrapolated"] <= iterations["plain"]


def test_penalty_penetration_is_given_in_facet_sizes_with_a_note(tmp_path, capsys):
    """A soft penalty 'converges' with a deep penetration: the line says what it is."""
    text = (SCENES / "paper_ex2.toml").read_text()
    scene = tmp_path / "soft.toml"
    scene.write_text(text.replace('method = "gnrm"', 'method = "penalty"').replace(
        "r = 100.0", "r = 0.1"))
    assert main(["run", str(scene), "--out", str(tmp_path / "soft"), "--no-pictures"]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if "max penetration" in x)
    depth, share = re.search(r"max penetration ([0-9.e+-]+) \(([0-9.e+-]+) h\)", line).groups()
    assert float(share) > 1e-3 and float(depth) > 0
    assert "the penalty method's own penetration: raise r, or use gnrm or auto" in line
    scene.write_text(text)  # GNRM: no penetration, no note
    assert main(["run", str(scene), "--out", str(tmp_path / "gnrm"), "--no-pictures"]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if "max penetration" in x)
    assert "penalty" not in line and "warning" not in line


def test_the_summary_line_counts_the_warnings(tmp_path, capsys):
    """Warnings scroll by during a run; the last line says how many and where they are kept."""
    scene = SCENES / "block_on_block_node_to_segment.toml"  # warns (its header says why)
    assert main(["run", str(scene), "--out", str(tmp_path / "out"), "--no-pictures"]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if "max penetration" in x)
    assert line.endswith("; 1 warning above (kept in summary.json)")


def test_a_log_gets_one_line_per_load_step(tmp_path, capsys):
    """Without a terminal (a log file, CI) no progress bar: one line per finished step."""
    scene = SCENES / "block_on_block.toml"
    assert main(["run", str(scene), "--out", str(tmp_path / "out"), "--no-pictures"]) == 0
    err = capsys.readouterr().err.splitlines()
    assert err == [
        "block-on-block: load step 1/2 converged, load factor 0.5, 1 Newton iteration, "
        "contact force 1.0989",
        "block-on-block: load step 2/2 converged, load factor 1, 0 Newton iterations, "
        "contact force 2.1978",
    ]


def test_a_new_run_in_an_old_folder_replaces_only_the_runs_files(tmp_path, capsys):
    """An earlier run's results go with one note; files the run does not write stay."""
    text = (SCENES / "paper_ex2.toml").read_text()
    scene = tmp_path / "ex2.toml"
    scene.write_text(text.replace("steps = 10", "steps = 4"))
    out = tmp_path / "out"
    assert main(["run", str(scene), "--out", str(out), "--quiet"]) == 0
    assert capsys.readouterr().err == ""  # a new folder: nothing to say
    mine = [out / "notes.txt", out / "checkpoint" / "notes.txt",
            out / "checkpoint" / "step_0004" / "mine.txt", out / "solution" / "readme.txt"]
    for path in mine:
        path.write_text("the user's")
    scene.write_text(text.replace("steps = 10", "steps = 2"))
    assert main(["run", str(scene), "--out", str(out), "--quiet", "--no-pictures"]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"fenics-contact: note: {out} held an earlier run (4 load steps); "
                   "its results are replaced"]
    assert all(path.read_text() == "the user's" for path in mine)
    # the earlier run's files are gone: its later steps, checkpoint files and pictures
    assert sorted(p.name for p in (out / "solution").iterdir()) == [
        "readme.txt", "step_0001.h5", "step_0001.xdmf", "step_0002.h5", "step_0002.xdmf"]
    assert sorted(p.name for p in (out / "checkpoint" / "step_0004").iterdir()) == ["mine.txt"]
    assert sorted(p.name for p in (out / "checkpoint").iterdir()) == [
        "latest.json", "notes.txt", "step_0002", "step_0004"]
    assert not (out / "deformed.png").exists() and not (out / "residuals.png").exists()
    summary = json.loads((out / "summary.json").read_text())
    assert summary["load_steps"] == summary["steps_completed"] == 2
    assert json.loads((out / "checkpoint" / "latest.json").read_text())["step"] == 2
    assert len(read_xdmf(out / "solution.xdmf")) == 2


def test_an_absolute_tolerance_too_loose_for_the_forces_is_warned_about(tmp_path, capsys):
    """E = 1e-9: every residual is below atol = 1e-8 from the start; the run says so."""
    text = (SCENES / "paper_ex2.toml").read_text()
    scene = tmp_path / "soft.toml"
    scene.write_text(re.sub(r"\nE = [0-9.e+]+", "\nE = 1e-9", text, count=1))
    assert main(["run", str(scene), "--out", str(tmp_path / "soft"), "--no-pictures",
                 "--quiet"]) == 0
    err = capsys.readouterr().err
    assert "[solver] atol = 1e-08 is absolute (force units) and not small" in err, err
    assert main(["run", str(SCENES / "paper_ex2.toml"), "--out", str(tmp_path / "stiff"),
                 "--no-pictures", "--quiet"]) == 0
    assert "atol" not in capsys.readouterr().err


def test_a_new_run_removes_the_earlier_runs_pictures_and_renders_only(tmp_path, capsys):
    """summary.json, deformed.png and `render`'s PNGs go; the user's own files stay."""
    from fenics_contact.runner import _replace_earlier_run

    out = tmp_path / "out"
    out.mkdir()
    for name in ("summary.json", "deformed.png", "render_step_0004_contact_pressure.png",
                 "notes.txt", "my_render.png"):
        (out / name).write_text("x")
    _replace_earlier_run(MPI.COMM_SELF, out)
    assert sorted(p.name for p in out.iterdir()) == ["my_render.png", "notes.txt"]
    assert "held an earlier run" in capsys.readouterr().err


def test_several_contacts_are_named_each_with_its_force(tmp_path, capsys):
    """Their sum would add the floor's force to the forces between the blocks."""
    scene = SCENES / "stack_3_blocks.toml"
    assert main(["run", str(scene), "--out", str(tmp_path / "out"), "--no-pictures"]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if "max penetration" in x)
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    last = summary["steps"][-1]["contacts"]
    assert len(last) >= 2
    named = ", ".join(f"{name} {c['normal_force']:.6g}" for name, c in last.items())
    assert f"; contact forces {named}, max penetration" in line


def test_a_support_that_drives_a_node_into_an_obstacle_is_named(tmp_path, capsys):
    """The top of a block dragged 0.1 sideways into a wall 0.05 away.

    The wall's candidate facets (the right side) include the top corner, which
    the drag holds: past 0.05 the support pushes it into the wall. The run
    stops at the step where that happens (the steps before are kept), and the
    message names the cause and its fix; before, it named the penetration
    only and advised method = "auto" and smaller steps, which cannot help.
    """
    scene = tmp_path / "dragged.toml"
    scene.write_text(
        '[scene]\nname = "dragged"\ndimension = 2\n\n'
        '[mesh]\ngenerator = "rectangle"\norigin = [0.0, 0.0]\nsize = [1.0, 0.5]\n'
        'cells = [10, 5]\n\n[material]\nlaw = "linear"\nE = 200.0\nnu = 0.3\n\n'
        '[obstacle]\ntype = "plane"\npoint = [1.05, 0.0]\nnormal = [-1.0, 0.0]\n\n'
        '[contact]\ntag = "right"\n\n'
        '[[dirichlet]]\ntag = "bottom"\nvalue = [0.0, 0.0]\n\n'
        '[[dirichlet]]\ntag = "top"\nvalue = [0.1, 0.0]\n\n'
        '[solver]\nmethod = "gnrm"\nsteps = 4\nmax_cutbacks = 1\n')
    assert main(["run", str(scene), "--out", str(tmp_path / "out"), "--quiet"]) == 1
    err = capsys.readouterr().err
    assert "at a node whose gap a [[dirichlet]] condition fixes: the prescribed displacement " \
           "drives it into the partner" in err, err
    assert "end that support's path before the contact" in err
    assert "To try" not in err
    assert "steps 1-2 are in" in err
    last = json.loads((tmp_path / "out" / "summary.json").read_text())["steps"][-1]
    # the state it stopped in, and the load factor of its last attempt
    assert (last["load_factor"], last["failed_at"]) == (0.5, 0.625)
    assert "at load factor 0.625" in last["message"]


#: A block whose top is dragged 0.1 towards a wall 0.05 away while a ball presses it:
#: step 2 (of 3) converges half-way (load factor 0.5, the dragged corner at the wall) and
#: fails past it, so the state it stops in lies between step 1 and the failed attempt.
DRAGGED_AND_PRESSED = (
    '[scene]\nname = "dragged"\ndimension = 2\n\n'
    '[mesh]\ngenerator = "rectangle"\norigin = [0.0, 0.0]\nsize = [1.0, 0.5]\n'
    'cells = [10, 5]\n\n[material]\nlaw = "linear"\nE = 200.0\nnu = 0.3\n\n'
    '[[obstacle]]\nname = "press"\ntype = "ball"\ncentre = [0.5, 1.0]\nradius = 0.5\n'
    'motion = [0.0, -0.06]\ntag = "top"\n\n'
    '[[obstacle]]\nname = "wall"\ntype = "plane"\npoint = [1.05, 0.0]\n'
    'normal = [-1.0, 0.0]\ntag = "right"\n\n'
    '[[dirichlet]]\ntag = "bottom"\nvalue = [0.0, 0.0]\n\n'
    '[[dirichlet]]\ntag = "top"\nvalue = [0.1, "free"]\n\n'
    '[solver]\nmethod = "gnrm"\nsteps = 3\nmax_cutbacks = 2\n')


def test_a_failed_runs_pictures_show_the_last_step_written(tmp_path, monkeypatch):
    """Before, deformed.png showed and was titled with the state the failed step stopped
    in (load factor 0.5, force 4.73), which solution.xdmf does not hold (it ends at step 1,
    0.333, force 2.97), and summary.json's last record did not say it was not written."""
    import fenics_contact.output.pictures as pictures

    path = tmp_path / "dragged.toml"
    path.write_text(DRAGGED_AND_PRESSED)
    drawn = []

    def picture(problem, png, title=""):
        drawn.append((title, problem.load_factor, problem.u.x.array.copy(),
                      sum(s.contact_force for s in problem.contact_states().values())))

    monkeypatch.setattr(pictures, "deformed_contact_picture", picture)
    outcome = run_scene(load_scene(path), tmp_path / "out", comm=MPI.COMM_SELF, pictures=True)
    first, failed = outcome.path.steps
    assert (first.status, failed.status) == ("converged", "cycling")
    assert (failed.load_factor, failed.failed_at) == (0.5, pytest.approx(0.5833333333333334))
    assert first.contact_force == pytest.approx(2.968, rel=1e-3)
    assert failed.contact_force == pytest.approx(4.730, rel=1e-3)
    # the picture: step 1's state, titled so, and the failed step named beside it
    (title, t, u, force), = drawn
    assert title == ("dragged: step 1, load factor 0.333333, contact force 2.968, the last "
                     "step written\n(step 2 cycling at load factor 0.583333)")
    assert t == pytest.approx(1 / 3, abs=1e-15)
    (_, grid), = read_xdmf(tmp_path / "out" / "solution.xdmf")  # step 1 only (float32)
    on_disk = np.linalg.norm(grid.point_data["displacement"], axis=1)
    assert np.linalg.norm(u.reshape(-1, 2), axis=1).max() == pytest.approx(on_disk.max(),
                                                                           rel=1e-6)
    assert force == pytest.approx(first.contact_force, rel=1e-10)
    # the problem is back in the state the run stopped in, as its record says
    assert outcome.problem.load_factor == 0.5
    assert sum(s.contact_force for s in outcome.problem.contact_states().values()) == \
        pytest.approx(failed.contact_force, rel=1e-10)
    steps = json.loads((tmp_path / "out" / "summary.json").read_text())["steps"]
    assert [s["written"] for s in steps] == [True, False]
    assert "note" not in steps[0]
    assert steps[1]["note"] == (
        "the failed step (cycling at load factor 0.583333): load_factor and the forces here "
        "are the state the run stopped in, at load factor 0.5 (the last converged part of "
        "this step, not written); solution.xdmf ends at step 1 (load factor 0.333333)")



def test_picture_titles_name_the_step_shown_and_a_failed_one():
    """Converged: the last step; failed with no step written (the first step's forms
    compiled ahead of a run): the state it stopped in, said to be no written step."""
    from fenics_contact.runner import picture_title
    from fenics_contact.solvers.stepping import RunRecord, StepRecord

    done = StepRecord(step=2, load_factor=1.0, status="converged", contact_force=3.25)
    assert picture_title("s", RunRecord("converged", [done])) == (
        "s: step 2, load factor 1, contact force 3.25 (converged)")
    stuck = StepRecord(step=1, load_factor=0.25, status="diverged", failed_at=0.375,
                       contact_force=1.5)
    assert picture_title("s", RunRecord("diverged", [stuck])) == (
        "s: step 1 diverged at load factor 0.375; shown: the state it stopped in, load "
        "factor 0.25, contact force 1.5 (not written)")


def test_a_second_run_into_a_folder_being_written_is_refused(tmp_path, capsys):
    """A --resume started while the first run still wrote into the folder found its
    checkpoint "damaged or unreadable". A folder that a live process holds is refused
    before any work (exit 2, naming the process); a lock left by a killed run is taken
    over, and a finished run leaves none."""
    import os
    import subprocess

    from fenics_contact.output.folders import LOCK

    scene = SCENES / "block_on_block.toml"
    out = tmp_path / "out"
    out.mkdir()
    (out / LOCK).write_text(f"{os.getppid()} {__import__('socket').gethostname()}")
    assert main(["run", str(scene), "--out", str(out), "--no-pictures"]) == 2
    err = capsys.readouterr().err
    assert f"another run (process {os.getppid()}) is writing to {out}" in err
    assert not (out / "summary.json").exists()
    gone = subprocess.Popen(["true"])
    gone.wait()
    (out / LOCK).write_text(f"{gone.pid} {__import__('socket').gethostname()}")
    assert main(["run", str(scene), "--out", str(out), "--no-pictures"]) == 0
    assert (out / "summary.json").is_file() and not (out / LOCK).exists()


def test_a_failed_svk_step_names_the_laws_compression_limit(tmp_path):
    """A hemisphere pressed 0.35 R with the SVK law failed at load factor 0.61 with 1 or
    20 steps, and was advised more steps; neo-Hookean solved it in one. The advice of an
    SVK scene that diverged or cycled now names the law's compression limit before more
    steps."""
    from fenics_contact.cli.run import _advice

    text = (SCENES / "paper_ex2.toml").read_text()
    laws = {}
    for law in ("svk", "neo-hookean"):
        path = tmp_path / f"{law}.toml"
        path.write_text(re.sub(r'law = "[a-z-]+"', f'law = "{law}"', text, count=1))
        laws[law] = _advice(load_scene(path), "diverged")
    tip = 'if a body is compressed by more than about 40 %, law = "neo-hookean"'
    assert tip in laws["svk"] and "1/sqrt(3)" not in laws["neo-hookean"]
    assert laws["svk"].index(tip) < laws["svk"].index("more [solver] steps")
