"""A pvpython script beside ``solution.xdmf`` that opens the run in ParaView.

``DIR/paraview_state.py`` opens ``DIR/solution.xdmf``, warps the mesh by the
displacement (true scale), colours it by the contact pressure -lam >= 0
(stress; zero off the contact surface) and shows the last finished load step
(or ``--step N``). Run it with ``pvpython DIR/paraview_state.py [--step N]
[--png FILE]`` (``--png`` saves a screenshot and exits), or in the ParaView
GUI with *File > Load State...* (Python state) or the Python shell's *Run
Script*. The script names only files and fields the run writes; it finds the
files beside itself, so the folder may be moved.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

#: The script's file name, beside the index ``solution.xdmf``.
SCRIPT = "paraview_state.py"

_TEMPLATE = '''"""Open this run in ParaView: warped by displacement, coloured by contact pressure.

Written by fenics-contact beside {index}. Usage:

    pvpython {script} [--step N] [--png FILE]

or, in the ParaView GUI, File > Load State... (Python state file) or
View > Python Shell > Run Script. Without --step the last finished load step
is shown; --png saves a screenshot and exits. The colour is the contact
pressure p = -lam >= 0 (stress, zero off the contact surface).
"""

import argparse
import os
import sys

from paraview.simple import (
    ColorBy,
    GetActiveViewOrCreate,
    GetAnimationScene,
    OpenDataFile,
    Render,
    ResetCamera,
    SaveScreenshot,
    Show,
    WarpByVector,
)

INDEX = {index!r}
DISPLACEMENT = {displacement!r}  # None: the run wrote no displacement
PRESSURE = {pressure!r}  # None: the run wrote no contact pressure
DIMENSION = {dimension}

here = os.path.dirname(os.path.abspath(globals().get("__file__", INDEX)))
parser = argparse.ArgumentParser(description="Open the run in ParaView.")
parser.add_argument("--step", type=int, default=None, help="load step, 1-based (default last)")
parser.add_argument("--png", default=None, help="save a screenshot to this file and exit")
args, _ = parser.parse_known_args(sys.argv[1:])

reader = OpenDataFile(os.path.join(here, INDEX))
values = reader.TimestepValues  # a number when the run has one step
times = (list(values) if hasattr(values, "__len__") else [values]) or [0.0]
step = len(times) if args.step is None else args.step
if not 1 <= step <= len(times):
    sys.exit(f"--step {{step}}: the run has load steps 1-{{len(times)}}")
scene = GetAnimationScene()
scene.UpdateAnimationUsingDataTimeSteps()
scene.AnimationTime = times[step - 1]

shown = reader
if DISPLACEMENT is not None:
    shown = WarpByVector(Input=shown)
    shown.Vectors = ["POINTS", DISPLACEMENT]
    shown.ScaleFactor = 1.0

view = GetActiveViewOrCreate("RenderView")
display = Show(shown, view)
if PRESSURE is not None:
    ColorBy(display, ("POINTS", PRESSURE))
    display.RescaleTransferFunctionToDataRange(True, False)
    display.SetScalarBarVisibility(view, True)
if DIMENSION == 2:
    view.InteractionMode = "2D"
    view.CameraPosition = [0.0, 0.0, 1.0]
    view.CameraFocalPoint = [0.0, 0.0, 0.0]
    view.CameraViewUp = [0.0, 1.0, 0.0]
ResetCamera(view)
Render(view)
if args.png:
    SaveScreenshot(args.png, view, ImageResolution=[1200, 800])
'''


def paraview_script(index: Path, fields: Sequence[str], dimension: int) -> str:
    """The text of the pvpython script for the run whose index is ``index``.

    Args:
        index: the run's ``solution.xdmf`` (only its name is written: the
            script looks beside itself).
        fields: the fields the run writes (scene ``fields``).
        dimension: 2 or 3 (2: the camera looks along z in 2D mode).
    """
    return _TEMPLATE.format(
        index=index.name, script=SCRIPT, dimension=int(dimension),
        displacement="displacement" if "displacement" in fields else None,
        pressure="contact_pressure" if "contact_pressure" in fields else None,
    )


def write_paraview_script(index: Path, fields: Sequence[str], dimension: int) -> Path:
    """Write :data:`SCRIPT` beside ``index`` (one process); returns its path."""
    path = index.parent / SCRIPT
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(paraview_script(index, fields, dimension), encoding="utf-8")
    return path


__all__ = ["SCRIPT", "paraview_script", "write_paraview_script"]
