"""The demos run as they are (serially, and on 2 ranks under `make test`)."""

import json
import runpy
import sys
from pathlib import Path

import pytest

from mpi4py import MPI

DEMOS = Path(__file__).parent.parent / "demos"


def run_demo(name, out, monkeypatch):
    monkeypatch.setattr(sys, "argv", [name, "--out", str(out)])
    runpy.run_path(str(DEMOS / name), run_name="__main__")


def shared_tmp(tmp_path):
    """One folder for all ranks (rank 0's tmp_path)."""
    return Path(MPI.COMM_WORLD.bcast(str(tmp_path), root=0))


@pytest.mark.mpi
def test_paper_example2_demo(tmp_path, monkeypatch):
    out = shared_tmp(tmp_path)
    run_demo("paper_example2.py", out, monkeypatch)
    MPI.COMM_WORLD.Barrier()
    summary = json.loads((out / "summary.json").read_text())
    runs = summary["runs"]
    assert [run["status"] for run in runs] == ["converged"] * 5
    assert [run["iterations"] for run in runs][:4] == [40, 40, 40, 40]
    assert max(run["error"] for run in runs) < 1e-10


@pytest.mark.mpi
def test_hertz_cylinder_demo(tmp_path, monkeypatch):
    out = shared_tmp(tmp_path)
    run_demo("hertz_cylinder.py", out, monkeypatch)
    MPI.COMM_WORLD.Barrier()
    summary = json.loads((out / "summary.json").read_text())
    assert summary["solver"]["mpi_ranks"] == MPI.COMM_WORLD.size
    assert all(abs(e) < 0.02 for e in summary["relative_error"].values())
    assert (out / "pressure.png").stat().st_size > 10_000
