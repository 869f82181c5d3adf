# ---
# jupyter:
#   jupytext:
#     formats: py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Hertz contact written out in UFL: a cylinder on a rigid plane
#
# This demo illustrates how to:
#
# - mesh a half-cylinder with gmsh and read its facet tags into DOLFINx;
# - build a submesh of the candidate contact facets with
#   `dolfinx.mesh.create_submesh` and a P1 Lagrange multiplier space on it;
# - write a strain energy `psi(F)` and the gap to a rigid plane in the
#   current configuration as UFL expressions;
# - add the Alart-Curnier augmented Lagrangian term
#   `[min(lam + r g, 0)^2 - lam^2] / (2 r)`, integrated with the vertex
#   quadrature rule (node-on-facet contact);
# - obtain the residual blocks with `ufl.derivative` on a
#   `ufl.MixedFunctionSpace` and `ufl.extract_blocks`, with the `entity_maps`
#   that couple the body mesh and the submesh;
# - solve the blocked system with Newton's method
#   (`dolfinx.fem.petsc.NonlinearProblem`, MUMPS) in a few load steps,
#   checking that every step converged;
# - compare the contact half-width and peak pressure with Hertz theory.
#
# Only the analytic Hertz formulas and the gmsh-to-DOLFINx helper come from
# `fenics_contact`; the formulation is all on this page. The library builds
# the same problem from the shipped scene `scenes/hertz_cylinder.toml`
# (`demos/hertz_cylinder.py` runs it), and both give the same numbers.
#
# Run it as a script, `python demos/demo_hertz_ufl.py [--out DIR]`, in
# parallel with `mpiexec -n 2 python demos/demo_hertz_ufl.py`, or open it as
# a notebook with jupytext. When the environment variable `CI` is set the
# mesh is twice as coarse near the contact, so that the test runs fast.
#
# ## The problem
#
# A linear elastic half-cylinder (plane strain, radius R = 1, E = 200,
# nu = 0.3) rests on the rigid plane y = 0. Its flat top face y = R is moved
# down by 0.01 R. With the total contact force P per unit thickness and the
# plane-strain modulus E* = E / (1 - nu^2), Hertz theory gives
#
# - the half-width of the contact zone a = sqrt(4 P R / (pi E*)),
# - the peak pressure p0 = 2 P / (pi a),
# - the pressure profile p(x) = p0 sqrt(1 - x^2 / a^2).
#
# Conventions: the gap g >= 0 when open; the multiplier lam <= 0 is the
# normal contact pressure (so the pressure magnitude is -lam).

# %%
from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from mpi4py import MPI

import fenics_contact  # noqa: F401  (loads the DOLFINx wheel's libraries first)

# isort: split
import dolfinx
import dolfinx.fem.petsc
import ufl
from dolfinx import default_scalar_type, fem, la, mesh

from fenics_contact.references.hertz import (
    fit_contact_profile,
    hertz_line_contact,
    relative_error,
)
from fenics_contact.scene.meshing import mesh_on_rank

parser = argparse.ArgumentParser(description="Hertz line contact written out in UFL")
parser.add_argument(
    "--out", type=Path, default=Path("results/hertz_ufl"),
    help="output folder (default: results/hertz_ufl)",
)
parser.add_argument("--steps", type=int, default=4, help="load steps (default: 4)")
parser.add_argument(
    "--max-iterations", type=int, default=30,
    help="Newton iterations allowed per load step (default: 30)",
)
args, _ = parser.parse_known_args()  # tolerate a notebook kernel's own arguments
if args.steps < 1 or args.max_iterations < 1:
    parser.error(
        f"--steps ({args.steps}) and --max-iterations ({args.max_iterations}) must be >= 1."
    )

comm = MPI.COMM_WORLD


def say(*text: object) -> None:
    """Print once, on rank 0."""
    if comm.rank == 0:
        print(*text, flush=True)


# %% [markdown]
# ## Parameters

# %%
R = 1.0  # cylinder radius (length)
E, nu = 200.0, 0.3  # Young's modulus (stress) and Poisson's ratio
push = 0.01 * R  # downward displacement of the top face at full load (length)
h_contact = (0.008 if os.environ.get("CI") else 0.004) * R  # element size at the contact
contact_band = 0.02 * R  # arc facets with midpoints below this height carry multipliers
mu_lame = E / (2 * (1 + nu))
lmbda = E * nu / ((1 + nu) * (1 - 2 * nu))

# %% [markdown]
# ## The mesh
#
# `meshes/hertz_cylinder.geo` describes the lower half of the disk of
# radius R centred at (0, R), touching y = 0 at the origin, with physical
# groups: the body (cells, tag 1), the flat top face (facets, tag 2) and the
# arc (facets, tag 3). Its triangles are of size `h_contact` within 0.1 R of
# the origin and grow to 0.1 R further away. gmsh meshes it on rank 0;
# `mesh_on_rank` hands the model to `dolfinx.io.gmsh.model_to_mesh`, which
# distributes the mesh and its tags over all ranks.

# %%
here = Path(__file__).parent if "__file__" in globals() else Path.cwd()
candidates = [folder / "hertz_cylinder.geo" for folder in (here.parent / "meshes", here / "meshes")]
geo = next((path for path in candidates if path.exists()), None)
if geo is None:
    raise FileNotFoundError(
        f"meshes/hertz_cylinder.geo not found (looked at {[str(p) for p in candidates]}); "
        "run the demo from the repository's root or its demos/ folder."
    )


def mesh_geo(gmsh) -> None:
    """Open the .geo file with our element size and mesh it in 2D."""
    gmsh.option.setNumber("General.Terminal", 0)
    # the .geo declares h_contact with DefineConstant[... Name "Parameters/h_contact"]:
    # a ONELAB parameter of that name overrides its default
    gmsh.onelab.setNumber("Parameters/h_contact", [h_contact])
    gmsh.open(str(geo))
    gmsh.model.mesh.generate(2)


#: The .geo's physical curves: "top" (the flat face) and "contact" (the arc).
TOP_TAG, CONTACT_TAG = 2, 3
mesh_data = mesh_on_rank(comm, 0, 2, mesh_geo)
msh = mesh_data.mesh
facet_tags = mesh_data.facet_tags
tdim = msh.topology.dim
fdim = tdim - 1

# %% [markdown]
# Only the part of the arc that can touch the plane needs a multiplier: the
# arc facets whose midpoint lies below `contact_band` (the band must
# contain the contact zone, whose edge rises to a^2 / (2 R) ~ 0.003 R).

# %%
arc = facet_tags.find(CONTACT_TAG)
midpoints = mesh.compute_midpoints(msh, fdim, arc)
contact_facets = arc[midpoints[:, 1] < contact_band]
top_facets = facet_tags.find(TOP_TAG)

# %% [markdown]
# ## The displacement space and the multiplier on the contact submesh
#
# The displacement is a continuous piecewise linear vector field on the
# body. The multiplier lives on a 1D mesh made of the contact facets:
# `create_submesh` returns it together with an `EntityMap` that relates its
# cells to the body's facets. Forms that mix the two meshes need that map.

# %%
V = fem.functionspace(msh, ("Lagrange", 1, (msh.geometry.dim,)))
msh.topology.create_connectivity(fdim, tdim)
contact_mesh, entity_map, _, _ = mesh.create_submesh(msh, fdim, contact_facets)
Q = fem.functionspace(contact_mesh, ("Lagrange", 1))
u = fem.Function(V, name="displacement")
lam = fem.Function(Q, name="multiplier")

n_u = V.dofmap.index_map.size_global * V.dofmap.index_map_bs
n_lam = Q.dofmap.index_map.size_global
say(f"Displacement dofs: {n_u}, multiplier dofs: {n_lam}")

# %% [markdown]
# ## The strain energy
#
# The stored energy per unit reference volume is a function of the
# deformation gradient F = I + grad u. For the comparison with Hertz we use
# small-strain linear elasticity, with eps = sym(F - I):
#
#   psi = lmbda/2 (tr eps)^2 + mu eps:eps.
#
# For finite deformation the same place takes St. Venant-Kirchhoff,
# psi = lmbda/2 (tr E)^2 + mu E:E with E = (F^T F - I)/2 (the paper's law),
# or a compressible neo-Hookean law,
# psi = mu/2 (I1 - 3) - mu ln J + lmbda/2 (ln J)^2 with I1 = tr(F^T F) + 1 in
# plane strain and J = det F. F is a `ufl.variable`, so the first
# Piola-Kirchhoff stress would be `ufl.diff(psi, F)`; we never need it
# explicitly: UFL derives the residual and the tangent from psi, so changing
# the law means changing this one function.
# In 2D the body is in plane strain (the out-of-plane stretch is one).

# %%
d = len(u)
I = ufl.Identity(d)  # noqa: E741
F = ufl.variable(I + ufl.grad(u))


def psi_linear(F):
    """Small-strain linear elasticity (stress units)."""
    eps = ufl.sym(F - I)
    return 0.5 * lmbda * ufl.tr(eps) ** 2 + mu_lame * ufl.inner(eps, eps)


def psi_svk(F):
    """St. Venant-Kirchhoff (stress units)."""
    E_gl = 0.5 * (F.T * F - I)
    return 0.5 * lmbda * ufl.tr(E_gl) ** 2 + mu_lame * ufl.inner(E_gl, E_gl)


def psi_neo_hookean(F):
    """Compressible neo-Hookean in plane strain (stress units)."""
    J = ufl.det(F)
    I1 = ufl.tr(F.T * F) + 1
    return 0.5 * mu_lame * (I1 - 3) - mu_lame * ufl.ln(J) + 0.5 * lmbda * ufl.ln(J) ** 2


psi = psi_linear(F)

# %% [markdown]
# ## The gap to the rigid plane, in the current configuration
#
# A material point X moves to x = X + u. The rigid plane passes through
# x0 = (0, 0) with outward unit normal n = (0, 1); the signed gap is
# g = (x - x0) . n, positive when the point is clear of the plane. The gap
# depends on u, so `ufl.derivative` sees its variation (for a plane:
# dg/du = n).

# %%
X = ufl.SpatialCoordinate(msh)
x = X + u
x0 = fem.Constant(msh, np.array([0.0, 0.0], dtype=default_scalar_type))
normal = fem.Constant(msh, np.array([0.0, 1.0], dtype=default_scalar_type))
g = ufl.dot(x - x0, normal)

# %% [markdown]
# ## The Alart-Curnier term and the vertex rule
#
# With the augmentation parameter r > 0 (stress per length) the augmented
# Lagrangian is
#
#   L(u, lam) = int_body psi dx
#             + int_contact [min(lam + r g, 0)^2 - lam^2] / (2 r) ds.
#
# Its stationarity in lam gives lam = min(lam + r g, 0), which is the
# Signorini conditions g >= 0, lam <= 0, lam g = 0 in one equation; its
# variation in u adds the contact force min(lam + r g, 0) dg/du.
#
# The surface measure uses the vertex quadrature rule: the points are the
# facet vertices with weights |facet|/2. The term is then evaluated at the
# nodes only (the node-on-facet discretisation, with a lumped multiplier
# mass), and the complementarity holds exactly at every node. We choose
# r = E / h with h the mean length of the contact facets; the converged
# solution does not depend on r, only the Newton path does.

# %%
contact_id = 1
contact_tags = mesh.meshtags(
    msh, fdim, np.sort(contact_facets), np.full(contact_facets.size, contact_id, np.int32)
)
ds_c = ufl.Measure(
    "ds", domain=msh, subdomain_data=contact_tags, subdomain_id=contact_id,
    metadata={"quadrature_rule": "vertex", "quadrature_degree": 1},
)

facet_nodes = mesh.entities_to_geometry(msh, fdim, contact_facets)
ends = msh.geometry.x[facet_nodes]
length = comm.allreduce(float(np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1).sum()), MPI.SUM)
h_mean = length / comm.allreduce(contact_facets.size, MPI.SUM)
r = fem.Constant(msh, default_scalar_type(E / h_mean))

alart_curnier = (ufl.min_value(lam + r * g, 0) ** 2 - lam**2) / (2 * r)
L = psi * ufl.dx + alart_curnier * ds_c

# %% [markdown]
# ## Residual blocks from `ufl.derivative`
#
# The test functions come from a `MixedFunctionSpace` of the two spaces,
# which live on different meshes. One variational statement holds both
# equations; `extract_blocks` splits it into the residual of each field.
# The multiplier equation is scaled by r, so that it reads
# (min(lam + r g, 0) - lam) mu ds, a residual in force units like the
# displacement's.

# %%
W = ufl.MixedFunctionSpace(V, Q)
v, mu = ufl.TestFunctions(W)
residual = ufl.derivative(L, u, v) + r * ufl.derivative(L, lam, mu)
residual_blocks = ufl.extract_blocks(residual)
entity_maps = [entity_map]

# %% [markdown]
# ## Boundary conditions
#
# The top face moves down by `t * push` at load factor t and does not move
# sideways, which also removes the rigid body modes. The value is a
# `Constant`, so the load steps change it without recompiling anything.

# %%
top_value = fem.Constant(msh, np.array([0.0, 0.0], dtype=default_scalar_type))
bc_top = fem.dirichletbc(top_value, fem.locate_dofs_topological(V, fdim, top_facets), V)

# %% [markdown]
# ## The blocked Newton solve
#
# `NonlinearProblem` derives the Jacobian blocks J_ij = dF_i/du_j with
# `ufl.derivative` (for min_value this is the generalized Jacobian of
# the generalized Newton method) and assembles them into one PETSc matrix
# (`kind="mpi"`). Each Newton step is a direct solve with MUMPS, without
# line search. A step counts as converged when the Euclidean norm of the
# residual is below 1e-10; otherwise the demo stops and says why.

# %%
problem = dolfinx.fem.petsc.NonlinearProblem(
    residual_blocks,
    [u, lam],
    bcs=[bc_top],
    entity_maps=entity_maps,
    kind="mpi",
    petsc_options_prefix="demo_hertz_ufl_",
    petsc_options={
        "snes_type": "newtonls",
        "snes_linesearch_type": "basic",
        "snes_atol": 1e-10,
        "snes_rtol": 0.0,
        "snes_stol": 0.0,
        "snes_max_it": args.max_iterations,
        "ksp_type": "preonly",
        "pc_type": "lu",
        "pc_factor_mat_solver_type": "mumps",
    },
)

iterations = []
for step in range(1, args.steps + 1):
    t = step / args.steps
    top_value.value[:] = (0.0, -t * push)
    problem.solve()
    reason = problem.solver.getConvergedReason()
    its = problem.solver.getIterationNumber()
    if reason <= 0:
        raise RuntimeError(
            f"Load step {step} (t = {t:.3g}): Newton did not converge, SNES reason "
            f"{reason} after {its} iterations."
        )
    iterations.append(its)
    say(f"load step {step}: t = {t:.3g}, {its} Newton iterations (SNES reason {reason})")

# %% [markdown]
# ## Nodal gaps and pressures
#
# With the vertex rule, the vector of `f mu ds_c` is the lumped nodal area
# times the nodal value of f, so dividing by the vector of `mu ds_c` reads
# nodal values of any expression. The pressure is the multiplier itself;
# the total contact force is P = -int lam ds (per unit thickness).


# %%
def nodal_values(expr) -> np.ndarray:
    """Values of ``expr`` at the owned multiplier nodes (vertex rule)."""
    mu_ = ufl.TestFunction(Q)

    def assemble(integrand):
        vec = fem.assemble_vector(fem.form(integrand * mu_ * ds_c, entity_maps=entity_maps))
        vec.scatter_reverse(la.InsertMode.add)
        return vec.array[: Q.dofmap.index_map.size_local]

    return assemble(expr) / assemble(1.0)


n_owned = Q.dofmap.index_map.size_local
gap = nodal_values(g)
pressure = lam.x.array[:n_owned]  # lam <= 0
force = comm.allreduce(
    fem.assemble_scalar(fem.form(-lam * ds_c, entity_maps=entity_maps)), MPI.SUM
)
min_gap = comm.allreduce(float(gap.min(initial=np.inf)), MPI.MIN)
max_lam = comm.allreduce(float(pressure.max(initial=-np.inf)), MPI.MAX)
max_lam_g = comm.allreduce(float(np.abs(pressure * gap).max(initial=0.0)), MPI.MAX)
say(
    f"Signorini at the nodes: min gap {min_gap:.2e}, max lam {max_lam:.2e}, "
    f"max |lam g| {max_lam_g:.2e}"
)

# %% [markdown]
# ## Check against Hertz
#
# The measured force P sets the Hertz reference. The half-width and the
# peak are measured by a least-squares fit of p^2 = p0^2 - (p0/a)^2 x^2
# over the nodes in contact (`fit_contact_profile`); the largest nodal
# pressure is compared too. Every rank gathers the whole profile.

# %%
x_nodes = np.concatenate(comm.allgather(Q.tabulate_dof_coordinates()[:n_owned, 0]))
p_nodes = -np.concatenate(comm.allgather(pressure))  # magnitudes >= 0
order = np.argsort(x_nodes)
x_nodes, p_nodes = x_nodes[order], p_nodes[order]
if p_nodes[0] > 0 or p_nodes[-1] > 0:
    raise RuntimeError("The contact zone reaches the end of the multiplier band: widen it.")
fit = fit_contact_profile(x_nodes, p_nodes)
hertz = hertz_line_contact(force, R, E, nu)
rows = [
    ("half-width a (fit)", fit.a, hertz.a, relative_error(fit.a, hertz.a)),
    ("peak p0 (fit)", fit.p0, hertz.p0, relative_error(fit.p0, hertz.p0)),
    ("peak p0 (largest nodal)", fit.nodal_peak, hertz.p0, relative_error(fit.nodal_peak, hertz.p0)),
]
say(f"\nContact force P = {force:.5f} per unit thickness, {fit.n_contact} nodes in contact")
say(f"{'quantity':<25} {'FE':>9} {'Hertz':>9} {'error':>8}")
for name, fe, exact, err in rows:
    say(f"{name:<25} {fe:>9.5f} {exact:>9.5f} {100 * err:>7.2f}%")
worst = max(abs(err) for *_, err in rows)
say(f"Largest error {100 * worst:.2f}% ({'within' if worst < 0.02 else 'OUTSIDE'} 2%)")

# %% [markdown]
# ## Outputs
#
# Rank 0 writes `summary.json` (the numbers above) and `pressure.png`, the
# nodal pressures against the Hertz profile.

# %%
if comm.rank == 0:
    args.out.mkdir(parents=True, exist_ok=True)
    summary = {
        "mesh": {"h_contact": h_contact, "displacement_dofs": n_u, "multiplier_dofs": n_lam},
        "r": float(r.value),
        "mpi_ranks": comm.size,
        "iterations_per_step": iterations,
        "P": force,
        "hertz": {"a": hertz.a, "p0": hertz.p0},
        "measured": {"a": fit.a, "p0": fit.p0, "p0_nodal": fit.nodal_peak,
                     "nodes_in_contact": fit.n_contact},
        "relative_error": {
            key: row[3] for key, row in zip(["a", "p0", "p0_nodal"], rows, strict=True)
        },
        "signorini": {"min_gap": min_gap, "max_lam": max_lam, "max_lam_gap": max_lam_g},
    }
    (args.out / "summary.json").write_text(json.dumps(summary, indent=2))

    fig, ax = plt.subplots(figsize=(6, 4))
    xs = np.linspace(-1.6 * hertz.a, 1.6 * hertz.a, 401)
    near = np.abs(x_nodes) <= 1.6 * hertz.a
    ax.plot(xs, hertz.pressure(xs), "k-", label=f"Hertz, P = {force:.4f}")
    ax.plot(x_nodes[near], p_nodes[near], "o", ms=3.5, color="tab:red", label="nodal -lam")
    ax.set_xlabel("x (reference configuration)")
    ax.set_ylabel("contact pressure")
    ax.set_title(f"Hertz cylinder in UFL: a = {fit.a:.4f} (Hertz {hertz.a:.4f})")
    ax.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out / "pressure.png", dpi=150)
    plt.close(fig)
    say(f"Wrote {args.out / 'summary.json'} and {args.out / 'pressure.png'}")
