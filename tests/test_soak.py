"""A soak: random valid scenes, run end to end, must end cleanly.

Property: for any scene within the documented ranges (r, E, nu, law, mesh,
load steps, obstacle placement, method), a run raises no exception, ends with
a status of the documented set, writes every finished step to disk, and no
output holds NaN or inf; a converged run of a multiplier method with the nodal
rule meets the Signorini conditions in their own units and no accepted step has det F <= 0.

Profiles (environment variable HYPOTHESIS_PROFILE): ``ci`` (default: a few
derandomized examples, no deadline) and ``soak`` (many; ``make soak``).
"""

import json
import math
import os
import re
import tempfile
import warnings
from pathlib import Path

import h5py
import numpy as np
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from fenics_contact.scene.schema import METHODS, load_scene
from fenics_contact.solvers.diagnostics import STATUSES

settings.register_profile(
    "ci", max_examples=4, derandomize=True, deadline=None, print_blob=True,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile(
    "soak", max_examples=int(os.environ.get("SOAK_EXAMPLES", "200")), deadline=None,
    print_blob=True, suppress_health_check=[HealthCheck.too_slow],
)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))


def log_uniform(lo: float, hi: float):
    return st.floats(math.log10(lo), math.log10(hi)).map(lambda e: 10.0**e)


@st.composite
def scenes(draw) -> dict:
    """A valid scene: a block held on top, pushed onto a plane or a ball below."""
    nx, ny = draw(st.integers(2, 6)), draw(st.integers(1, 3))
    lx, ly = draw(st.floats(0.5, 2.0)), draw(st.floats(0.2, 1.0))
    h = lx / nx  # contact facet size on the bottom side
    push = draw(st.floats(0.0, 0.1)) * ly
    gap0 = draw(st.floats(-0.3 * h, 0.05 * ly))  # < h inside: no warning expected
    if draw(st.booleans()):
        tilt = draw(st.floats(-0.1, 0.1))
        obstacle = {
            "type": "plane", "point": [0.5 * lx, -gap0],
            "normal": [math.sin(tilt), math.cos(tilt)],
        }
    else:
        radius = draw(st.floats(0.5, 5.0)) * lx
        shift = draw(st.floats(-0.2, 0.2)) * lx
        obstacle = {"type": "ball", "centre": [0.5 * lx + shift, -radius - gap0],
                    "radius": radius}
    method = draw(st.sampled_from(METHODS))
    return {
        "scene": {"name": "soak", "dimension": 2},
        "mesh": {"generator": "rectangle", "size": [lx, ly], "cells": [nx, ny],
                 "cell": draw(st.sampled_from(["quadrilateral", "triangle"]))},
        "material": {"law": draw(st.sampled_from(["svk", "neo-hookean", "linear"])),
                     "E": draw(log_uniform(1e-1, 1e6)), "nu": draw(st.floats(0.0, 0.45))},
        "dirichlet": [{"tag": "top", "value": [0.0, -push]}],
        "obstacle": obstacle,
        "contact": {"tag": "bottom", "r": draw(log_uniform(1e-2, 1e4)),
                    "quadrature": draw(st.sampled_from(["nodal", "gauss"]))},
        "solver": {"method": method, "steps": draw(st.integers(1, 4)),
                   "max_iterations": 30, "max_cutbacks": draw(st.integers(0, 2)),
                   "predictor": draw(st.sampled_from(["extrapolate", "previous"]))},
        "output": {"pictures": False},
    }


MESHES = Path(__file__).parent.parent / "meshes"


@st.composite
def two_body_scenes(draw) -> dict:
    """A valid two-body scene: a block pressed (and, with friction, slid) on another block."""
    n_upper, n_lower = draw(st.integers(2, 10)), draw(st.integers(2, 10))
    push = draw(st.floats(0.0, 0.03))
    mu = draw(st.one_of(st.none(), st.floats(0.0, 0.6)))
    pair = {"striker": "striker_face", "target": "target_face",
            "r": draw(log_uniform(1e-2, 1e3))}
    if mu is None:
        dirichlet = [{"tag": "bottom", "value": ["free", 0.0]},
                     {"tag": "symmetry", "value": [0.0, "free"]},
                     {"tag": "top", "value": ["free", -push]}]
    else:
        pair["mu"] = mu
        slide = draw(st.floats(0.0, 0.05))
        dirichlet = [{"tag": "bottom", "value": [0.0, 0.0]},
                     {"tag": "top", "path": [[0.0, 0.0, 0.0], [0.5, 0.0, -push],
                                             [1.0, slide, -push]]}]
    laws = st.sampled_from(["svk", "neo-hookean", "linear"])
    bodies = [{"name": name, "tag": tag, "law": draw(laws), "E": draw(log_uniform(1e0, 1e4)),
               "nu": draw(st.floats(0.0, 0.45))}
              for name, tag in (("upper", "striker"), ("lower", "target"))]
    return {
        "scene": {"name": "soak-pair", "dimension": 2},
        "mesh": {"file": str(MESHES / "block_on_block.geo"),
                 "parameters": {"n_upper": n_upper, "n_lower": n_lower}},
        "body": bodies,
        "pair": [pair],
        "dirichlet": dirichlet,
        "solver": {"method": draw(st.sampled_from(METHODS)), "steps": draw(st.integers(1, 3)),
                   "max_iterations": 30, "max_cutbacks": draw(st.integers(0, 2))},
        "output": {"pictures": False},
    }


def _toml(scene: dict) -> str:
    def value(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, str):
            return f'"{v}"'
        if isinstance(v, list):
            return "[" + ", ".join(value(x) for x in v) + "]"
        if isinstance(v, dict):
            return "{ " + ", ".join(f"{k} = {value(x)}" for k, x in v.items()) + " }"
        return repr(float(v)) if isinstance(v, float) else repr(v)

    lines = []
    for name, table in scene.items():
        for t in table if isinstance(table, list) else [table]:
            lines.append(f"[[{name}]]" if isinstance(table, list) else f"[{name}]")
            lines += [f"{k} = {value(v)}" for k, v in t.items()]
    return "\n".join(lines) + "\n"


def _numbers(data, skip=("residuals",)):
    if isinstance(data, dict):
        for k, v in data.items():
            if k not in skip:
                yield from _numbers(v, skip)
    elif isinstance(data, list):
        for v in data:
            yield from _numbers(v, skip)
    else:
        yield data


def check_run(scene: dict) -> None:
    from fenics_contact.runner import run_scene

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "soak.toml"
        path.write_text(_toml(scene))
        out = Path(tmp) / "out"
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # e.g. the initial-penetration warning
            outcome = run_scene(load_scene(path), out, pictures=False)
        summary = json.loads((out / "summary.json").read_text())
        event(f"status {summary['status']}")  # shown by --hypothesis-show-statistics
        assert summary["status"] in STATUSES
        assert summary["status"] == outcome.path.status
        steps = summary["steps"]
        assert all(s["status"] in STATUSES for s in steps)
        # no NaN or inf anywhere (residual histories of failed attempts may diverge)
        for v in _numbers(summary):
            assert not (isinstance(v, str) and v.lower() in ("nan", "inf", "-inf")), summary
            assert not (isinstance(v, float) and not math.isfinite(v)), summary
        for s in steps:
            if s["status"] == "converged":
                assert all(math.isfinite(x) for h in s["residuals"] for x in h)
        done = summary["steps_completed"]
        assert done == sum(s["status"] == "converged" for s in steps)
        assert done == len(steps) - (summary["status"] != "converged")
        # every finished step is on disk, with finite values
        index = out / "solution.xdmf"
        if done == 0:  # no index until the first step is on disk
            assert not index.exists()
        else:
            times = {float(t) for t in re.findall(r'<Time Value="([^"]+)"', index.read_text())}
            assert len(times) == done, (times, done)
        for h5 in out.glob("**/*.h5"):
            with h5py.File(h5, "r") as f:
                def finite(name, obj):
                    if isinstance(obj, h5py.Dataset) and obj.dtype.kind == "f":
                        assert np.all(np.isfinite(obj[()])), name
                f.visititems(finite)
        # accepted steps are not inverted; converged multiplier methods meet Signorini
        assert all(s["min_det_F"] > 0 for s in steps if s["status"] == "converged")
        pair = "pair" in scene
        nodal = pair or scene["contact"]["quadrature"] == "nodal"
        exact = scene["solver"]["method"] != "penalty" and nodal
        if summary["status"] == "converged" and exact:
            h = outcome.problem.surface.h
            # two bodies: depth inside the actual target surface (surface_tol = 1e-3 h)
            assert steps[-1]["max_penetration"] <= (1e-3 if pair else 1e-6) * h + 1e-14


@given(scenes())
def test_random_valid_scenes_end_cleanly(scene):
    check_run(scene)


@settings(max_examples=2 if os.environ.get("HYPOTHESIS_PROFILE", "ci") == "ci"
          else int(os.environ.get("SOAK_EXAMPLES", "200")))
@given(two_body_scenes())
def test_random_two_body_scenes_end_cleanly(scene):
    """Two bodies, a pair, with or without friction and a load path: a named status, no trace."""
    check_run(scene)
