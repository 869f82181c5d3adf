"""Pictures of the trade-off and stability sweeps (matplotlib, Agg backend)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import ListedColormap
from matplotlib.ticker import NullFormatter

from fenics_contact.output.plotting import save_figure
from fenics_contact.solvers import PAPER_NAMES
from fenics_contact.sweeps.stability import OFF_REFERENCE, CaseRecord
from fenics_contact.sweeps.tradeoff import ERROR_FLOOR, TradeoffRecord

#: Colour of each outcome in the stability table (a status, or converged off the reference).
STATUS_COLOURS = {
    "converged": "#7fc97f",
    OFF_REFERENCE: "#80b1d3",
    "max_iterations": "#fdc086",
    "cycling": "#ffff99",
    "diverged": "#f0027f",
    "nonfinite": "#bf5b17",
    "error": "#666666",
}
MARKERS = ("o", "s", "^", "D", "v")


def _drawn(error: float) -> float:
    """Where an error sits on a log axis: at ERROR_FLOOR when smaller (0 too)."""
    return max(error, ERROR_FLOOR)


def time_label(recs: Sequence[TradeoffRecord]) -> str:
    """The time axis' label: a median only where a point was timed more than once."""
    repeats = max((r.repeats for r in recs if r.status == "converged"), default=1)
    runs = f", median of {repeats} runs" if repeats > 1 else ""
    return f"wall time, whole load path (s{runs})"


def _panel(ax: plt.Axes, recs: Sequence[TradeoffRecord], field: str, front: str) -> None:
    """Error against time, one colour a method, one marker a mesh; front joined.

    Errors below ERROR_FLOOR (0 too) are drawn on it, a dotted line that the
    legend names.
    """
    meshes = list(dict.fromkeys(r.mesh for r in recs))
    methods = list(dict.fromkeys(r.method for r in recs))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    floored = False
    for m, method in enumerate(methods):
        for k, mesh in enumerate(meshes):
            pts = [r for r in recs if r.method == method and r.mesh == mesh
                   and r.status == "converged" and math.isfinite(getattr(r, field))]
            if not pts:
                continue
            floored |= any(getattr(r, field) < ERROR_FLOOR for r in pts)
            ax.loglog(
                [r.wall_s for r in pts], [_drawn(getattr(r, field)) for r in pts],
                MARKERS[k % len(MARKERS)], color=colours[m % len(colours)], ms=5, alpha=0.8,
                label=f"{PAPER_NAMES.get(method, method)}" if k == 0 else None,
            )
    groups = meshes if front == "pareto_u" else [None]
    for mesh in groups:
        pts = sorted(
            (r for r in recs if getattr(r, front) and (mesh is None or r.mesh == mesh)),
            key=lambda r: r.wall_s,
        )
        if pts:
            ax.loglog([r.wall_s for r in pts], [_drawn(getattr(r, field)) for r in pts],
                      "-", color="k", lw=1, zorder=0)
            ax.loglog([r.wall_s for r in pts], [_drawn(getattr(r, field)) for r in pts],
                      "o", mfc="none", mec="k", ms=10, mew=1.2)
    for k, mesh in enumerate(meshes):
        ax.plot([], [], MARKERS[k % len(MARKERS)], color="grey", label=f"mesh {mesh}")
    ax.plot([], [], "o", mfc="none", mec="k", ms=10, label="Pareto front")
    if floored:
        ax.axhline(ERROR_FLOOR, color="grey", ls=":", lw=1, zorder=0,
                   label=f"error < {ERROR_FLOOR:g} (0 too), drawn at {ERROR_FLOOR:g}")
    ax.xaxis.set_minor_formatter(NullFormatter())  # decade labels only: no overlap
    ax.set_xlabel(time_label(recs))
    ax.legend(fontsize=7, ncol=2)


def tradeoff_figure(records: Sequence[TradeoffRecord]) -> plt.Figure:
    """One panel per case (displacement error vs time), plus Hertz peak error vs time.

    A case is a scene, or a friction scene at one Coulomb coefficient.
    """
    panels: list[tuple[str, str, str]] = []
    for case in dict.fromkeys(r.case for r in records):
        panels.append((case, "u_error", "pareto_u"))
        if any(math.isfinite(r.p0_error) for r in records if r.case == case):
            panels.append((case, "p0_error", "pareto_p0"))
    fig, axes = plt.subplots(1, len(panels), figsize=(5.2 * len(panels), 4.4), squeeze=False)
    for ax, (case, field, front) in zip(axes[0], panels, strict=True):
        _panel(ax, [r for r in records if r.case == case], field, front)
        what = ("displacement error vs tight GNRM (rel. L2)" if field == "u_error"
                else "peak-pressure error vs Hertz (rel.)")
        ax.set_ylabel(what)
        ax.set_title(f"{case}: {'per mesh' if front == 'pareto_u' else 'all meshes'}", fontsize=9)
    return fig


def tradeoff_plot(records: Sequence[TradeoffRecord], path: Path) -> None:
    """Write :func:`tradeoff_figure` to ``path``."""
    save_figure(tradeoff_figure(records), path)


def stability_plot(records: Sequence[CaseRecord], path: Path) -> None:
    """Write :func:`stability_figure` to ``path``."""
    save_figure(stability_figure(records), path)


def stability_figure(records: Sequence[CaseRecord]) -> plt.Figure:
    """Case x method table coloured by outcome, with the Newton iterations written in.

    A converged run that missed the reference has its own colour, and its
    deviation written in.
    """
    cases = list(dict.fromkeys(r.case for r in records))
    methods = list(dict.fromkeys(r.method for r in records))
    statuses = list(STATUS_COLOURS)
    grid = np.full((len(cases), len(methods)), np.nan)
    text: dict[tuple[int, int], str] = {}
    for rec in records:
        i, j = cases.index(rec.case), methods.index(rec.method)
        outcome = rec.outcome
        grid[i, j] = statuses.index(outcome) if outcome in statuses else len(statuses) - 1
        note = str(rec.iterations)
        if outcome == OFF_REFERENCE:
            note += f" off {rec.reference_deviation:.0e}"
        elif outcome != "converged":
            note += f" {outcome.replace('max_iterations', 'max it')}"
        text[(i, j)] = note
    fig, ax = plt.subplots(figsize=(2.0 + 1.45 * len(methods), 0.9 + 0.26 * len(cases)))
    cmap = ListedColormap([STATUS_COLOURS[s] for s in statuses])
    ax.imshow(grid, cmap=cmap, vmin=-0.5, vmax=len(statuses) - 0.5, aspect="auto")
    for (i, j), note in text.items():
        ax.text(j, i, note, ha="center", va="center", fontsize=7)
    ax.set_xticks(range(len(methods)), [PAPER_NAMES.get(m, m) for m in methods], fontsize=8)
    ax.set_yticks(range(len(cases)), cases, fontsize=7)
    ax.xaxis.tick_top()
    handles = [plt.Rectangle((0, 0), 1, 1, color=STATUS_COLOURS[s]) for s in statuses]
    ax.legend(handles, statuses, fontsize=7, ncol=3, loc="upper center",
              bbox_to_anchor=(0.5, -0.01), frameon=False)
    ax.set_title("outcome per case and method (Newton iterations, all load steps)", fontsize=9,
                 pad=22)
    return fig
