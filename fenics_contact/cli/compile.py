"""``fenics-contact compile SCENE...``: fill the form cache so that runs start at once."""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path


def _compile(args: argparse.Namespace) -> int:
    from mpi4py import MPI

    from fenics_contact.precompile import precompile
    from fenics_contact.scene.schema import load_scene

    scenes = [load_scene(path) for path in args.scenes]  # every file checked before any build
    comm = MPI.COMM_WORLD
    if len(scenes) > 1 and comm.size == 1:
        # one fresh process per scene: FFCx names a compiled expression (the stress
        # and det F fields) after the objects of its process, so a second scene's
        # expressions in one process would not be the ones its own run looks for
        codes = [subprocess.run([sys.executable, "-m", "fenics_contact.cli", "compile",
                                 str(path)], check=False).returncode for path in args.scenes]
        return max(codes)
    root = comm.rank == 0
    failed = 0
    for path, scene in zip(args.scenes, scenes, strict=True):
        done = precompile(scene, comm)
        failed += done.status != "compiled"
        if root:
            note = "" if done.status == "compiled" else (
                f" (its first load step ended {done.status}; the forms are compiled)")
            print(f"{path}: forms compiled in {done.seconds:.1f} s{note}", flush=True)
    return 1 if failed else 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``compile`` subcommand."""
    compile_ = sub.add_parser(
        "compile",
        help="compile the forms of scenes into the form cache (faster first runs)",
        description="Compile the UFL forms each scene's run needs into the form cache "
        "($XDG_CACHE_HOME/fenics, by default ~/.cache/fenics): the scene is built and its "
        "first load step solved into a temporary folder, which is then removed. Later runs "
        "of these scenes (and of any scene with the same forms) load the compiled forms "
        "instead of compiling them. Exit code 0 when every first step converged, 1 when "
        "one did not (its forms are compiled all the same), 2 for a bad scene.",
    )
    compile_.add_argument("scenes", type=Path, nargs="+", metavar="scene",
                          help="scene files (e.g. scenes/*.toml)")
    compile_.set_defaults(func=_compile)
