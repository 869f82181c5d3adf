"""A write that fails mid-run (disk full, folder removed, read-only) stops the run cleanly.

Faults are injected: a write in the output layer raises the OSError the
operating system would. The run must end with exit code 1 and one line
naming the file and the reason, on every process together (no hang), and
every step finished before must stay readable.
"""

import errno
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest

from mpi4py import MPI

import fenics_contact.output.checkpoint as checkpoint
import fenics_contact.output.xdmf as xdmf
from fenics_contact.cli import main

SCENES = Path(__file__).parent.parent / "scenes"
COMM = MPI.COMM_WORLD


def _scene(tmp_path) -> tuple[Path, Path]:
    folder = Path(COMM.bcast(str(tmp_path), root=0))
    scene = folder / "ex2.toml"
    if COMM.rank == 0:
        text = (SCENES / "paper_ex2.toml").read_text().replace("steps = 10", "steps = 5")
        scene.write_text(text + "\n[output]\npictures = false\n")
    COMM.Barrier()
    return scene, folder / "out"


def _readable_steps(out: Path) -> list[int]:
    """The steps the index names, each opened whole with h5py."""
    steps = xdmf.finished_steps(out / "solution.xdmf")
    for k in steps:
        with h5py.File(out / "solution" / f"step_{k:04d}.h5", "r") as f:
            assert np.all(np.isfinite(f["Function/displacement"][next(iter(
                f["Function/displacement"]))][()]))
    return steps


def _fail_on_step(monkeypatch, module, name: str, step: int, error: OSError, rank=None):
    """Make ``module.name`` raise ``error`` from its ``step``-th call on (on ``rank`` only)."""
    real = getattr(module, name)
    calls = {"n": 0}

    def failing(*args, **kwargs):
        calls["n"] += 1
        if calls["n"] >= step and (rank is None or COMM.rank == rank):
            raise error
        return real(*args, **kwargs)

    monkeypatch.setattr(module, name, failing)


@pytest.mark.mpi
@pytest.mark.parametrize(("where", "error", "words"), [
    ("checkpoint", OSError(errno.ENOSPC, "No space left on device", "rank_0000.npz"),
     "cannot write rank_0000.npz (No space left on device)"),
    ("index", OSError(errno.EROFS, "Read-only file system", "solution.xdmf"),
     "cannot write solution.xdmf (Read-only file system)"),
])
def test_write_failure_stops_every_process_with_one_line(tmp_path, monkeypatch, capfd, where,
                                                          error, words):
    scene, out = _scene(tmp_path)
    if where == "checkpoint":  # one process's own file: the others must not wait for it
        _fail_on_step(monkeypatch, checkpoint.np, "savez", 3, error, rank=COMM.size - 1)
    else:  # rank 0's index
        _fail_on_step(monkeypatch, xdmf, "write_index", 3, error)
    code = main(["run", str(scene), "--out", str(out), "--quiet"])
    assert code == 1
    err = capfd.readouterr().err.strip().splitlines()
    if COMM.rank == 0:
        assert len(err) == 1, err
        assert err[0] == (f"fenics-contact: {words}; the run stopped in load step 3; "
                          f"steps 1-2 are in {out}/solution.xdmf")
        steps = _readable_steps(out)
        assert steps[:2] == [1, 2]
    COMM.Barrier()


def test_output_folder_removed_mid_run(tmp_path, monkeypatch, capsys):
    scene, out = _scene(tmp_path)
    real = xdmf.StepWriter.write

    def remove_then_write(self, t):
        if self.step == 3:
            shutil.rmtree(out)
        return real(self, t)

    monkeypatch.setattr(xdmf.StepWriter, "write", remove_then_write)
    assert main(["run", str(scene), "--out", str(out), "--quiet"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith(f"fenics-contact: cannot write {out}/solution.xdmf (the files "
                             "of step(s) [1, 2] were removed during the run)")
    assert "the run stopped in load step 3" in err[0]
