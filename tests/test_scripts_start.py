"""Every benchmark and demo starts in a fresh interpreter, as the docs run them.

A script that imports ``dolfinx`` before ``fenics_contact`` stops at once
with ``ImportError: libmpi.so.12`` on the wheel install; each one is run
here as ``python SCRIPT --help`` in its own process to catch that.
"""

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).parent.parent
#: The benchmark scripts (the files with a ``__main__`` block, in every folder) and the demos.
SCRIPTS = sorted(
    path for path in (ROOT / "benchmarks").rglob("*.py") if "__main__" in path.read_text()
) + sorted((ROOT / "demos").glob("*.py"))


def test_every_benchmark_and_demo_starts_in_a_fresh_process():
    assert len(SCRIPTS) >= 10
    # as the docs run them: from the repository root, nothing added to the path
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    runs = {
        script.relative_to(ROOT): subprocess.Popen(
            [sys.executable, str(script), "--help"], cwd=ROOT, env=env,
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        )
        for script in SCRIPTS
    }
    failed = {}
    for name, proc in runs.items():
        out, err = proc.communicate(timeout=300)
        if proc.returncode != 0:
            failed[str(name)] = err.strip().splitlines()[-1:]
        elif "__main__" in (ROOT / name).read_text():
            assert out.startswith("usage:"), name
    assert not failed, failed

