"""Convergence plots (matplotlib, Agg backend: no display needed)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.ticker import MaxNLocator

from fenics_contact.solvers import PAPER_NAMES
from fenics_contact.solvers.stepping import RunRecord


def save_figure(fig: plt.Figure, path: Path) -> None:
    """Lay out, write (PNG at 120 dpi; the folder is created) and close ``fig``."""
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def residual_histories(records: Sequence[RunRecord], path: Path) -> None:
    """One semilog panel per method: residual against cumulative iteration, a line per r."""
    methods = list(dict.fromkeys(r.method for r in records))
    fig, axes = plt.subplots(
        1, len(methods), figsize=(4.2 * len(methods), 3.6), squeeze=False, sharey=True
    )
    for ax, method in zip(axes[0], methods, strict=True):
        for rec in (r for r in records if r.method == method):
            history = [v for solve in rec.residuals for v in solve]
            ax.semilogy(range(len(history)), history, lw=1, label=f"r = {rec.r:g} ({rec.status})")
        ax.axhline(1e-8, color="k", lw=0.6, ls=":")
        ax.set_title(PAPER_NAMES.get(method, method))
        ax.set_xlabel("residual evaluation (all load steps)")
        ax.legend(fontsize=7)
    axes[0][0].set_ylabel("static residual (L2 norm)")
    save_figure(fig, path)


def iterations_against_r(records: Sequence[RunRecord], path: Path) -> None:
    """Total Newton iterations against r per method; failures drawn as open markers."""
    fig, ax = plt.subplots(figsize=(5.5, 4))
    for method in dict.fromkeys(r.method for r in records):
        recs = sorted((r for r in records if r.method == method), key=lambda r: r.r)
        line = ax.loglog(
            [r.r for r in recs], [max(r.iterations, 1) for r in recs], "-", lw=1,
            label=PAPER_NAMES.get(method, method),
        )[0]
        for rec in recs:
            ok = rec.status == "converged"
            ax.plot(
                rec.r, max(rec.iterations, 1), "o", color=line.get_color(),
                mfc=line.get_color() if ok else "none",
            )
    ax.set_xlabel("r (absolute)")
    ax.set_ylabel("Newton iterations, all load steps")
    ax.set_title("open marker: not converged")
    ax.legend(fontsize=8)
    save_figure(fig, path)


def step_residuals(steps: Sequence, path: Path, title: str = "") -> None:
    """Residual against Newton iteration, one line per load step (semilog)."""
    fig, ax = plt.subplots(figsize=(5.5, 4))
    for step in steps:
        history = [v for solve in step.residuals for v in solve]
        iterations = [k for k, v in enumerate(history) if v > 0]  # 0 (exact) has no log
        ax.semilogy(iterations, [history[k] for k in iterations], "o-", ms=3, lw=1,
                    label=f"step {step.step}")
    ax.set_xlabel("Newton iteration")
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_ylabel("static residual (L2 norm)")
    ax.set_title(title)
    if len(steps) <= 12:
        ax.legend(fontsize=7, ncol=2)
    save_figure(fig, path)
