# %% [markdown]
# # The paper's comparison: four strategies on Example 2
#
# This demo illustrates how to:
#
# - solve one scene, the Example 2 analog `scenes/paper_ex2.toml` (a
#   St. Venant-Kirchhoff bar of 6 x 2 quadrilaterals pressed into a rigid
#   cradle in 10 load steps), with each of the four strategies of Heegaard,
#   Hovey and Kaplan: the penalty method (PM), simultaneous and nested Uzawa
#   (SUA, NUA) and the generalized Newton method (GNRM);
# - sweep the augmentation parameter r and print the iteration table in the
#   paper's layout (its Table 2);
# - draw the residual histories of the four strategies.
#
# ## The formulation
#
# With the strain energy $\Psi(\mathbf u)$ of the bar and the gap
# $g(\mathbf x)$ to the cradle (positive when open), every strategy solves the
# discrete contact conditions at the contact nodes
#
# $$ g \ge 0, \qquad \lambda \le 0, \qquad \lambda\, g = 0 $$
#
# (the multiplier $\lambda$ is the normal pressure). They differ in the
# functional they drive to stationarity and in how $\lambda$ is updated:
#
# - **PM** (paper eq. 7): $\Pi_p(\mathbf u) = \Psi(\mathbf u) + \tfrac r2 \int
#   \min(g, 0)^2$, Newton on $\mathbf u$ alone; the penetration falls like
#   $1/r$ and is never zero.
# - **Alart-Curnier augmented Lagrangian** (eq. 9):
#
#   $$ \Pi_r(\mathbf u, \lambda) = \Psi(\mathbf u) + \int \frac{1}{2r}
#   \left[\min(\lambda + r g, 0)^2 - \lambda^2\right], $$
#
#   whose stationarity in $\lambda$ is $\lambda = \min(\lambda + r g, 0)$, the
#   three conditions above in one equation.
#   **SUA** takes one Newton step in $\mathbf u$ then updates
#   $\lambda \leftarrow \min(\lambda + r g, 0)$; **NUA** converges $\mathbf u$
#   first, then updates; **GNRM** takes Newton steps on $(\mathbf u, \lambda)$
#   together, with the generalized (semismooth) derivative of the $\min$.
#
# All four share one Newton kernel, one residual measure (out-of-balance
# forces together with the complementarity residual
# $\lambda - \min(\lambda + r g, 0)$) and one stopping test, so their
# iteration counts compare directly. The library builds the forms from the
# scene (`build_problem`) and a strategy by name (`make_strategy`);
# `run_study` does both for every method and r, from $(\mathbf u, \lambda) = 0$,
# without step cut-backs, as the paper does.

# %%
from __future__ import annotations

import argparse
import os
from pathlib import Path

import fenics_contact  # noqa: F401  (loads the DOLFINx wheel's MPI libraries: first)

# isort: split
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from mpi4py import MPI

from fenics_contact import SolverSettings, load_scene
from fenics_contact.output.io import write_json
from fenics_contact.solvers import PAPER_NAMES
from fenics_contact.sweeps.study import paper_table, run_study

parser = argparse.ArgumentParser(description="The four strategies on the paper's Example 2")
parser.add_argument("--out", type=Path, default=Path("results/paper-comparison"))
parser.add_argument(
    "--scene", type=Path,
    default=Path(__file__).resolve().parents[1] / "scenes" / "paper_ex2.toml",
)
args, _ = parser.parse_known_args()  # tolerate notebook kernel arguments
root = MPI.COMM_WORLD.rank == 0


def say(*text: object) -> None:
    """Print once, on rank 0."""
    if root:
        print(*text, flush=True)


# %% [markdown]
# ## The sweep
#
# r is absolute (stress per length, as in the paper's tables with E = 210).
# The stopping test is the paper's: residual below 1e-8, at most 500
# iterations a load step. With `CI` set the sweep keeps three values of r.

# %%
METHODS = ("penalty", "sua", "nua", "gnrm")
R_VALUES = (1.0, 100.0, 10000.0) if os.environ.get("CI") else (1.0, 10.0, 100.0, 1000.0, 1e4)
scene = load_scene(args.scene)
records = run_study(
    scene, METHODS, R_VALUES, settings=SolverSettings(atol=1e-8, max_iterations=500),
)
table = paper_table(records)
say(table)
say("\nmethod      r      status          iterations  error against GNRM  max penetration")
for rec in records:
    say(f"{rec.method:<8} {rec.r:>7g}  {rec.status:<15} {rec.iterations:>6}  "
        f"{rec.error:>18.1e}  {rec.max_penetration:>15.1e}")

# %% [markdown]
# ## Residual histories
#
# Left: every Newton iteration of the whole load path at r = 100, one line a
# strategy (the residual restarts at each load step). GNRM converges
# quadratically in every step; the penalty method too, but to the penalised
# answer (its error column above); NUA needs an inner Newton solve per
# multiplier update; SUA cycles. Right: GNRM at every r, the same curve.

# %%
by_key = {(rec.method, rec.r): rec for rec in records}
r_show = 100.0
colours = dict(zip(METHODS, ("tab:orange", "tab:red", "tab:green", "tab:blue"), strict=True))
fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4))
for method in METHODS:
    history = [value for step in by_key[(method, r_show)].steps
               for solve in step.residuals for value in solve]
    left.semilogy(range(1, len(history) + 1), history, ".-", ms=2, lw=0.8,
                  color=colours[method], label=PAPER_NAMES[method])
left.set_xlim(0, 200)
left.set_xlabel("Newton iteration (all load steps, first 200)")
left.set_ylabel("residual")
left.set_title(f"Example 2, r = {r_show:g}")
left.legend(fontsize=8)
for r in R_VALUES:
    history = [value for step in by_key[("gnrm", r)].steps
               for solve in step.residuals for value in solve]
    right.semilogy(range(1, len(history) + 1), history, ".-", ms=3, lw=0.8, label=f"r = {r:g}")
right.set_xlabel("Newton iteration (all load steps)")
right.set_title("GNRM: the same iterations at every r")
right.legend(fontsize=8)
fig.tight_layout()
if root:
    args.out.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out / "residuals.png", dpi=120)
plt.close(fig)

# %% [markdown]
# ## Outputs
#
# `<out>/summary.json` holds every run (status, iterations, updates, error,
# penetration, per-step residual histories), `<out>/table.md` the table.

# %%
if root:
    write_json(args.out / "summary.json", {
        "scene": scene.name,
        "r_values": list(R_VALUES),
        "runs": [rec.to_dict() for rec in records],
    })
    (args.out / "table.md").write_text(table + "\n")
say(f"\nWrote {args.out}/summary.json, table.md and residuals.png")
