"""Record and draw a squeezed section step by step (used by o_ring.py and tube_crush.py).

A frame is one converged load step: the deformed mesh (serial), every
contact's deformed nodes and nodal pressure (lam <= 0; drawn as its
magnitude), and each contact's normal force. Pictures are drawn with
matplotlib (Agg), the section mirrored about x = 0 when it is a half model.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from mpi4py import MPI

import fenics_contact  # noqa: F401  (before dolfinx)
from fenics_contact.runner import scene_strategy
from fenics_contact.scene.build import build_problem
from fenics_contact.scene.schema import Scene
from fenics_contact.solvers.stepping import solve_load_path


@dataclass
class Frame:
    """One converged step: load factor, deformed nodes, cells and contact data."""

    t: float
    x: np.ndarray
    cells: np.ndarray
    contacts: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)
    forces: dict[str, float] = field(default_factory=dict)
    penetration: dict[str, float] = field(default_factory=dict)


def squeeze(scene: Scene) -> tuple[object, object, list[Frame]]:
    """Solve ``scene`` serially; return the problem, the run record and every step's frame."""
    problem = build_problem(scene, MPI.COMM_SELF)
    strategy = scene_strategy(scene, problem)  # the scene's [solver], as `run` has it
    domain = problem.domain
    gdim = domain.geometry.dim
    cells = domain.geometry.dofmaps[0]
    frames: list[Frame] = []
    V = problem.V
    node_block = np.full(domain.geometry.x.shape[0], -1, np.int64)
    node_block[cells.reshape(-1)] = V.dofmap.list.reshape(-1)

    def record(step) -> None:
        u = problem.u.x.array.reshape(-1, gdim)[node_block]
        frame = Frame(step.load_factor, domain.geometry.x[:, :gdim] + u, cells.copy())
        for c in problem.contacts:
            state = c.contact_state()
            X = c.nodal_coordinates()[:, :gdim]
            blocks = [int(np.argmin(np.linalg.norm(domain.geometry.x[:, :gdim] - p, axis=1)))
                      for p in X]
            frame.contacts[c.name] = (frame.x[blocks], np.asarray(state.pressure))
            frame.forces[c.name] = state.contact_force
            frame.penetration[c.name] = state.max_penetration
        frames.append(frame)

    path = solve_load_path(strategy, scene.solver.steps, max_cutbacks=scene.solver.max_cutbacks,
                           on_step=record)
    return problem, path, frames


def draw(frames: list[Frame], path: Path, *, mirror: bool, title: str, labels: list[str],
         curve: tuple[np.ndarray, list[tuple[np.ndarray, str]], str, str] | None = None,
         log: bool = False) -> None:
    """Deformed sections side by side, the contact nodes coloured by |pressure|, and a curve."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.tri import Triangulation

    n = len(frames) + (curve is not None)
    fig, axes = plt.subplots(1, n, figsize=(3.2 * n, 3.6))
    peak = max(float(np.max(-p, initial=0.0)) for f in frames for _, p in f.contacts.values())
    scatter = None
    for ax, frame, label in zip(axes, frames, labels, strict=False):
        sides = (1.0, -1.0) if mirror else (1.0,)
        for s in sides:
            tri = Triangulation(s * frame.x[:, 0], frame.x[:, 1], frame.cells)
            ax.triplot(tri, color="0.75", lw=0.3)
            for x, p in frame.contacts.values():
                on = p < 0
                scatter = ax.scatter(s * x[on, 0], x[on, 1], c=-p[on], s=8, cmap="viridis",
                                     vmin=0.0, vmax=peak, zorder=3)
        ax.set_aspect("equal")
        ax.set_title(label, fontsize=9)
        ax.axis("off")
    if scatter is not None:
        fig.colorbar(scatter, ax=axes[: len(frames)], shrink=0.7, label="contact pressure")
    if curve is not None:
        ax = axes[-1]
        x, series, xlabel, ylabel = curve
        for y, name in series:
            ax.plot(x, y, "o-" if "FE" in name else "--", label=name, ms=3)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        if log:
            ax.set_yscale("log")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
    fig.suptitle(title, fontsize=10)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=130, bbox_inches="tight")
    plt.close(fig)
