# %% [markdown]
# # A 3D scene with the iterative linear solver, on several processes
#
# This demo illustrates how to:
#
# - solve a finite-strain 3D contact scene (`scenes/block_3d.toml`: a
#   neo-Hookean block of hexahedra, clamped on top, into which a rigid ball
#   is pushed from below) with GNRM;
# - choose the iterative linear solver (GMRES with a Schur-complement field
#   split and algebraic multigrid) instead of the direct one (MUMPS), from the
#   scene (`[solver] linear_solver = "iterative"`) or from Python
#   (`LinearSolverSettings(kind="iterative")`);
# - run it under MPI: `mpiexec -n 2 python demos/block_3d_iterative.py`.
#
# ## The formulation
#
# The block's strain energy is compressible neo-Hookean,
#
# $$ \Psi(\mathbf F) = \frac\mu2\left(I_1 - 3\right) - \mu \ln J
# + \frac\lambda2 (\ln J)^2, \qquad I_1 = \operatorname{tr}\mathbf F^\top\mathbf F,
# \quad J = \det\mathbf F, $$
#
# and the gap to the ball (centre $\mathbf c$, radius $\rho$) is measured in the
# current configuration, $g(\mathbf x) = |\mathbf x - \mathbf c| - \rho$, with
# $\mathbf x = \mathbf X + \mathbf u$. The Alart-Curnier term
# $\int \frac1{2r}[\min(\lambda + r g, 0)^2 - \lambda^2]$ on the candidate
# facets (the block's base) and GNRM's Newton steps on $(\mathbf u, \lambda)$
# give, at every iteration, the saddle-point system
#
# $$ \begin{bmatrix} K & B^\top \\ C & D \end{bmatrix}
# \begin{bmatrix} \delta\mathbf u \\ \delta\lambda \end{bmatrix} =
# -\begin{bmatrix} R_u \\ R_\lambda \end{bmatrix}, $$
#
# with $C = rB$ on the active nodes and $D$ diagonal (the lumped multiplier
# block) on the inactive ones. The iterative solver is right-preconditioned
# GMRES with a Schur field split: GAMG, with the rigid body modes as its near
# null space, on $K$, and the Schur complement $S \approx D - C\,
# \mathrm{diag}(K)^{-1} B^\top$, which lives on the contact surface only,
# factorised exactly. Its tolerance is tight, so Newton sees the same steps
# as with the direct solver: the demo checks that.

# %%
from __future__ import annotations

import argparse
import dataclasses
import os
import time
from pathlib import Path

import fenics_contact  # noqa: F401  (loads the DOLFINx wheel's MPI libraries: first)

# isort: split
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from mpi4py import MPI

from fenics_contact import (
    LinearSolverSettings,
    SolverSettings,
    build_problem,
    load_scene,
    make_strategy,
    solve_load_path,
)
from fenics_contact.output.io import write_json
from fenics_contact.solvers.diagnostics import signorini_report

parser = argparse.ArgumentParser(description="3D contact with the iterative solver under MPI")
parser.add_argument("--out", type=Path, default=Path("results/block-3d-iterative"))
parser.add_argument(
    "--scene", type=Path,
    default=Path(__file__).resolve().parents[1] / "scenes" / "block_3d.toml",
)
args, _ = parser.parse_known_args()  # tolerate notebook kernel arguments
comm = MPI.COMM_WORLD
root = comm.rank == 0


def say(*text: object) -> None:
    """Print once, on rank 0."""
    if root:
        print(*text, flush=True)


# %% [markdown]
# ## The scene
#
# The shipped block has 8 x 8 x 4 hexahedra; this demo refines it to
# 16 x 16 x 8 (about 7000 displacement unknowns) unless `CI` is set.

# %%
scene = load_scene(args.scene)
if not os.environ.get("CI"):
    scene = dataclasses.replace(scene, mesh=dataclasses.replace(scene.mesh, cells=(16, 16, 8)))
say(f"{comm.size} process(es), mesh {'x'.join(map(str, scene.mesh.cells))} hexahedra, "
    f"{scene.solver.steps} load steps")

# %% [markdown]
# ## Solve with each linear solver
#
# The same scene, built twice, solved by GNRM with the direct and with the
# iterative linear solver.

# %%
runs = {}
for kind in ("direct", "iterative"):
    problem = build_problem(scene, comm)
    strategy = make_strategy("gnrm", problem, SolverSettings(atol=1e-10, rtol=1e-12),
                             linear=LinearSolverSettings(kind=kind))
    start = time.perf_counter()
    path = solve_load_path(strategy, scene.solver.steps)
    wall = comm.allreduce(time.perf_counter() - start, op=MPI.MAX)
    if not path.converged:
        raise RuntimeError(f"{kind}: the load path stopped ({path.status})")
    state = problem.contact_state()
    kkt = signorini_report(state.gap, state.pressure, comm)
    runs[kind] = {
        "iterations_per_step": [s.iterations for s in path.steps],
        "residuals": [s.residuals[-1] for s in path.steps],
        "active_nodes": path.steps[-1].active_count,
        "contact_force": state.contact_force,
        "max_penetration": state.max_penetration,
        "wall_s": wall,
        "displacement_dofs": problem.V.dofmap.index_map.size_global * problem.V.dofmap.index_map_bs,
        "multiplier_dofs": problem.surface.num_dofs,
        "signorini": {"min_gap": kkt.min_gap, "max_pressure": kkt.max_pressure,
                      "max_complementarity": kkt.max_complementarity},
    }
direct, iterative = runs["direct"], runs["iterative"]
say(f"displacement dofs {direct['displacement_dofs']}, multiplier dofs {direct['multiplier_dofs']}")
say(f"{'solver':<10} {'Newton per step':<24} {'force':>10} {'active':>6} {'wall s':>7}")
for kind, run in runs.items():
    say(f"{kind:<10} {run['iterations_per_step']!s:<24} {run['contact_force']:>10.6f} "
        f"{run['active_nodes']:>6} {run['wall_s']:>7.2f}")
force_difference = abs(iterative["contact_force"] / direct["contact_force"] - 1)
say(f"relative force difference {force_difference:.1e}; "
    f"max penetration {iterative['max_penetration']:.1e}")

# %% [markdown]
# ## Residual histories
#
# The last load step's Newton residuals with each solver: the same quadratic
# convergence.

# %%
if root:
    args.out.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(6, 4))
    for (kind, run), style in zip(runs.items(), ("o-", "x--"), strict=True):
        history = run["residuals"][-1]
        ax.semilogy(range(len(history)), history, style, label=kind)
    ax.set_xlabel("Newton iteration (last load step)")
    ax.set_ylabel("residual")
    ax.set_title(f"block_3d on {comm.size} process(es)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.out / "residuals.png", dpi=120)
    plt.close(fig)
    write_json(args.out / "summary.json", {
        "mpi_ranks": comm.size, "cells": list(scene.mesh.cells),
        "force_difference": force_difference, "runs": runs,
    })
say(f"\nWrote {args.out}/summary.json and residuals.png")
