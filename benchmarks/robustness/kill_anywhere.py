"""Kill a running `fenics-contact run` at random moments; read back and resume each time.

Each trial starts the 3D block scene (12 load steps) as its own process
(or under ``mpiexec -n N``), sends SIGKILL after a random delay (to the
whole run, or with ``--one-rank`` to a single MPI process), then reads
every step the index names with h5py, meshio and VTK
(tests/read_solution.py, a separate interpreter), compares each field with
an uninterrupted run, resumes from the checkpoint and compares the Newton
iterations of every step. The delays cover the whole run, start-up and
file writes included.

Run: ``python benchmarks/robustness/kill_anywhere.py [--trials 20] [--processes 2 [--one-rank]]``.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
READER = ROOT / "tests" / "read_solution.py"
CLI = [sys.executable, "-c", "import sys; from fenics_contact.cli import main; sys.exit(main())"]
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}


def command(args: list[str], processes: int) -> list[str]:
    launcher = [str(Path(sys.executable).parent / "mpiexec"), "-n", str(processes)]
    return [*(launcher if processes > 1 else []), *CLI, *args]


def run(args: list[str], processes: int) -> subprocess.CompletedProcess:
    return subprocess.run(command(args, processes), env=ENV, capture_output=True, text=True)


def children(pid: int) -> list[int]:
    found = subprocess.run(["pgrep", "-P", str(pid)], capture_output=True, text=True).stdout
    pids = [int(p) for p in found.split()]
    return pids + [q for p in pids for q in children(p)]


def trial(scene: Path, out: Path, reference: Path, delay: float, processes: int,
          one_rank: bool) -> dict:
    args = ["run", str(scene), "--out", str(out), "--quiet", "--no-pictures"]
    proc = subprocess.Popen(command(args, processes), env=ENV, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    time.sleep(delay)
    target = proc.pid
    if one_rank:  # the youngest python process of the job: one MPI rank
        ranks = [p for p in children(proc.pid)
                 if "fenics_contact" in Path(f"/proc/{p}/cmdline").read_text(errors="ignore")]
        target = max(ranks) if ranks else proc.pid
    try:
        os.kill(target, signal.SIGKILL)
    except ProcessLookupError:
        pass
    proc.wait()
    read = subprocess.run([sys.executable, str(READER), str(out / "solution.xdmf"),
                           str(reference / "solution.xdmf")], capture_output=True, text=True)
    record: dict = {"delay_s": delay, "readable": read.returncode == 0}
    if read.returncode == 0:
        report = json.loads(read.stdout)
        steps = report["meshio"]
        record["steps_on_disk"] = len(steps)
        record["readers_agree"] = len(report["h5py"]) == len(steps) == len(report["vtk"])
        record["max_difference"] = max(
            (max(s["difference"].values()) for s in steps), default=0.0
        )
    else:
        record["error"] = read.stderr.strip().splitlines()[-1:]
    resumed = run(["run", str(scene), "--resume", str(out), "--quiet", "--no-pictures"],
                  processes)
    record["resume_exit"] = resumed.returncode
    if record.get("steps_on_disk") == 0:  # killed before a step finished: nothing to resume
        record["same_iterations"] = (
            resumed.returncode == 2 and "No checkpoint" in resumed.stderr
        )
    elif resumed.returncode == 0:
        mine = json.loads((out / "summary.json").read_text())["steps"]
        full = json.loads((reference / "summary.json").read_text())["steps"]
        record["same_iterations"] = [s["iterations"] for s in mine] == [
            s["iterations"] for s in full
        ]
    return record


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--trials", type=int, default=10)
    parser.add_argument("--processes", type=int, default=1)
    parser.add_argument("--one-rank", action="store_true",
                        help="kill one MPI process instead of the whole run")
    parser.add_argument("--out", type=Path, default=ROOT / "results" / "bench")
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    random.seed(args.seed)
    work = Path(tempfile.mkdtemp(prefix="kill_anywhere_"))
    scene = work / "block.toml"
    scene.write_text((ROOT / "scenes" / "block_3d.toml").read_text().replace(
        "steps = 6", "steps = 12"))
    reference = work / "reference"
    start = time.perf_counter()
    done = run(["run", str(scene), "--out", str(reference), "--quiet", "--no-pictures"],
               args.processes)
    if done.returncode != 0:
        sys.exit(done.stderr)
    full_s = time.perf_counter() - start
    records = []
    for k in range(args.trials):
        delay = random.uniform(0.3, 1.1) * full_s
        record = trial(scene, work / f"trial_{k}", reference, delay, args.processes,
                       args.one_rank)
        records.append(record)
        print(json.dumps(record), flush=True)
    good = [r for r in records if r["readable"] and r.get("readers_agree")
            and r.get("max_difference", 1.0) <= 1e-10 and r.get("same_iterations")]
    print(f"{len(good)} of {len(records)} trials: every finished step readable by h5py, "
          f"meshio and VTK, equal to the uninterrupted run, resumed to the same iterations")
    args.out.mkdir(parents=True, exist_ok=True)
    name = f"kill_anywhere_n{args.processes}{'_one_rank' if args.one_rank else ''}.json"
    (args.out / name).write_text(json.dumps(
        {"processes": args.processes, "one_rank": args.one_rank,
         "uninterrupted_s": full_s, "trials": records}, indent=2) + "\n")
    sys.exit(0 if len(good) == len(records) else 1)


if __name__ == "__main__":
    main()
