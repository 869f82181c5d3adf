# %% [markdown]
# # The paper's Example 2: a bar pressed into a rigid cradle
#
# This demo illustrates how to:
#
# - load the Example 2 analog of Heegaard, Hovey and Kaplan, the shipped scene
#   `scenes/paper_ex2.toml`: a plane-strain
#   bar of 6 x 2 bilinear quadrilaterals (12 elements, 7 contact nodes on its
#   lower face), St. Venant-Kirchhoff with E = 210, nu = 0.3;
# - solve it with the generalized Newton method (GNRM) on displacement and
#   Alart-Curnier multiplier together, in 10 equal load increments;
# - check that the iteration count does not depend on the augmentation
#   parameter r (absolute r = 1 ... 10000, as in the paper's Table 2);
# - write the fields of every load step to XDMF for ParaView.
#
# The paper's Figure 2 is not available. Our bar hangs 0.02 above a rigid
# cylindrical cradle (radius 10) and the middle third of its top face is
# driven down by 0.8. The bar's ends touch first; the gaps then close toward
# the centre; at the last steps the ends lift off again while the centre
# stays closed, the "gap openings near the extremities and gap closings toward
# the center" of the paper.

# %%
import argparse
from pathlib import Path

import fenics_contact  # noqa: F401  (loads the DOLFINx wheel's MPI libraries: first)

# isort: split
import numpy as np

from mpi4py import MPI

from fenics_contact import build_problem, load_scene
from fenics_contact.output.io import write_json
from fenics_contact.output.xdmf import StepWriter
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.stepping import solve_load_path
from fenics_contact.sweeps.study import paper_table, reference_solution, run_one

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--out", type=Path, default=Path("results/paper-ex2"))
parser.add_argument(
    "--scene", type=Path,
    default=Path(__file__).resolve().parents[1] / "scenes" / "paper_ex2.toml",
)
args = parser.parse_args()
out: Path = args.out


def say(*text: object) -> None:
    """Print once, on rank 0."""
    if MPI.COMM_WORLD.rank == 0:
        print(*text)


# %% [markdown]
# ## One r, step by step
# The contact pattern of each step: `#` a node in contact, `.` an open gap.

# %%
example = load_scene(args.scene)  # r = 100 (absolute), nodal rule, 10 load steps
problem = build_problem(example)
strategy = make_strategy("gnrm", problem, SolverSettings(atol=1e-8, max_iterations=500))
writer = StepWriter(problem, out / "solution.xdmf")
patterns = []


def report(step) -> None:
    state = problem.contact_state()
    pieces = problem.comm.allgather((problem.nodal_coordinates()[:, 0], state.active))
    x = np.concatenate([p[0] for p in pieces])
    active = np.concatenate([p[1] for p in pieces])
    pattern = "".join("#" if a else "." for a in active[np.argsort(x)])
    patterns.append(pattern)
    say(
        f"step {step.step:2d}  iterations {step.iterations}  contact {pattern}  "
        f"force {step.contact_force:8.3f}  max penetration {step.max_penetration:.1e}"
    )
    writer.write(step.load_factor)


path = solve_load_path(strategy, example.solver.steps, max_cutbacks=0, on_step=report)
writer.close()

# %% [markdown]
# ## GNRM over r (the paper's Table 2 row)

# %%
reference = reference_solution(example)
records = []
for r in (1.0, 10.0, 100.0, 1000.0, 10000.0):
    record, _ = run_one(
        example, "gnrm", r, relative=False,
        settings=SolverSettings(atol=1e-8, max_iterations=500), reference=reference,
    )
    records.append(record)

table = paper_table(records)
say()
say(table)
say("\nPer r: status, total iterations, error against the reference, max penetration")
for rec in records:
    say(
        f"  r = {rec.r:<7g} {rec.status}  {rec.iterations:3d}  {rec.error:.1e}  "
        f"{rec.max_penetration:.1e}"
    )

# One process writes the summary (every rank holds the same records).
if MPI.COMM_WORLD.rank == 0:
    write_json(
        out / "summary.json",
        {
            "example": "paper-ex2 (bar on a cradle)",
            "method": "gnrm",
            "contact_patterns": patterns,
            "runs": [rec.to_dict() for rec in records],
        },
    )
    (out / "table.md").write_text(table + "\n")
say(f"\nWrote {out}/summary.json, {out}/table.md and {out}/solution.xdmf (open in ParaView)")
