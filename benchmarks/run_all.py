"""Run every benchmark in sequence (one process per case) and gather the tables.

``python benchmarks/run_all.py [--quick]
[--only hertz2d,cost,predict,auto,compile,first,mortar,hertz3d,ladder,mpi,speedup,inexact,
twobody]``.
The ladder's large sizes take minutes each; ``--quick`` stops at 1e5 DOFs.
Ends with ``benchmarks/targets.py``: every target, its figure before and
now from the records, and whether it is met (``results/bench/targets.md``).
Serial and 2-rank runs of a size are run one after the other, on a machine
that others may be using: compare them side by side, not across days.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
PYTHON = sys.executable
MPIEXEC = str(Path(PYTHON).parent / "mpiexec")

#: (DOFs, solver, ranks, repeats) of the ladder, in the order they run. The
#: million-DOF cases and MUMPS beyond 3e4 DOFs run once (minutes each).
LADDER = [
    (1e4, "iterative", 1, 3), (3e4, "iterative", 1, 3), (1e5, "iterative", 1, 3),
    (1e4, "direct", 1, 3), (3e4, "direct", 1, 3),
    (1e6, "iterative", 1, 1), (1e6, "iterative", 2, 1),
    (3e5, "iterative", 1, 3), (3e5, "iterative", 2, 3),
    (1e5, "iterative", 2, 3), (1e5, "direct", 1, 1),
]
#: Serial and 2-rank runs of the same size back to back (the speed-up figures).
SPEEDUP = [(1e5, 3), (1e6, 1)]
#: Inexact Newton (issue 21, item 3): the iterative solver's variants interleaved
#: (DOFs, ranks, rounds), then the inexact solver's single cases for memory per rank
#: and the 1M-DOF point on 2 ranks beside the fixed-tolerance one.
INEXACT = [(1e5, 1, 3), (1e5, 2, 3)]
#: Two bodies at scale (issue 21, item 4): two hemispheres against one sphere on a
#: plane, 1e5 DOFs, iterative solver, on 1 and then 2 ranks (each alternates the cases).
TWO_BODY = ["--dim", "3", "--h", "0.013", "--solver", "iterative", "--steps", "4",
            "--repeats", "3"]
INEXACT_LADDER = [(1e5, "inexact", 1, 3), (1e5, "inexact", 2, 3), (1e6, "inexact", 2, 1),
                  (1e6, "iterative", 2, 1)]


def call(cmd: list[str]) -> None:
    """Run one benchmark process, echoing its command."""
    print("$", " ".join(cmd), flush=True)
    subprocess.run(cmd, cwd=ROOT, check=False)


def ladder_case(dofs: float, solver: str, ranks: int, repeats: int) -> None:
    """One ladder case in its own process (under mpiexec for ranks > 1)."""
    cmd = [PYTHON, str(HERE / "performance" / "ladder3d.py"), "--dofs", f"{dofs:g}",
           "--solver", solver, "--repeats", str(repeats)]
    call(([MPIEXEC, "-n", str(ranks)] if ranks > 1 else []) + cmd)


def main() -> None:
    """Command line."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--only",
                        default="hertz2d,cost,predict,auto,compile,first,mortar,hertz3d,ladder,"
                                "mpi,speedup,inexact,twobody")
    args = parser.parse_args()
    parts = set(args.only.split(","))
    limit = 1e5 if args.quick else 1e6
    if "hertz2d" in parts:
        call([PYTHON, str(HERE / "validation" / "hertz2d.py")])
    if "cost" in parts:
        call([PYTHON, str(HERE / "performance" / "cost_of_contact.py")])
    if "predict" in parts:
        call([PYTHON, str(HERE / "performance" / "active_set_prediction.py")])
        call([PYTHON, str(HERE / "performance" / "exact_contact_set.py")])
    if "auto" in parts:
        call([PYTHON, str(HERE / "performance" / "auto_r_range.py")])
    if "compile" in parts:
        call([PYTHON, str(HERE / "performance" / "compile_cost.py")])
    if "first" in parts:
        call([PYTHON, str(HERE / "performance" / "first_iteration.py")])
        # the 3D two-body scenes with friction on their pairs (issue 21's cold-start case)
        call([PYTHON, str(HERE / "performance" / "first_iteration.py"), "--friction", "0.3",
              "--scenes", "two_hemispheres_3d_node_to_segment,two_hemispheres_3d,"
              "block_on_block_3d,three_blocks_3d",
              "--out", str(ROOT / "results" / "bench" / "friction")])
    if "mortar" in parts:
        call([PYTHON, str(HERE / "performance" / "mortar_cost.py")])
        call([PYTHON, str(HERE / "performance" / "mortar_cost.py"), "--case", "hemispheres"])
        call([PYTHON, str(HERE / "validation" / "mortar_patch.py")])
        call([PYTHON, str(HERE / "validation" / "mortar_hemispheres.py")])
        call([PYTHON, str(HERE / "validation" / "mortar_hertz.py")])
        call([PYTHON, str(HERE / "validation" / "mortar_hertz.py"), "--swap"])
        call([PYTHON, str(HERE / "validation" / "striker_choice.py")])
        call([PYTHON, str(HERE / "validation" / "bridge_rim.py")])
    if "hertz3d" in parts:
        call([PYTHON, str(HERE / "validation" / "hertz3d.py")])
    for dofs, solver, ranks, repeats in LADDER:
        wanted = "mpi" in parts if ranks > 1 else "ladder" in parts
        if wanted and dofs <= limit:
            ladder_case(dofs, solver, ranks, repeats)
    for dofs, repeats in SPEEDUP if "speedup" in parts else []:
        if dofs <= limit:
            ladder_case(dofs, "iterative", 1, repeats)
            ladder_case(dofs, "iterative", 2, repeats)
    for dofs, ranks, rounds in INEXACT if "inexact" in parts else []:
        cmd = [PYTHON, str(HERE / "performance" / "inexact_newton.py"), "--dofs", f"{dofs:g}",
               "--rounds", str(rounds)]
        call(([MPIEXEC, "-n", str(ranks)] if ranks > 1 else []) + cmd)
    for dofs, solver, ranks, repeats in INEXACT_LADDER if "inexact" in parts else []:
        if dofs <= limit:
            ladder_case(dofs, solver, ranks, repeats)
    for ranks in (1, 2) if "twobody" in parts else ():
        cmd = [PYTHON, str(HERE / "performance" / "two_body.py"), *TWO_BODY]
        call(([MPIEXEC, "-n", str(ranks)] if ranks > 1 else []) + cmd)
    if parts & {"ladder", "mpi", "speedup", "inexact"}:
        call([PYTHON, str(HERE / "performance" / "ladder3d.py"), "--table"])
    call([PYTHON, str(HERE / "targets.py")])  # the targets, before and now, from the records


if __name__ == "__main__":
    main()
