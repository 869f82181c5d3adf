# ---
# jupyter:
#   jupytext:
#     formats: py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Hertz line contact: an elastic cylinder on a rigid plane
#
# This demo validates the frictionless contact formulation against Hertz
# theory in 2D on the shipped scene `scenes/hertz_cylinder.toml`. A
# small-strain linear elastic half-cylinder (plane strain,
# radius R = 1, E = 200, nu = 0.3) is pushed onto the rigid plane y = 0 by
# moving its flat top face down. The contact problem is solved with GNRM
# (generalized Newton on displacement and Alart-Curnier multiplier, nodal
# quadrature) in a few load steps. The measured total contact force P per
# unit thickness sets the analytic reference (E* = E / (1 - nu^2)):
#
# - half-width  a  = sqrt(4 P R / (pi E*)),
# - peak        p0 = 2 P / (pi a) = sqrt(P E* / (pi R)),
# - profile     p(x) = p0 sqrt(1 - x^2 / a^2).
#
# The half-width and the peak are measured by a least-squares fit of
# p^2 = p0^2 - (p0/a)^2 x^2 over the nodes in contact; the largest nodal
# pressure is reported too. Outputs: a table on screen,
# `<out>/summary.json` and `<out>/pressure.png` (nodal pressure against the
# Hertz profile).
#
# Run it with `python demos/hertz_cylinder.py [--out DIR]` (or under
# `mpiexec -n 2`). It takes a few seconds (about 4 x 10^3 unknowns), so it
# runs unchanged when the `CI` environment variable is set.

# %%
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import fenics_contact  # noqa: F401  (loads the DOLFINx wheel's MPI libraries: first)

# isort: split
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from mpi4py import MPI

from fenics_contact import build_problem, load_scene
from fenics_contact.references.measure import contact_profile, measure_hertz
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings, signorini_report
from fenics_contact.solvers.stepping import StepRecord, solve_load_path

parser = argparse.ArgumentParser(description="Hertz line contact validation")
parser.add_argument(
    "--out",
    type=Path,
    default=Path("results/hertz_cylinder"),
    help="output directory (default: results/hertz_cylinder)",
)
parser.add_argument(
    "--scene",
    type=Path,
    default=Path(__file__).resolve().parents[1] / "scenes" / "hertz_cylinder.toml",
    help="the Hertz scene (default: scenes/hertz_cylinder.toml)",
)
parser.add_argument("--steps", type=int, default=4, help="load steps (default: 4)")
args, _ = parser.parse_known_args()  # tolerate notebook kernel arguments

comm = MPI.COMM_WORLD
root = comm.rank == 0


def say(*text: object) -> None:
    """Print on rank 0 only."""
    if root:
        print(*text, flush=True)


# %% [markdown]
# ## The problem
#
# The mesh (`meshes/hertz_cylinder.geo`) is the lower half-disk graded with
# gmsh: elements of size `h_contact = 0.004 R` within 0.1 R of the contact
# point, growing to `0.1 R` further away. The push of 0.01 R gives a
# half-width of about 0.08 R, small enough for Hertz's half-space assumption
# and spanned by about 20 elements. The arc's facets carry the multipliers
# (nodal quadrature, r = 1 relative to E/h).

# %%
cylinder = load_scene(args.scene)
mesh_parameters = {"radius": 1.0, "fine_radius": 0.1, "coarse_radius": 0.5,  # the .geo's
                   **cylinder.mesh.parameters}
radius, h_contact = mesh_parameters["radius"], mesh_parameters["h_contact"]
push = -cylinder.dirichlet[0].value[1]  # the flat top's downward displacement
settings = cylinder.contact
start = time.perf_counter()
problem = build_problem(cylinder, comm)
n_dofs = problem.V.dofmap.index_map.size_global * problem.V.dofmap.index_map_bs
n_lam = problem.surface.num_dofs
say(
    f"Displacement dofs: {n_dofs}, multiplier dofs: {n_lam}, "
    f"contact facet size h = {problem.surface.h:.4g}"
)

# %% [markdown]
# ## Solve with GNRM
#
# After each load step the state is compared with Hertz theory at the load
# that step reached.

# %%
strategy = make_strategy("gnrm", problem, SolverSettings(atol=1e-10, max_iterations=30))
history: list[dict] = []


def record(step: StepRecord) -> None:
    """Compare the converged step with Hertz theory."""
    c = measure_hertz(problem, radius, cylinder.E, cylinder.nu)
    history.append(
        {
            "step": step.step,
            "push": step.load_factor * push,
            "iterations": step.iterations,
            "active_nodes": step.active_count,
            "P": c.P,
            "a_fit": c.fit.a,
            "a_hertz": c.hertz.a,
            "p0_fit": c.fit.p0,
            "p0_nodal": c.fit.nodal_peak,
            "p0_hertz": c.hertz.p0,
        }
    )


path = solve_load_path(strategy, args.steps, on_step=record)
wall = time.perf_counter() - start
if not path.converged:
    raise RuntimeError(f"The load path stopped: {path.status}")

say(
    f"\n{'step':>4} {'push':>7} {'its':>3} {'nodes':>5} {'P':>8} {'a fit':>8} "
    f"{'a Hertz':>8} {'p0 fit':>8} {'p0 node':>8} {'p0 Hertz':>8}"
)
for h in history:
    say(
        f"{h['step']:>4} {h['push']:>7.4f} {h['iterations']:>3} {h['active_nodes']:>5} "
        f"{h['P']:>8.4f} {h['a_fit']:>8.5f} {h['a_hertz']:>8.5f} {h['p0_fit']:>8.3f} "
        f"{h['p0_nodal']:>8.3f} {h['p0_hertz']:>8.3f}"
    )

# %% [markdown]
# ## Comparison at full load

# %%
comparison = measure_hertz(problem, radius, cylinder.E, cylinder.nu)
state = problem.contact_state()
kkt = signorini_report(state.gap, state.pressure, comm)
hertz = comparison.hertz
rows = [
    ("half-width a (fit)", comparison.fit.a, hertz.a, comparison.a_error),
    ("peak p0 (fit)", comparison.fit.p0, hertz.p0, comparison.p0_error),
    ("peak p0 (largest nodal)", comparison.fit.nodal_peak, hertz.p0, comparison.nodal_peak_error),
]
say(
    f"\nTotal contact force P = {comparison.P:.6f} per unit thickness; "
    f"a/R = {hertz.a / radius:.4f}, a/h_contact = {hertz.a / h_contact:.1f}, "
    f"{comparison.fit.n_contact} nodes in contact"
)
say(f"{'quantity':<26} {'FE':>10} {'Hertz':>10} {'error':>8}")
for name, fe, exact, err in rows:
    say(f"{name:<26} {fe:>10.5f} {exact:>10.5f} {100 * err:>7.3f}%")
say(
    f"Signorini: min gap {kkt.min_gap:.2e}, max pressure {kkt.max_pressure:.2e}, "
    f"max |lam g| {kkt.max_complementarity:.2e}; wall time {wall:.1f} s"
)

# %% [markdown]
# ## What the contact set costs in Newton iterations
#
# The paper's GNRM takes each Newton step's contact set from the sign of
# lam + r g at the iterate, so every node that closes within a load step
# costs an iteration. The scenes start each step from the extrapolated state
# (`predictor = "active-set"`) and give every Newton step the exact contact
# set of its own linear model (`contact_set = "exact"`), found with the
# step's own factorisation. The answer is the same; this body is linear
# elasticity against a plane, so with the right set each step is one
# iteration.

# %%
variants = {
    "paper's GNRM (last state, sign rule)": ("previous", "sign"),
    "extrapolated start, sign rule": ("active-set", "sign"),
    "extrapolated start, exact set (scenes)": ("active-set", "exact"),
}
for label, (predictor, contact_set) in variants.items():
    again = build_problem(cylinder, comm)
    run = solve_load_path(
        make_strategy("gnrm", again, SolverSettings(atol=1e-10, max_iterations=30),
                      predictor=predictor, contact_set=contact_set),
        args.steps,
    )
    difference = comm.allreduce(float(np.max(np.abs(again.u.x.array - problem.u.x.array))),
                                op=MPI.MAX)
    say(f"{label:<40} {run.iterations:>3} Newton iterations "
        f"({' '.join(str(s.iterations) for s in run.steps)}); "
        f"displacements differ by {difference:.1e}")

# %% [markdown]
# ## Outputs: summary.json and the pressure plot

# %%
x, p = contact_profile(problem)
if root:
    args.out.mkdir(parents=True, exist_ok=True)
    summary = {
        "problem": {
            "scene": cylinder.name,
            "radius": radius,
            "E": cylinder.E,
            "nu": cylinder.nu,
            "push": push,
            "material": "linear elastic, plane strain",
        },
        "mesh": {
            **mesh_parameters,
            "displacement_dofs": n_dofs,
            "multiplier_dofs": n_lam,
        },
        "solver": {
            "strategy": "gnrm",
            "quadrature": settings.quadrature,
            "r_relative": settings.r,
            "load_steps": args.steps,
            "iterations_per_step": [s.iterations for s in path.steps],
            "wall_s": wall,
            "mpi_ranks": comm.size,
        },
        "P": comparison.P,
        "hertz": {"a": hertz.a, "p0": hertz.p0, "E_star": hertz.E_star},
        "measured": {
            "a_fit": comparison.fit.a,
            "p0_fit": comparison.fit.p0,
            "p0_nodal": comparison.fit.nodal_peak,
            "x_nodal_peak": comparison.fit.x_peak,
            "nodes_in_contact": comparison.fit.n_contact,
        },
        "relative_error": {
            "a_fit": comparison.a_error,
            "p0_fit": comparison.p0_error,
            "p0_nodal": comparison.nodal_peak_error,
        },
        "signorini": {
            "min_gap": kkt.min_gap,
            "max_pressure": kkt.max_pressure,
            "max_complementarity": kkt.max_complementarity,
        },
        "load_steps": history,
    }
    (args.out / "summary.json").write_text(json.dumps(summary, indent=2))

    fig, ax = plt.subplots(figsize=(6, 4))
    window = np.abs(x) <= 1.6 * hertz.a
    xs = np.linspace(-1.6 * hertz.a, 1.6 * hertz.a, 401)
    ax.plot(xs, hertz.pressure(xs), "k-", label=f"Hertz, P = {comparison.P:.4f}")
    ax.plot(x[window], -p[window], "o", ms=3.5, color="tab:red", label="FE nodal pressure")
    ax.axvline(-comparison.fit.a, color="tab:blue", ls=":", lw=1, label="fitted half-width")
    ax.axvline(comparison.fit.a, color="tab:blue", ls=":", lw=1)
    ax.set_xlabel("x (reference)")
    ax.set_ylabel("contact pressure -lam")
    ax.set_title(
        f"Hertz cylinder: a/R = {hertz.a / radius:.3f}, "
        f"{comparison.fit.n_contact} nodes in contact"
    )
    ax.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out / "pressure.png", dpi=150)
    plt.close(fig)
    say(f"Wrote {args.out / 'summary.json'} and {args.out / 'pressure.png'}")
