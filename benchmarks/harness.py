"""Shared benchmark plumbing: repeats, medians, the time split, JSON and markdown output.

Every figure is the median over repeats (>= 3). Wall time of a solve is
split into assembly (residual + Jacobian), linear solver (set-up + solve)
and the rest (Python, diagnostics, stepping), from the Newton kernel's
:class:`~fenics_contact.solvers.timing.KernelTimings`. Form compilation
(FFCx JIT; cached on disk after the first run) happens while a problem is
built and is reported apart as ``build_s``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path

OUT = Path(__file__).resolve().parents[1] / "results" / "bench"


def median_dict(runs: Sequence[dict]) -> dict:
    """Field-wise median of numeric entries over runs; other entries from the first run."""
    out: dict = {}
    for key, value in runs[0].items():
        values = [r[key] for r in runs]
        if isinstance(value, bool) or not isinstance(value, int | float):
            out[key] = value
        else:
            out[key] = statistics.median(values)
    return out


def split(total_s: float, timings: dict) -> dict[str, float]:
    """Assembly / linear / rest split of a solve's wall time (seconds)."""
    assembly = timings["residual_s"] + timings["jacobian_s"]
    linear = timings["setup_s"] + timings["solve_s"]
    return {
        "total_s": total_s,
        "assembly_s": assembly,
        "linear_s": linear,
        "linear_setup_s": timings["setup_s"],
        "linear_solve_s": timings["solve_s"],
        "rest_s": total_s - assembly - linear,
    }


def repeat(fn: Callable[[], dict], repeats: int) -> tuple[dict, list[dict]]:
    """Run ``fn`` ``repeats`` times; return the median record and all records."""
    runs = [fn() for _ in range(repeats)]
    return median_dict(runs), runs


def machine() -> dict:
    """What ran the benchmark."""
    return {
        "host": platform.node(),
        "cpus": os.cpu_count(),
        "python": platform.python_version(),
        "date": time.strftime("%Y-%m-%d %H:%M:%S"),
        "argv": sys.argv[1:],
    }


def write(name: str, data: dict, table: str, out: Path = OUT) -> None:
    """Write ``<out>/<name>.json`` and ``<out>/<name>.md``."""
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{name}.json").write_text(json.dumps(data, indent=2, default=float) + "\n")
    (out / f"{name}.md").write_text(table.rstrip() + "\n")


def figure_parser(doc: str, sizes: Sequence[float] | None = None) -> argparse.ArgumentParser:
    """The command line of a validation script: --out, --figure and, given sizes, --sizes."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("results/bench"))
    parser.add_argument("--figure", type=Path, default=None)
    if sizes is not None:
        parser.add_argument("--sizes", default=",".join(map(str, sizes)),
                            type=lambda v: [float(x) for x in v.split(",")])
    return parser


def save_figure(fig, path: Path) -> None:
    """Write a matplotlib figure (the folder made when missing) and say so."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    print(f"Wrote {path}")


def report(name: str, runs: Sequence[dict], header: Sequence[str], columns: Sequence[str],
           out: Path = OUT, drop: Sequence[str] = ()) -> str:
    """Tabulate ``columns`` of each run, write ``<out>/<name>.json``/``.md``; return the table.

    ``drop``: keys of the runs (long profiles) left out of the JSON.
    """
    table = md_table(header, [[r[c] for c in columns] for r in runs])
    summary = [{k: v for k, v in r.items() if k not in drop} for r in runs]
    write(name, {"machine": machine(), "runs": summary}, table, out)
    return table


def md_table(header: Sequence[str], rows: Sequence[Sequence[object]]) -> str:
    """A markdown table; floats to 4 significant digits."""

    def cell(v: object) -> str:
        return f"{v:.4g}" if isinstance(v, float) else str(v)

    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(cell(v) for v in row) + " |" for row in rows]
    return "\n".join(lines)
