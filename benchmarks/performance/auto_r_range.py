"""``auto`` across r: Newton iterations at every r from 1e-8 to 1e12 E/h against r = 1 E/h.

Three scenes, each run as one case of the stability grid
(:func:`fenics_contact.sweeps.stability.run_case`: the scaled stopping
test, at most 100 iterations a step, no cut-backs): the two cylinders of
``tests/test_auto.py`` (node-to-segment, h = 0.01, 10 steps), the 2D Hertz
cylinder and the sliding blocks (Coulomb friction 0.3) of
``benchmarks/robustness/stability_grid.py``. Reported per scene and r: the
status and the Newton iterations over the load path, and per scene the
largest count over that at r = 1 E/h. Target (issue 21): at most 1.3 on
every scene, every run converged.

Run: ``python benchmarks/performance/auto_r_range.py [--out results/bench]``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import fenics_contact  # noqa: F401  (loads the DOLFINx wheel's MPI libraries: first)

# isort: split
from benchmarks import cases, harness
from fenics_contact.sweeps.stability import StabilityCase, run_case

#: r relative to E/h (dimensionless): every even power of ten from 1e-8 to 1e12.
R_VALUES = tuple(10.0**e for e in range(-8, 13, 2))
TARGET_RATIO = 1.3
SCENES = {
    "two-cylinders": lambda: cases.two_cylinders(0.01, push=0.02, steps=10, h_far=0.1),
    "hertz": lambda: cases.hertz_cylinder(0.01),
    "sliding-blocks": lambda: cases.sliding_blocks(),
}


def main() -> None:
    """Every scene at every r with ``auto``; JSON and a markdown table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=harness.OUT)
    args = parser.parse_args()
    records, rows = {}, []
    for name, scene in SCENES.items():
        runs = {f"{r:g}": run_case(StabilityCase(f"{name}-r{r:g}", "auto-r", scene(), r), "auto")
                for r in R_VALUES}
        iterations = {r: run.iterations for r, run in runs.items()}
        status = {r: run.status for r, run in runs.items()}
        ratio = max(iterations.values()) / max(iterations["1"], 1)
        records[name] = {"iterations": iterations, "status": status, "ratio": ratio}
        rows.append((name, " ".join(str(n) for n in iterations.values()), iterations["1"],
                     ratio, "yes" if all(s == "converged" for s in status.values()) else "no"))
    header = ("scene", "Newton at r = " + " ".join(runs), "at r = 1", "largest / r = 1",
              "all converged")
    table = harness.md_table(header, rows)
    harness.write("auto_r_range",
                  {"machine": harness.machine(), "r_values": list(R_VALUES),
                   "target_ratio": TARGET_RATIO, "scenes": records}, table, args.out)
    print(table)


if __name__ == "__main__":
    main()
