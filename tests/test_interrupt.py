"""Runs stopped by SIGKILL, SIGTERM and SIGINT (serial and on 2 processes) and resumed.

Each run is a real ``fenics-contact run`` process, stopped once a few load
steps are in summary.json. The output is then read by h5py, meshio and
VTK in a separate interpreter (tests/read_solution.py) and compared with an
uninterrupted run of the same scene; the resumed run must repeat the
uninterrupted run's Newton iterations and fields.
"""

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).parent.parent
READER = Path(__file__).parent / "read_solution.py"
STEPS = 12
FIELDS = ["active", "contact_pressure", "displacement", "gap", "von_mises"]
MPIEXEC = next(
    (str(p) for p in (Path(sys.executable).parent / "mpiexec", shutil.which("mpiexec") or "")
     if str(p) and Path(p).is_file()),
    None,
)
ENV = {**os.environ, "PYTHONPATH": str(ROOT), "OMP_NUM_THREADS": "1"}
CLI = [sys.executable, "-c", "import sys; from fenics_contact.cli import main; sys.exit(main())"]


def command(*args, processes=1):
    launcher = [MPIEXEC, "-n", str(processes)] if processes > 1 else []
    return [*launcher, *CLI, *map(str, args)]


def summary(out):
    return json.loads((out / "summary.json").read_text())


def finished_steps(out):
    try:
        return summary(out)["steps_completed"]
    except (OSError, ValueError, KeyError):
        return 0


def stop_after(scene, out, steps, signum, processes=1):
    """Start a run, send ``signum`` once ``steps`` load steps are done; (rc, stderr lines)."""
    proc = subprocess.Popen(
        command("run", scene, "--out", out, "--quiet", "--no-pictures", processes=processes),
        env=ENV, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )
    deadline = time.monotonic() + 300
    while finished_steps(out) < steps:
        assert proc.poll() is None, proc.communicate()[1]
        assert time.monotonic() < deadline
        time.sleep(0.02)
    proc.send_signal(signum)
    _, err = proc.communicate(timeout=300)
    lines = [line for line in err.splitlines() if not line.startswith("[mpiexec@")]
    return proc.returncode, lines


def read(out, reference=None):
    args = [sys.executable, str(READER), str(out / "solution.xdmf")]
    if reference is not None:
        args.append(str(reference / "solution.xdmf"))
    done = subprocess.run(args, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    """The 3D block of scenes/ in 12 load steps (about 0.1-0.3 s each)."""
    folder = tmp_path_factory.mktemp("scene")
    text = (ROOT / "scenes" / "block_3d.toml").read_text()
    path = folder / "block.toml"
    path.write_text(text.replace("steps = 6", f"steps = {STEPS}"))
    return path


@pytest.fixture(scope="module")
def reference(scene, tmp_path_factory):
    """The uninterrupted run (with pictures)."""
    out = tmp_path_factory.mktemp("reference")
    done = subprocess.run(
        command("run", scene, "--out", out, "--quiet"), env=ENV, cwd=ROOT,
        capture_output=True, text=True, timeout=600,
    )
    assert done.returncode == 0, done.stderr
    assert summary(out)["steps_completed"] == STEPS
    return out


def assert_readable_steps(out, reference, expected):
    """Steps 1..expected are on disk with every field, equal to the reference's."""
    report = read(out, reference)
    times = [(k + 1) / STEPS for k in range(expected)]
    for reader in ("h5py", "meshio", "vtk"):
        assert [s["t"] for s in report[reader]] == pytest.approx(times), reader
    for step in report["h5py"]:
        assert set(FIELDS) <= set(step["datasets"])
        assert all(d["shape_ok"] and d["finite"] for d in step["datasets"].values())
    for step in report["meshio"] + report["vtk"]:
        assert step["fields"] == FIELDS and step["finite"]
    for step in report["meshio"]:
        assert max(step["difference"].values()) <= 1e-10, step
    return report


def assert_resume_repeats_reference(scene, out, reference, processes=1, pictures=False):
    args = ["run", scene, "--resume", out, "--quiet"] + ([] if pictures else ["--no-pictures"])
    done = subprocess.run(
        command(*args, processes=processes), env=ENV, cwd=ROOT, capture_output=True,
        text=True, timeout=600,
    )
    assert done.returncode == 0, done.stderr
    resumed, full = summary(out), summary(reference)
    assert resumed["status"] == "converged" and resumed["steps_completed"] == STEPS
    assert [s["iterations"] for s in resumed["steps"]] == [s["iterations"] for s in full["steps"]]
    assert sum(s["iterations"] for s in full["steps"]) > 20  # the comparison means something
    assert_readable_steps(out, reference, STEPS)


def test_sigkill_leaves_every_finished_step_readable_and_resumable(scene, reference, tmp_path):
    out = tmp_path / "killed"
    rc, _ = stop_after(scene, out, 3, signal.SIGKILL)
    assert rc == -signal.SIGKILL
    on_disk = len(read(out)["meshio"])
    assert 3 <= on_disk < STEPS  # killed in the middle of the path
    assert_readable_steps(out, reference, on_disk)
    assert_resume_repeats_reference(scene, out, reference)


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_signal_stops_cleanly_with_one_line(scene, reference, tmp_path, signum):
    out = tmp_path / "stopped"
    rc, err = stop_after(scene, out, 2, signum)
    assert rc == 128 + signum
    assert len(err) == 1, err
    done = summary(out)
    assert done["status"] == "interrupted"
    k = done["steps_completed"]
    assert 2 <= k < STEPS
    assert done["message"] == (f"stopped by {signal.Signals(signum).name} after {k} finished "
                               "load steps; continue with --resume")
    assert err[0] == (
        f"fenics-contact: stopped by {signum.name} after {k} of {STEPS} load steps; "
        f"steps 1-{k} are in {out}/solution.xdmf; resume with: "
        f"fenics-contact run {scene} --resume {out}"
    )
    assert_readable_steps(out, reference, k)
    if signum == signal.SIGTERM:
        assert_resume_repeats_reference(scene, out, reference)


@pytest.mark.skipif(MPIEXEC is None, reason="no mpiexec")
@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_signal_stops_two_processes_cleanly(scene, reference, tmp_path, signum):
    out = tmp_path / "stopped"
    rc, err = stop_after(scene, out, 2, signum, processes=2)
    assert rc == 128 + signum
    assert len(err) == 1 and "Traceback" not in err[0], err
    k = summary(out)["steps_completed"]
    assert err[0].endswith(f"resume with: mpiexec -n 2 fenics-contact run {scene} --resume {out}")
    assert f"after {k} of {STEPS} load steps" in err[0]
    assert_readable_steps(out, reference, k)
    if signum == signal.SIGTERM:  # resumed on 2 processes, pictures drawn as in serial
        assert_resume_repeats_reference(scene, out, reference, processes=2, pictures=True)
        import matplotlib.image

        mine = matplotlib.image.imread(out / "deformed.png")
        serial = matplotlib.image.imread(reference / "deformed.png")
        assert mine.shape == serial.shape
        changed = np.abs(mine - serial).sum(axis=-1) > 0.1
        assert changed.mean() < 0.01  # the same picture up to a few edge pixels
        assert (out / "residuals.png").stat().st_size > 5_000


def test_checkpoint_of_another_run_is_refused(scene, reference, tmp_path):
    out = tmp_path / "copy"
    shutil.copytree(reference, out)
    before = (out / "solution.xdmf").read_text()
    text = scene.read_text()
    cases = {
        "mesh.cells": text.replace("cells = [8, 8, 4]", "cells = [8, 8, 5]"),
        "solver.method": text.replace('method = "gnrm"', 'method = "nua"'),
        "solver.steps": text.replace(f"steps = {STEPS}", "steps = 6"),
        "E": text.replace("E = 10.0", "E = 11.0"),
    }
    for key, changed in cases.items():
        other = tmp_path / f"{key}.toml"
        other.write_text(changed)
        done = subprocess.run(
            command("run", other, "--resume", out, "--quiet"), env=ENV, cwd=ROOT,
            capture_output=True, text=True, timeout=300,
        )
        assert done.returncode == 2, (key, done.stderr)
        err = done.stderr.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("fenics-contact: error: The checkpoint in")
        assert f"{key}: checkpoint" in err[0]
    if MPIEXEC is not None:
        done = subprocess.run(
            command("run", scene, "--resume", out, "--quiet", processes=2), env=ENV, cwd=ROOT,
            capture_output=True, text=True, timeout=300,
        )
        assert done.returncode == 2
        assert "processes: checkpoint 1, now 2" in done.stderr
    done = subprocess.run(
        command("run", scene, "--resume", tmp_path / "nothing", "--quiet"), env=ENV, cwd=ROOT,
        capture_output=True, text=True, timeout=300,
    )
    assert done.returncode == 2 and "No checkpoint in" in done.stderr
    assert (out / "solution.xdmf").read_text() == before  # a refused resume writes nothing


def _rank_pids(launcher_pid: int) -> list[int]:
    """Process ids of the Python ranks below an mpiexec (its descendants running this CLI)."""
    children: dict[int, list[int]] = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        children.setdefault(int(fields[1]), []).append(int(stat.parent.name))
    found, todo = [], [launcher_pid]
    while todo:
        pid = todo.pop()
        for child in children.get(pid, []):
            todo.append(child)
            try:
                cmdline = (Path("/proc") / str(child) / "cmdline").read_bytes()
            except OSError:
                continue
            if b"fenics_contact.cli" in cmdline:
                found.append(child)
    return sorted(found)


@pytest.mark.skipif(MPIEXEC is None, reason="needs mpiexec")
def test_one_killed_rank_stops_the_others(scene, reference, tmp_path):
    """SIGKILL one of two ranks: the other must not hang in a collective call.

    MPICH's mpiexec ends the remaining ranks when one dies; the bound below is
    a guard against a hang, not a timing measurement.
    """
    out = tmp_path / "rank-killed"
    proc = subprocess.Popen(
        command("run", scene, "--out", out, "--quiet", "--no-pictures", processes=2),
        env=ENV, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )
    deadline = time.monotonic() + 300
    while finished_steps(out) < 3:
        assert proc.poll() is None, proc.communicate()[1]
        assert time.monotonic() < deadline
        time.sleep(0.02)
    ranks = _rank_pids(proc.pid)
    assert len(ranks) == 2, ranks
    os.kill(ranks[-1], signal.SIGKILL)
    try:
        proc.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.communicate()
        pytest.fail("the surviving rank hung after its partner was killed")
    assert proc.returncode != 0
    for pid in ranks:  # no orphaned rank left running
        assert not Path(f"/proc/{pid}").exists() or "Z" in Path(
            f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    on_disk = len(read(out)["meshio"])
    assert 3 <= on_disk < STEPS
    assert_readable_steps(out, reference, on_disk)


def test_sigterm_stops_cleanly_after_gmsh_has_meshed_the_scene(tmp_path):
    """gmsh resets the process's signal handling; the run installs its handler again."""
    text = (ROOT / "scenes" / "tube_crush.toml").read_text()  # a .geo mesh, 50 load steps
    scene = tmp_path / "tube.toml"
    scene.write_text(text.replace('"../meshes/', f'"{ROOT}/meshes/'))
    out = tmp_path / "stopped"
    rc, err = stop_after(scene, out, 3, signal.SIGTERM)
    assert rc == 128 + signal.SIGTERM, err
    assert len(err) == 1 and err[0].startswith("fenics-contact: stopped by SIGTERM after "), err
    assert summary(out)["status"] == "interrupted"
