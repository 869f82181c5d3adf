# %% [markdown]
# # Coulomb friction: Cattaneo-Mindlin partial slip of two cylinders
#
# This demo illustrates how to:
#
# - give a contact pair a Coulomb coefficient (`mu` in its `[[pair]]` block)
#   and a load path that presses, then shears
#   (`scenes/cattaneo_mindlin_node_to_segment.toml`: two identical linear-elastic
#   half-cylinders, R = 1, E = 200, nu = 0.3, mu = 0.3, on matching arcs and a
#   node-to-segment pair; `scenes/cattaneo_mindlin.toml` is the same on
#   non-matching arcs and a mortar pair, `--scene` runs it);
# - read the stick and slip nodes of each load step;
# - compare the stick zone and the tangential traction with
#   Cattaneo-Mindlin's closed form (`fenics_contact.references.cattaneo`).
#
# ## Friction in the augmented Lagrangian
#
# Beside the normal multiplier $\lambda_n$ each contact node carries a
# tangential one, $\boldsymbol\lambda_t$, and Alart and Curnier's augmented
# conditions are projections:
#
# $$ \lambda_n = \min(\lambda_n + r g, 0), \qquad
# \boldsymbol\lambda_t = P_{\mathcal C(\mu\lambda_n)}\!\left(\boldsymbol\lambda_t
# + r_t\,\Delta\mathbf g_t\right), $$
#
# with $\Delta\mathbf g_t$ the slip increment of the load step and
# $P_{\mathcal C(\mu\lambda_n)}$ the projection onto the Coulomb disc of radius
# $\mu\,|\min(\lambda_n + r g, 0)|$. Inside the disc the node *sticks*
# ($\Delta\mathbf g_t = 0$); on its rim it *slips*, with
# $|\boldsymbol\lambda_t| = \mu|\lambda_n|$ opposing the slip. The projection is
# written in UFL and GNRM differentiates it like the normal term.
#
# ## Cattaneo-Mindlin
#
# Two identical bodies have Dundurs' $\beta = 0$: the normal problem stays
# Hertz's ($1/R^* = 2/R$, $1/E^* = 2(1-\nu^2)/E$, half-width $a$, peak
# $p_0$) while a tangential force $Q < \mu P$ opens a slip annulus
# $c \le |x| \le a$ around a stick zone of half-width
#
# $$ \frac{c}{a} = \sqrt{1 - \frac{Q}{\mu P}}, $$
#
# with the traction
# $q(x) = \mu p_0\left[\sqrt{1 - x^2/a^2} - \tfrac{c}{a}\sqrt{1 - x^2/c^2}\right]$
# for $|x| < c$ and $\mu p_0\sqrt{1 - x^2/a^2}$ in the slip annulus.

# %%
from __future__ import annotations

import argparse
import dataclasses
import os
from pathlib import Path

import fenics_contact  # noqa: F401  (loads the DOLFINx wheel's MPI libraries: first)

# isort: split
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from mpi4py import MPI

from fenics_contact import SolverSettings, build_problem, load_scene, make_strategy, solve_load_path
from fenics_contact.output.io import write_json
from fenics_contact.references.cattaneo import (
    StickZone,
    analytic_traction,
    contact_profile,
    measure_stick_zone,
)
from fenics_contact.solvers.stepping import StepRecord

parser = argparse.ArgumentParser(description="Cattaneo-Mindlin partial slip")
parser.add_argument("--out", type=Path, default=Path("results/cattaneo-mindlin"))
parser.add_argument(
    "--scene", type=Path,
    default=(Path(__file__).resolve().parents[1] / "scenes"
             / "cattaneo_mindlin_node_to_segment.toml"),
)
args, _ = parser.parse_known_args()  # tolerate notebook kernel arguments
root = MPI.COMM_WORLD.rank == 0


def say(*text: object) -> None:
    """Print once, on rank 0."""
    if root:
        print(*text, flush=True)


# %% [markdown]
# ## The scene
#
# The upper body's flat face follows a `path`: pressed down by 0.03 over
# load factors 0 ... 0.25, then shifted sideways by 0.014 up to load factor 1,
# so $Q/(\mu P)$ climbs to about 0.87. The contact zone is meshed with
# h = 0.003 R (about 67 nodes across it); with `CI` set, h = 0.005 R.

# %%
scene = load_scene(args.scene)
if os.environ.get("CI"):
    mesh = dataclasses.replace(scene.mesh, parameters={**scene.mesh.parameters,
                                                         "h_contact": 0.005})
    scene = dataclasses.replace(scene, mesh=mesh)
T_SHEAR = 0.25  # the load factor where the shift starts (the scene's path)
problem = build_problem(scene)
strategy = make_strategy(
    "gnrm", problem, SolverSettings(atol=scene.solver.atol, rtol=scene.solver.rtol,
                                    max_iterations=scene.solver.max_iterations),
    predictor=scene.solver.predictor,
)

# %% [markdown]
# ## Solve, measuring the stick zone at every shear step
#
# `measure_stick_zone` gathers the striker's nodal pressure, traction and
# stick/slip state, fits the Hertz ellipse and compares with the closed form.

# %%
zones: list[StickZone] = []
profiles = []


def measure(step: StepRecord) -> None:
    """After each converged shear step: the stick zone against theory."""
    if step.load_factor > T_SHEAR + 1e-12:
        profiles.append(contact_profile(problem))
        zones.append(measure_stick_zone(problem, profiles[-1]))


path = solve_load_path(strategy, scene.solver.steps, on_step=measure)
if not path.converged:
    raise RuntimeError(f"The load path stopped: {path.status}")
say(f"Newton iterations per step: {[s.iterations for s in path.steps]}")
say(f"\n{'Q/(mu P)':>8} {'stick':>5} {'slip':>5} {'c/a FE':>7} {'c/a exact':>9} "
    f"{'c error':>8} {'resolution':>10} {'traction L2':>11}")
for z in zones:
    say(f"{z.load_ratio:>8.3f} {z.stick_nodes:>5} {z.slip_nodes:>5} {z.c_measured / z.a:>7.3f} "
        f"{z.c_analytic / z.a:>9.3f} {z.c_error:>+8.2%} {z.c_resolution:>10.2%} "
        f"{z.traction_error:>11.2%}")

# %% [markdown]
# The measured stick half-width is the midpoint between the last sticking and
# the first slipping node, so it is known to half a node spacing (the
# *resolution* column); its error stays within that.
#
# ## The pictures
#
# Left: the stick half-width against the load ratio. Right: the nodal
# tangential traction at the middle and the last shear step against $q(x)$.

# %%
mu = scene.pairs[0].mu
if root:
    args.out.mkdir(parents=True, exist_ok=True)
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4))
    ratio = np.linspace(0.0, 1.0, 200)
    left.plot(ratio, np.sqrt(1 - ratio), "k-", label="Cattaneo-Mindlin")
    left.plot([z.load_ratio for z in zones], [z.c_measured / z.a for z in zones], "o",
              label="FE (stick/slip nodes)")
    left.set_xlabel("Q / (mu P)")
    left.set_ylabel("c / a")
    left.legend()
    for k, colour in ((len(zones) // 2, "tab:blue"), (len(zones) - 1, "tab:red")):
        z, prof = zones[k], profiles[k]
        x = prof.x - z.centre
        closed = prof.pressure < 0
        xs = np.linspace(-z.a, z.a, 400)
        right.plot(xs / z.a, analytic_traction(xs, z.a, z.c_analytic, z.p0, mu) / (mu * z.p0),
                   "-", color=colour, label=f"theory, Q/(mu P) = {z.load_ratio:.2f}")
        right.plot(x[closed] / z.a, prof.tau_along_resultant()[closed] / (mu * z.p0), "o",
                   ms=3, color=colour)
    right.set_xlabel("x / a")
    right.set_ylabel("q / (mu p0)")
    right.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out / "stick_zone.png", dpi=120)
    plt.close(fig)
    write_json(args.out / "summary.json", {
        "mpi_ranks": MPI.COMM_WORLD.size,
        "mesh": scene.mesh.parameters,
        "mu": mu,
        "iterations_per_step": [s.iterations for s in path.steps],
        "zones": [z.to_dict() for z in zones],
    })
say(f"\nWrote {args.out}/summary.json and stick_zone.png")
