"""Form compilation cost: build the 2D Hertz problem with an empty JIT cache, then warm.

Each build runs in a fresh process whose ``XDG_CACHE_HOME`` points at a new
directory, so the first build compiles every form (FFCx + C compiler) and
the later ones load them from that cache. Median of the warm builds.

Run: ``python benchmarks/performance/compile_cost.py [--repeats 3]``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from benchmarks import harness

CHILD = """
import json, time, sys
sys.path.insert(0, {root!r})
start = time.perf_counter()
import fenics_contact
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers import make_strategy
from benchmarks import cases
from benchmarks.validation.hertz2d import CYLINDER
import_s = time.perf_counter() - start
start = time.perf_counter()
problem = cases.build(CYLINDER, 1.0)
strategy = make_strategy("gnrm", problem, SolverSettings())
print(json.dumps({{"import_s": import_s, "build_s": time.perf_counter() - start,
                  "kernel_compile_s": strategy.kernel.timings.compile_s}}))
"""


def build_once(cache: str) -> dict:
    """One build in a fresh process with ``XDG_CACHE_HOME=cache``."""
    env = dict(os.environ, XDG_CACHE_HOME=cache)
    code = CHILD.format(root=str(Path(__file__).resolve().parents[2]))
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    """Cold build, then warm builds."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--out", type=Path, default=harness.OUT)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as cache:
        cold = build_once(cache)
        warm = [build_once(cache) for _ in range(args.repeats)]
    med = {k: statistics.median(w[k] for w in warm) for k in warm[0]}
    rows = [("cold (empty cache)", cold["build_s"], cold["kernel_compile_s"]),
            ("warm (median)", med["build_s"], med["kernel_compile_s"])]
    table = harness.md_table(("2D Hertz build", "build s (mesh + all forms)",
                              "GNRM kernel forms s"), rows)
    harness.write("compile_cost", {"cold": cold, "warm": warm, "warm_median": med}, table,
                  args.out)
    print(table)


if __name__ == "__main__":
    main()
