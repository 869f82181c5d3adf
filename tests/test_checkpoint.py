"""Checkpoints, the per-step XDMF index and the gathered picture grid, in process."""

from pathlib import Path

import numpy as np
import pytest

from mpi4py import MPI

from fenics_contact.output.checkpoint import (
    CheckpointError,
    CheckpointWriter,
    identity,
    read_latest,
    restore,
)
from fenics_contact.output.xdmf import StepWriter, finished_steps
from fenics_contact.scene.build import build_problem
from fenics_contact.scene.schema import load_scene
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.predictor import Extrapolated

SCENES = Path(__file__).parent.parent / "scenes"
COMM = MPI.COMM_WORLD


def shared(tmp_path):
    return Path(COMM.bcast(str(tmp_path), root=0))


def scene_file(folder, name, text):
    path = folder / name
    if COMM.rank == 0:
        path.write_text(text)
    COMM.Barrier()
    return load_scene(path)


@pytest.mark.mpi
def test_checkpoint_round_trip_and_moved_mesh_refused(tmp_path):
    folder = shared(tmp_path)
    text = (SCENES / "paper_ex2.toml").read_text()
    scene = scene_file(folder, "a.toml", text)
    problem = build_problem(scene, COMM)
    strategy = Extrapolated(make_strategy("gnrm", problem, SolverSettings()))
    for t in (0.1, 0.2):
        problem.set_load(t)
        assert strategy.solve().converged
    writer = CheckpointWriter(folder / "checkpoint", problem, identity(scene, COMM.size),
                              fresh=True)
    writer.write(2, [{"step": 1}, {"step": 2}], strategy.history)

    again = build_problem(scene, COMM)
    marker = read_latest(folder / "checkpoint", identity(scene, COMM.size))
    saved = restore(folder / "checkpoint", again, marker)
    assert saved.step == 2 and again.load_factor == pytest.approx(0.2, abs=0)
    assert np.array_equal(again.u.x.array, problem.u.x.array)  # ghosts included
    assert np.array_equal(again.lam.x.array, problem.lam.x.array)
    assert np.abs(problem.lam.x.array).max() > 0  # in contact: the multiplier is saved
    assert [h[0] for h in saved.history] == [0.1, 0.2]
    for (_, u0, l0), (_, u1, l1) in zip(saved.history, strategy.history, strict=True):
        assert np.array_equal(u0, u1) and np.array_equal(l0, l1)

    # the same numbers of DOFs on a shifted bar: refused by the DOF coordinates
    moved = scene_file(folder, "b.toml", text.replace("origin = [-3.0, 0.0]",
                                                      "origin = [-2.9, 0.0]"))
    with pytest.raises(CheckpointError, match="the mesh changed"):
        restore(folder / "checkpoint", build_problem(moved, COMM), marker)
    with pytest.raises(CheckpointError, match=r"mesh.origin: checkpoint \[-3.0, 0.0\], now \[-2.9"):
        read_latest(folder / "checkpoint", identity(moved, COMM.size))


@pytest.mark.mpi
def test_step_writer_continues_an_index_and_refuses_missing_steps(tmp_path):
    folder = shared(tmp_path)
    problem = build_problem(load_scene(SCENES / "paper_ex2.toml"), COMM)
    index = folder / "solution.xdmf"
    writer = StepWriter(problem, index)
    for t in (0.1, 0.2, 0.3):
        writer.write(t)
    assert finished_steps(index) == [1, 2, 3]
    writer = StepWriter(problem, index, first_step=3)  # step 3 is dropped, 1-2 kept
    assert finished_steps(index) == [1, 2]
    if COMM.rank == 0:
        assert index.read_text().count("<Time ") == 2
    writer.write(0.25)
    assert finished_steps(index) == [1, 2, 3]
    if COMM.rank == 0:
        assert index.read_text().count("<Time ") == 3 and 'Value="0.25"' in index.read_text()
        (folder / "solution" / "step_0002.h5").unlink()
    COMM.Barrier()
    with pytest.raises(ValueError, match=r"step\(s\) \[2\] are missing"):
        StepWriter(problem, index, first_step=4)


@pytest.mark.mpi
def test_picture_grid_is_the_whole_deformed_body_on_rank_0():
    from fenics_contact.output.pictures import _gathered_grid

    problem = build_problem(load_scene(SCENES / "paper_ex2.toml"), COMM)
    problem.u.interpolate(lambda x: np.vstack([0.1 * x[0], 0.0 * x[1]]))
    grid = _gathered_grid(problem)
    if COMM.rank != 0:
        assert grid is None
        return
    assert grid.n_cells == 12  # the 6 x 2 bar, every process's cells
    lo, hi = np.array(grid.bounds).reshape(3, 2).T
    assert lo[:2] == pytest.approx([-3.3, 0.0]) and hi[:2] == pytest.approx([3.3, 1.0])
    assert grid.point_data["contact pressure"].shape == (grid.n_points,)


class _Stop(Exception):
    """Stands for a run stopped after a given step."""


def _full_and_resumed(scene, tmp_path: Path, stop_after: int) -> tuple:
    """The uninterrupted run, and the run stopped after ``stop_after`` steps then resumed."""
    from fenics_contact.runner import run_scene

    full = run_scene(scene, tmp_path / "full", comm=MPI.COMM_SELF, pictures=False)

    def stop(step):
        if step.step == stop_after:
            raise _Stop

    with pytest.raises(_Stop):
        run_scene(scene, tmp_path / "part", comm=MPI.COMM_SELF, pictures=False, on_step=stop)
    resumed = run_scene(scene, tmp_path / "part", comm=MPI.COMM_SELF, pictures=False,
                        resume=True)
    assert full.path.converged and resumed.path.converged
    return full, resumed


@pytest.mark.parametrize(("method", "r"), [("gnrm", 1.0), ("penalty", 100.0)])
def test_a_resumed_frictional_run_repeats_the_uninterrupted_one(tmp_path, method, r):
    """Friction has a history: lam_t, the last converged u and the obstacle's frame.

    Stopped after step 6 of 10 (sticking and slipping nodes on the plane),
    the resumed run must repeat every step of the uninterrupted one: the
    same iterations and the same numbers to the last bit. (Without lam_t in
    the checkpoint GNRM took 5 iterations at step 7 instead of 3; without
    the obstacle's committed position the penalty method's regularised
    stick traction jumped, F_t 5.51 instead of 5.19 at step 7.)
    """
    import dataclasses

    scene = load_scene(SCENES / "block_slide_friction.toml")
    scene = dataclasses.replace(
        scene, solver=dataclasses.replace(scene.solver, method=method, steps=10),
        contact=dataclasses.replace(scene.contact, r=r),
    )
    full, resumed = _full_and_resumed(scene, tmp_path, stop_after=6)
    assert [s.step for s in resumed.path.steps] == list(range(1, 11))
    for a, b in zip(full.path.steps, resumed.path.steps, strict=True):
        assert (a.iterations, a.tangential_force, a.contact_force, a.stick_count) == (
            b.iterations, b.tangential_force, b.contact_force, b.stick_count), a.step
    assert np.array_equal(full.problem.u.x.array, resumed.problem.u.x.array)
    assert 0 < full.path.steps[6].stick_count  # step 7 has sticking nodes: the history counts


def test_a_resumed_run_keeps_the_active_set_predictors_gaps(tmp_path):
    """The active-set predictor chooses a step's first set from the last two states' gaps.

    Stopped after step 2 of 4, the resumed Hertz cylinder must repeat every
    step of the uninterrupted run to the last bit. (Without the gaps in the
    checkpoint the steps after the resume decided their set by the
    extrapolated lam + r g alone: 3 iterations instead of 1 at steps 3 and 4.)
    """
    scene = load_scene(SCENES / "hertz_cylinder.toml")
    assert scene.solver.predictor == "active-set"
    full, resumed = _full_and_resumed(scene, tmp_path, stop_after=2)
    assert [s.iterations for s in full.path.steps] == [s.iterations for s in resumed.path.steps]
    assert np.array_equal(full.problem.u.x.array, resumed.problem.u.x.array)


#: A thin ring crushed between two plates until its inner wall closes on itself at the
#: last step (self-contact; a node-to-segment pair with its facet hysteresis).
RING = """
[scene]
name = "ring"
dimension = 2

[mesh]
file = "{mesh}"
parameters = {{ "wall thickness" = 0.15, n_t = 4, n_q = 50 }}

[[body]]
name = "ring"
tag = "tube"
law = "neo-hookean"
E = 10.0
nu = 0.3

[[pair]]
name = "inner"
striker = "inner_top"
target = "inner_bottom"
self_contact = true

[[obstacle]]
name = "bottom"
type = "plane"
point = [0.0, -1.0]
normal = [0.0, 1.0]
motion = [0.0, 0.86]
tag = "outer_bottom"

[[obstacle]]
name = "top"
type = "plane"
point = [0.0, 1.0]
normal = [0.0, -1.0]
motion = [0.0, -0.86]
tag = "outer_top"

[[dirichlet]]
tag = "cut"
value = [0.0, "free"]

[solver]
method = "gnrm"
steps = 20
atol = 1e-10
"""


@pytest.mark.mpi
def test_a_resumed_self_contact_run_keeps_the_facets_its_nodes_hold(tmp_path):
    """A node-to-segment search keeps a node's facet while it stays about as close as the best.

    Stopped after step 18 of 20 (the ring's inner wall still open) and
    resumed, the run must repeat the uninterrupted one: the same Newton
    iterations at every step and the same fields. (Without the pairs'
    search state in the checkpoint the first search after the resume
    started from no facet, and the nodes at a vertex of two facets that tie
    took the other one: 60 iterations instead of 63 at the closing step 20
    in serial, u off by 9e-8; 117 instead of 63 when stopped after step 19.)
    """
    from fenics_contact.runner import run_scene

    folder = shared(tmp_path)
    mesh = Path(__file__).parent.parent / "meshes" / "tube_crush.geo"
    scene = scene_file(folder, "ring.toml", RING.format(mesh=mesh.as_posix()))
    full = run_scene(scene, folder / "full", comm=COMM, pictures=False)

    def stop(step):
        if step.step == 18:
            raise _Stop

    with pytest.raises(_Stop):
        run_scene(scene, folder / "part", comm=COMM, pictures=False, on_step=stop)
    resumed = run_scene(scene, folder / "part", comm=COMM, pictures=False, resume=True)
    assert full.path.converged and resumed.path.converged
    assert full.path.steps[-1].contacts["inner"]["active_count"] > 0  # the wall closed
    assert [s.iterations for s in full.path.steps] == [s.iterations for s in resumed.path.steps]
    pairs = [(full.problem.u, resumed.problem.u),
             *zip(full.problem.multipliers(), resumed.problem.multipliers(), strict=True)]
    for a, b in pairs:
        gap = COMM.allreduce(float(np.abs(a.x.array - b.x.array).max(initial=0.0)), op=MPI.MAX)
        assert gap <= 1e-10
