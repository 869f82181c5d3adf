"""The laboratory's problem families, each a function returning a validated :class:`Scene`.

Every case the studies, sweeps, benchmarks and tests run is a scene, so it
gets the defaults, checks, checkpoints and output of ``fenics-contact run``.
A family is a shipped TOML scene's geometry (``meshes/*.geo`` or a mesh
generator) with its knobs as keyword arguments; ``scene_from_data`` checks it
as it checks a file. The one problem that is not a scene is the paper's
Example 1 (a prescribed striker node on one element): ``striker_on_facet``
in :mod:`benchmarks.research.paper_ex1` builds it explicitly.

Units are the scenes' own (E in stress units, lengths as given); r is
relative to E/h unless a family says otherwise.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from mpi4py import MPI

from fenics_contact import ContactProblem, Scene, build_problem, scene_from_data
from fenics_contact.scene.variants import with_contact_settings

ROOT = Path(__file__).resolve().parents[1]
MESHES = ROOT / "meshes"

#: The paper's material (E = 210, nu = 0.3; Saint Venant-Kirchhoff).
PAPER_E, PAPER_NU = 210.0, 0.3
#: Candidate facets: the case's own tag, detected along the obstacle's path,
#: or every exterior facet.
CANDIDATES = ("tag", "detected", "boundary")
#: Sliding block: press 0.01 (t <= 0.4), then slide 0.02 (t, dx, dy of the plane).
PRESS_SLIDE = ((0.0, 0.0, 0.0), (0.4, 0.0, 0.01), (1.0, 0.02, 0.01))
#: Press, slide +0.02, then back to -0.01: the friction force reverses.
REVERSAL = ((0.0, 0.0, 0.0), (0.3, 0.0, 0.01), (0.65, 0.02, 0.01), (1.0, -0.01, 0.01))
#: Press up by 0.01, then slide by 0.02 while pressing on to 0.015.
OBLIQUE = ((0.0, 0.0, 0.0), (0.4, 0.0, 0.01), (1.0, 0.02, 0.015))
#: Sliding blocks: press 0.01 over load factors 0 ... 0.4, then slide 0.04 (t, dx, dy).
PRESS_SLIDE_PAIR = ((0.0, 0.0, 0.0), (0.4, 0.0, -0.01), (1.0, 0.04, -0.01))
#: Press as above, slide +0.04 by t = 0.7, then back to -0.02: the friction reverses.
REVERSAL_PAIR = ((0.0, 0.0, 0.0), (0.4, 0.0, -0.01), (0.7, 0.04, -0.01), (1.0, -0.02, -0.01))


def _scene(name: str, data: dict[str, Any]) -> Scene:
    """Validate ``data`` as the scene ``name`` (mesh files are absolute paths)."""
    data.setdefault("scene", {})["name"] = name
    return scene_from_data(data, ROOT / "scenes" / f"{name}.toml")


def _contact(candidates: str, tag: str, **extra: Any) -> dict[str, Any]:
    """Contact keys for a candidate mode (see :data:`CANDIDATES`)."""
    if candidates not in CANDIDATES:
        raise ValueError(f"candidates = {candidates!r}: use one of {', '.join(CANDIDATES)}.")
    if candidates == "tag":
        return {"tag": tag, **extra}
    # 'boundary': a margin beyond any body of the lab, so every exterior facet
    margin = 0.0 if candidates == "detected" else 1e6
    return {"detect": True, "margin": margin,
            **{k: v for k, v in extra.items() if k not in "xyz"}}


def _rows(path: Sequence[Sequence[float]]) -> list[list[float]]:
    return [list(map(float, row)) for row in path]


def _solver(steps: int, **extra: Any) -> dict[str, Any]:
    return {"method": "gnrm", "steps": steps, **extra}


# -- one body on rigid obstacles ------------------------------------------------------------


def bar_on_cradle(
    nx: int = 6, ny: int = 2, *, end_gap: float = 0.02, push: float = 0.8,
    E: float = PAPER_E, nu: float = PAPER_NU, law: str = "svk", steps: int = 10,
    candidates: str = "tag", length: float = 6.0, height: float = 1.0, radius: float = 10.0,
    r: float = 100.0, relative: bool = False,
) -> Scene:
    """The paper's Example 2 analog (``scenes/paper_ex2.toml``): a bar pushed into a cradle.

    A bar [-L/2, L/2] x [0, H] of ``nx`` x ``ny`` quadrilaterals hangs
    ``end_gap`` above the inside of a rigid circle of radius ``radius``; the
    middle third of its top face is driven down by ``push`` and held
    horizontally. ``end_gap`` < 0 starts penetrated, 0 grazing.
    """
    half = length / 2
    centre_y = -end_gap + math.sqrt(radius**2 - half**2)
    return _scene(f"bar-{nx}x{ny}", {
        "scene": {"dimension": 2, "description": "SVK bar pressed into a rigid cradle"},
        "mesh": {"generator": "rectangle", "origin": [-half, 0.0], "size": [length, height],
                 "cells": [nx, ny]},
        "material": {"law": law, "E": E, "nu": nu},
        "dirichlet": [{"tag": "top", "value": [0.0, -push], "x": [-half / 3, half / 3]}],
        "obstacle": {"type": "ball", "centre": [0.0, centre_y], "radius": radius,
                     "inside": True},
        "contact": _contact(candidates, "bottom", r=r, relative=relative),
        "solver": _solver(steps),
    })


def block_on_plane(
    n: int = 4, *, delta: float = 0.05, E: float = PAPER_E, nu: float = PAPER_NU,
    law: str = "svk", steps: int = 2, candidates: str = "tag",
) -> Scene:
    """A unit block resting on the plane y = 0 (gap 0), its top pushed down by ``delta``.

    Every lower node ends in contact with a uniform pressure ~ E' delta; the
    left face is held horizontally.
    """
    return _scene(f"block-{n}x{n}", {
        "scene": {"dimension": 2, "description": "a block pressed flat on a rigid plane"},
        "mesh": {"generator": "rectangle", "size": [1.0, 1.0], "cells": [n, n]},
        "material": {"law": law, "E": E, "nu": nu},
        "dirichlet": [{"tag": "top", "value": ["free", -delta]},
                      {"tag": "left", "value": [0.0, "free"]}],
        "obstacle": {"type": "plane", "point": [0.0, 0.0], "normal": [0.0, 1.0]},
        "contact": _contact(candidates, "bottom"),
        "solver": _solver(steps),
    })


def hertz_cylinder(
    h_contact: float = 0.004, *, radius: float = 1.0, E: float = 200.0, nu: float = 0.3,
    push: float = 0.01, h_far: float = 0.1, fine_radius: float = 0.1,
    coarse_radius: float = 0.5, contact_band: float = 0.02, steps: int = 4,
    candidates: str = "tag",
) -> Scene:
    """Plane-strain Hertz (``scenes/hertz_cylinder.toml``): a half-cylinder on a rigid plane.

    Small strain; the flat top y = R moves down by ``push``. Candidate facets:
    the arc below ``contact_band`` R (the band must hold the contact zone).
    """
    return _scene(f"hertz-h{h_contact:g}", {
        "scene": {"dimension": 2, "description": "plane-strain Hertz, half-cylinder on a plane"},
        "mesh": {"file": str(MESHES / "hertz_cylinder.geo"),
                 "parameters": {"radius": radius, "h_contact": h_contact, "h_far": h_far,
                                "fine_radius": fine_radius, "coarse_radius": coarse_radius}},
        "material": {"law": "linear", "E": E, "nu": nu},
        "dirichlet": [{"tag": "top", "value": [0.0, -push]}],
        "obstacle": {"type": "plane", "point": [0.0, 0.0], "normal": [0.0, 1.0]},
        "contact": _contact(candidates, "contact", y=[-radius, contact_band * radius]),
        "solver": _solver(steps),
    })


def hertz_sphere(
    h_contact: float = 0.02, *, radius: float = 1.0, E: float = 200.0, nu: float = 0.3,
    law: str = "linear", push: float = 0.01, h_far: float = 0.25, fine_radius: float = 0.15,
    coarse_radius: float = 0.6, contact_band: float = 0.03, steps: int = 4,
    linear_solver: str = "direct",
) -> Scene:
    """3D Hertz: a sphere octant (``meshes/sphere.geo``) pushed onto the plane z = 0.

    The flat top z = R moves down by ``push`` (in-plane free); x = 0 and
    y = 0 are symmetry planes. Candidate facets: the sphere below
    ``contact_band`` R.
    """
    return _scene(f"hertz-sphere-h{h_contact:g}", {
        "scene": {"dimension": 3, "description": "3D Hertz, sphere octant on a plane"},
        "mesh": {"file": str(MESHES / "sphere.geo"),
                 "parameters": {"radius": radius, "h_contact": h_contact, "h_far": h_far,
                                "fine_radius": fine_radius, "coarse_radius": coarse_radius}},
        "material": {"law": law, "E": E, "nu": nu},
        "dirichlet": [{"tag": "top", "value": ["free", "free", -push]},
                      {"tag": "symmetry_x", "value": [0.0, "free", "free"]},
                      {"tag": "symmetry_y", "value": ["free", 0.0, "free"]}],
        "obstacle": {"type": "plane", "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]},
        "contact": {"tag": "contact", "z": [-radius, contact_band * radius]},
        "solver": _solver(steps, linear_solver=linear_solver),
    })


def sliding_block(
    mu: float | None = 0.3, *, schedule: Sequence[Sequence[float]] = PRESS_SLIDE,
    nx: int = 20, ny: int = 10, width: float = 1.0, height: float = 0.5, E: float = 1000.0,
    nu: float = 0.0, steps: int = 20, tangential_r_max: float | None = 2.0,
) -> Scene:
    """A block (SVK) clamped at its top, on a plane that presses and slides with friction ``mu``.

    ``tangential_r_max`` None: r_t = r (no cap); mu None: frictionless.
    """
    contact: dict[str, Any] = {"tag": "bottom"}
    if mu is not None:
        contact["mu"] = mu
        # an uncapped r_t: a cap beyond any r of the lab
        contact["tangential_r_max"] = 1e300 if tangential_r_max is None else tangential_r_max
    return _scene(f"slide-{nx}x{ny}", {
        "scene": {"dimension": 2, "description": "a block pressed and slid on a rigid plane"},
        "mesh": {"generator": "rectangle", "size": [width, height], "cells": [nx, ny]},
        "material": {"law": "svk", "E": E, "nu": nu},
        "dirichlet": [{"tag": "top", "value": [0.0, 0.0]}],
        "obstacle": {"type": "plane", "point": [0.0, 0.0], "normal": [0.0, 1.0],
                     "schedule": _rows(schedule)},
        "contact": contact,
        "solver": _solver(steps),
    })


def cells_for_dofs(dofs: float) -> int:
    """Cells per edge n whose tetrahedral box has about ``dofs`` displacement DOFs (3 (n+1)^3)."""
    return max(2, round((dofs / 3.0) ** (1.0 / 3.0)) - 1)


def block_indentation(
    n: int = 20, *, length: float = 1.0, height: float = 1.0, E: float = 200.0,
    nu: float = 0.3, law: str = "neo-hookean", ball_radius: float = 1.0, depth: float = 0.02,
    candidate_width: float = 0.4, steps: int = 4, linear_solver: str = "iterative",
) -> Scene:
    """The 3D ladder: a rigid ball pressed ``depth`` into a quarter block of n^3 x 6 tetrahedra.

    The block [0, L]^2 x [0, H] is clamped at z = 0 with symmetry on x = 0 and
    y = 0; candidate facets: the top face within ``candidate_width`` of both
    symmetry planes.
    """
    w = candidate_width
    return _scene(f"ladder-n{n}", {
        "scene": {"dimension": 3, "description": "a rigid ball pressed into a block"},
        "mesh": {"generator": "box", "size": [length, length, height], "cells": [n, n, n],
                 "cell": "tetrahedron"},
        "material": {"law": law, "E": E, "nu": nu},
        "dirichlet": [{"tag": "zmin", "value": [0.0, 0.0, 0.0]},
                      {"tag": "xmin", "value": [0.0, "free", "free"]},
                      {"tag": "ymin", "value": ["free", 0.0, "free"]}],
        "obstacle": {"type": "ball", "centre": [0.0, 0.0, height + ball_radius],
                     "radius": ball_radius, "motion": [0.0, 0.0, -depth]},
        "contact": {"tag": "zmax", "x": [0.0, w], "y": [0.0, w]},
        "solver": _solver(steps, linear_solver=linear_solver),
    })


def wedge_on_corner(*, h: float = -0.25, slope: float = 2.0, steps: int = 1,
                    r: float = 100.0) -> Scene:
    """The rigid-wedge analog of the paper's Example 1 (``scenes/paper_ex1.toml``).

    One SVK quadrilateral [0, 1]^2, clamped left and bottom, its right face
    vertical only: one free unknown, the corner's vertical displacement u.
    A wedge face of slope ``slope`` through the corner slides by ``h``: u =
    slope h exactly.
    """
    return _scene("paper-ex1-wedge", {
        "scene": {"dimension": 2, "description": "one SVK element against a sliding rigid wedge"},
        "mesh": {"generator": "rectangle", "size": [1.0, 1.0], "cells": [1, 1]},
        "material": {"law": "svk", "E": PAPER_E, "nu": PAPER_NU},
        "dirichlet": [{"tag": "left", "value": [0.0, 0.0]},
                      {"tag": "bottom", "value": [0.0, 0.0]},
                      {"tag": "right", "value": [0.0, "free"]}],
        "obstacle": {"type": "plane", "point": [1.0, 1.0], "normal": [-slope, -1.0],
                     "motion": [h, 0.0]},
        "contact": {"tag": "top", "r": r, "relative": False},
        "solver": _solver(steps),
    })


# -- deformable pairs -----------------------------------------------------------------------


def _linear_bodies(E_upper: float = 200.0, E_lower: float = 200.0,
                   law: str = "linear") -> list[dict[str, Any]]:
    return [{"name": "upper", "tag": "striker", "law": law, "E": E_upper, "nu": 0.3},
            {"name": "lower", "tag": "target", "law": law, "E": E_lower, "nu": 0.3}]


def _pair(striker: str, target: str, mu: float | None = None,
          tangential_r_max: float | None = 2.0,
          discretisation: str = "node-to-segment") -> dict[str, Any]:
    pair: dict[str, Any] = {"name": "pair", "striker": striker, "target": target,
                            "discretisation": discretisation}
    if mu is not None:
        pair["mu"] = mu
        pair["tangential_r_max"] = 1e300 if tangential_r_max is None else tangential_r_max
    return pair


def _block_rows(n_upper: int, n_lower: int, upper_width: float, height: float = 0.5
                ) -> dict[str, int]:
    """Rows of cells across the blocks of ``block_on_block.geo``: n H / width, at least 2.

    Rounded half to even (4.5 -> 4), as the measured figures' meshes were.
    """
    return {"rows_upper": max(2, round(n_upper * height / upper_width)),
            "rows_lower": max(2, round(n_lower * height / 1.0))}


def two_cylinders(
    h_contact: float = 0.02, *, push: float = 0.02, steps: int = 3,
    stiffness_ratio: float = 1.0, h_far: float = 0.2, target_ratio: float = 1.37,
    discretisation: str = "node-to-segment",
) -> Scene:
    """Two half-disks (R = 1) pushed together by ``push`` (``scenes/two_cylinders.toml``).

    Hertz for two cylinders; E_upper = 200 ``stiffness_ratio``, E_lower = 200;
    the target's contact size is ``target_ratio`` h_contact (non-matching);
    the pair's ``discretisation`` as in a scene.
    """
    return _scene(f"two-cylinders-h{h_contact:g}", {
        "scene": {"dimension": 2, "description": "two cylinders pressed together"},
        "mesh": {"file": str(MESHES / "two_cylinders.geo"),
                 "parameters": {"h_contact": h_contact, "h_far": h_far,
                                "target_ratio": target_ratio}},
        "body": _linear_bodies(200.0 * stiffness_ratio),
        "pair": [_pair("striker_arc", "target_arc", discretisation=discretisation)],
        "dirichlet": [{"tag": "top", "value": [0.0, -push]},
                      {"tag": "bottom", "value": [0.0, 0.0]}],
        "solver": _solver(steps),
    })


def block_on_block(
    n_upper: int = 8, n_lower: int = 11, *, steps: int = 2, upper_width: float | None = None,
    push: float = 0.01,
) -> Scene:
    """The contact patch test (``scenes/block_on_block.toml``): a block pressed onto another.

    ``n_upper`` and ``n_lower`` divisions along x (8 and 11: non-matching);
    the striker, ``upper_width`` wide (None: 1), is centred on the 1-wide
    target; symmetric at x = 0 (with the default width).
    """
    parameters: dict[str, float] = {"n_upper": n_upper, "n_lower": n_lower,
                                    **_block_rows(n_upper, n_lower, upper_width or 1.0)}
    if upper_width is not None:
        parameters["upper_width"] = upper_width
    return _scene(f"block-on-block-{n_upper}-{n_lower}", {
        "scene": {"dimension": 2, "description": "the contact patch test"},
        "mesh": {"file": str(MESHES / "block_on_block.geo"), "parameters": parameters},
        "body": _linear_bodies(),
        "pair": [_pair("striker_face", "target_face")],
        "dirichlet": [{"tag": "top", "value": ["free", -push]},
                      {"tag": "bottom", "value": ["free", 0.0]},
                      {"tag": "symmetry", "value": [0.0, "free"]}],
        "solver": _solver(steps),
    })


def sliding_blocks(
    mu: float | None = 0.3, *, path: Sequence[Sequence[float]] = PRESS_SLIDE_PAIR,
    n_upper: int = 6, n_lower: int = 9, upper_width: float = 0.6, steps: int = 10,
    tangential_r_max: float | None = 2.0,
) -> Scene:
    """A 0.6-wide block pressed onto a 1-wide one, then slid, with Coulomb friction ``mu``.

    The striker's top follows ``path`` (t, dx, dy); the target's bottom is
    clamped. mu None: frictionless; ``tangential_r_max`` None: r_t = r.
    """
    return _scene(f"sliding-blocks-{n_upper}-{n_lower}", {
        "scene": {"dimension": 2, "description": "a block pressed and slid on another"},
        "mesh": {"file": str(MESHES / "block_on_block.geo"),
                 "parameters": {"n_upper": n_upper, "n_lower": n_lower,
                                "upper_width": upper_width,
                                **_block_rows(n_upper, n_lower, upper_width)}},
        "body": _linear_bodies(),
        "pair": [_pair("striker_face", "target_face", mu, tangential_r_max)],
        "dirichlet": [{"tag": "top", "path": _rows(path)},
                      {"tag": "bottom", "value": [0.0, 0.0]}],
        "solver": _solver(steps),
    })


def ironing(
    *, steps: int = 10, slide: float = 0.6, h_indenter: float = 0.08, h_block: float = 0.12,
    mu: float | None = None, discretisation: str = "node-to-segment", block_strikes: bool = False,
) -> Scene:
    """Ironing (``scenes/ironing.toml``, coarse by default): a neo-Hookean indenter on a block.

    E = 1000 (indenter) and 100 (block); pressed 0.1 over the first 20 % of
    the path, then slid ``slide``. The indenter strikes unless ``block_strikes``
    (as in ``scenes/ironing.toml``, a mortar pair).
    """
    sides = ("target_face", "striker_arc") if block_strikes else ("striker_arc", "target_face")
    return _scene(f"ironing-{h_indenter:g}", {
        "scene": {"dimension": 2, "description": "an indenter pressed and slid on a block"},
        "mesh": {"file": str(MESHES / "ironing.geo"),
                 "parameters": {"h_indenter": h_indenter, "h_block": h_block}},
        "body": [{"name": "indenter", "tag": "striker", "law": "neo-hookean", "E": 1000.0,
                  "nu": 0.3},
                 {"name": "block", "tag": "target", "law": "neo-hookean", "E": 100.0,
                  "nu": 0.3}],
        "pair": [_pair(*sides, mu, discretisation=discretisation)],
        "dirichlet": [{"tag": "bottom", "value": [0.0, 0.0]},
                      {"tag": "top", "path": [[0.0, 0.0, 0.0], [0.2, 0.0, -0.1],
                                              [1.0, slide, -0.1]]}],
        "solver": _solver(steps),
    })


def _shipped(name: str) -> dict[str, Any]:
    """The data of a shipped scene file (to vary it before validation)."""
    import tomllib

    return tomllib.loads((ROOT / "scenes" / f"{name}.toml").read_text())


def stack_automatic(steps: int = 2) -> Scene:
    """Three blocks stacked on a floor, pairs found automatically: the middle touches two."""
    data = _shipped("stack_3_blocks_automatic")
    data["solver"]["steps"] = steps
    return _scene("stack_3_blocks_automatic", data)


def junction_blocks(slide: float = 0.0, steps: int = 2, held: bool = False) -> Scene:
    """A block pressed onto two blocks side by side (a node touching both), pairs automatic.

    ``slide`` > 0: the top block is pressed by 0.008 up to load factor 0.3,
    then slides right by ``slide``: past 0.5 it leaves the left block (that
    contact opens) while its contact with the right one closes over more nodes.
    ``held``: the left block's outer wall holds it vertically too (u = 0
    there, not only u_x). Without it, once the top block has left, nothing
    holds the left block down against the frictionless joint, which pushes
    it up (docs/contacts.md): the static problem has no solution.
    """
    data = _shipped("junction_blocks")
    data["solver"]["steps"] = steps
    if held:
        wall = next(d for d in data["dirichlet"] if d["tag"] == "left_wall")
        wall["value"] = [0.0, 0.0]
    if slide:
        top = data["dirichlet"][2]
        top.pop("value")
        top["path"] = [[0.0, 0.0, 0.0], [0.3, 0.0, -0.008], [1.0, slide, -0.008]]
    return _scene("junction_blocks", data)


def tube_crush(steps: int = 50) -> Scene:
    """The tube crushed until its inner wall touches itself (a self-contact pair)."""
    data = _shipped("tube_crush")
    data["solver"]["steps"] = steps
    return _scene("tube_crush", data)


def build(
    scene: Scene, r: float = 1.0, relative: bool = True, quadrature: str | None = None,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> ContactProblem:
    """The problem of ``scene`` with r (relative to E/h, or absolute) on every contact."""
    return build_problem(with_contact_settings(scene, r, relative, quadrature), comm)  # type: ignore[arg-type]
