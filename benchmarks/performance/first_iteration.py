"""Time to the first Newton iteration of every shipped scene, on an empty and a warm form cache.

Each run is a fresh process (as ``fenics-contact run``): import, read the
scene, mesh it, build the problem and its forms, and solve until the first
Newton iteration of the first load step has finished (then the run is
stopped). ``cold``: ``XDG_CACHE_HOME`` points at a new, empty directory, so
every form is compiled (FFCx and the C compiler); ``warm``: the same cache
again (median of ``--repeats``). Writes ``OUT/first_iteration.json`` and
``.md``.

``--scan-too`` adds, per scene, a cold run with FFCx's own node lookup in
its value numbering (:mod:`fenics_contact.form_compiler` replaces it by a
dictionary): the first start before and after, measured side by side.

``--friction MU`` runs each scene with Coulomb friction of coefficient MU
added to every pair that has none (a copy of the scene file, beside it):
the frictional 3D two-body start that users meet.

``--before TREE`` adds, per scene, a cold run of another checkout's code
(``git worktree add TREE COMMIT``) on the same scene file: a change's first
start before and after, side by side.

Run: ``python benchmarks/performance/first_iteration.py [--repeats 2]
[--scenes two_hemispheres_3d,block_on_block_3d] [--friction 0.3] [--scan-too]
[--before TREE] [--out results/bench]``.
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

ROOT = Path(__file__).resolve().parents[2]

CHILD = """
import json, sys, time, tempfile
start = time.perf_counter()
import fenics_contact
if {scan!r}:
    fenics_contact.form_compiler.uninstall()
from fenics_contact.runner import run_scene
from fenics_contact.scene.schema import load_scene
imported = time.perf_counter() - start

class First(Exception):
    pass

def observer(iteration, norm):
    if iteration >= 1:
        raise First

try:
    with tempfile.TemporaryDirectory() as out:
        run_scene(load_scene({scene!r}), __import__("pathlib").Path(out), on_residual=observer,
                  pictures=False)
    status = "finished before"
except First:
    status = "first iteration"
print(json.dumps({{"import_s": imported, "first_iteration_s": time.perf_counter() - start,
                  "status": status}}))
"""


def once(scene: Path, cache: str, scan: bool = False, code: Path = ROOT) -> dict:
    """One run in a fresh process with ``XDG_CACHE_HOME=cache``.

    ``scan``: with FFCx's own node lookup in its value numbering (a scan of
    the whole graph per lookup) instead of the dictionary the package
    installs (:mod:`fenics_contact.form_compiler`). ``code``: the source
    tree whose ``fenics_contact`` runs (another checkout, for a before/after).
    """
    env = dict(os.environ, XDG_CACHE_HOME=cache, PYTHONPATH=str(code))
    out = subprocess.run([sys.executable, "-c", CHILD.format(scene=str(scene), scan=scan)],
                         env=env, cwd=code,
                         capture_output=True, text=True, check=False)
    if out.returncode != 0:
        return {"first_iteration_s": float("nan"), "status": "failed: "
                + (out.stderr.strip().splitlines() or ["?"])[-1]}
    return json.loads(out.stdout.strip().splitlines()[-1])


def with_friction(scene: Path, mu: float, folder: Path) -> Path:
    """A copy of ``scene`` in ``folder`` whose pairs without ``mu`` get ``mu``.

    The copy keeps the scene's relative paths (they are made absolute).
    """
    lines = []
    for line in scene.read_text().splitlines():
        if line.strip().startswith("file = \"../"):
            line = line.replace('"../', f'"{scene.parent.parent}/')
        lines.append(line)
        if line.strip() == "[[pair]]":
            lines.append(f"mu = {mu!r}")
    text = "\n".join(lines) + "\n"
    if text.count("\nmu = ") > text.count("[[pair]]"):
        raise SystemExit(f"{scene.name}: a pair has its own mu; leave --friction out")
    copy = folder / f"{scene.stem}_mu{mu:g}.toml"
    copy.write_text(text)
    return copy


def main() -> None:
    """Cold and warm, scene after scene."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--scenes", default=None, help="comma-separated names (default: all)")
    parser.add_argument("--out", type=Path, default=harness.OUT)
    parser.add_argument("--friction", type=float, default=None, metavar="MU",
                        help="add Coulomb friction MU to every pair (3D two-body with friction)")
    parser.add_argument("--scan-too", action="store_true",
                        help="also a cold run with FFCx's own node lookup, side by side")
    parser.add_argument("--before", type=Path, default=None, metavar="TREE",
                        help="also a cold run of each scene with the fenics_contact of another "
                             "checkout (git worktree add TREE COMMIT), side by side")
    args = parser.parse_args()
    names = (args.scenes.split(",") if args.scenes
             else sorted(p.stem for p in (ROOT / "scenes").glob("*.toml")))
    runs = []
    copies = tempfile.TemporaryDirectory()
    for name in names:
        scene = ROOT / "scenes" / f"{name}.toml"
        if args.friction is not None:
            scene = with_friction(scene, args.friction, Path(copies.name))
            name = scene.stem
        with tempfile.TemporaryDirectory() as cache:
            cold = once(scene, cache)
            warm = [once(scene, cache) for _ in range(args.repeats)]
        warm_s = statistics.median(w["first_iteration_s"] for w in warm)
        runs.append({"scene": name, "cold_s": round(cold["first_iteration_s"], 1),
                     "warm_s": round(warm_s, 2), "import_s": round(cold.get("import_s", 0), 2),
                     "status": cold["status"]})
        if args.scan_too:
            with tempfile.TemporaryDirectory() as cache:
                scan = once(scene, cache, scan=True)
            runs[-1]["cold_scan_s"] = round(scan["first_iteration_s"], 1)
            runs[-1]["cold_ratio"] = round(cold["first_iteration_s"] / scan["first_iteration_s"], 2)
        if args.before is not None:
            with tempfile.TemporaryDirectory() as cache:
                before = once(scene, cache, code=args.before.resolve())
            runs[-1]["cold_before_s"] = round(before["first_iteration_s"], 1)
            runs[-1]["cold_ratio"] = round(cold["first_iteration_s"]
                                           / before["first_iteration_s"], 2)
        print(runs[-1], flush=True)
    header = ["scene", "cold s", "warm s (median)", "import s", "status"]
    columns = ["scene", "cold_s", "warm_s", "import_s", "status"]
    if args.scan_too:
        header += ["cold s, FFCx's scan", "cold ratio"]
        columns += ["cold_scan_s", "cold_ratio"]
    if args.before is not None:
        header += [f"cold s, {args.before.name}", "cold ratio"]
        columns += ["cold_before_s", "cold_ratio"]
    table = harness.report("first_iteration", runs, header, columns, args.out)
    print(table)


if __name__ == "__main__":
    main()
