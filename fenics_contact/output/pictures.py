"""Pictures of a solved problem: the deformed body coloured by contact pressure.

PyVista renders off-screen (no display needed). The body is drawn deformed
(true scale) and coloured by the contact pressure -lam (zero off the
contact surface, so the colour shows where and how hard the body presses);
the rigid obstacle is drawn in grey.

2D: the whole body, and beside it a window on the contact zone when it is
small. 3D: first the pressed surfaces seen from their partners' side along
the contact normal (:mod:`fenics_contact.output.contact_view`), with
friction the stick/slip map on the same surfaces, then the whole deformed
bodies seen aside.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from dolfinx import plot

from fenics_contact.model.obstacles import RigidBall, RigidObstacle, RigidPlane
from fenics_contact.model.problem import ContactProblem
from fenics_contact.output.contact_view import (
    BODY,
    PRESSURE,
    STICK_SLIP,
    Picture,
    draw_solid,
)
from fenics_contact.output.io import ContactsToBody


def _obstacle_mesh(problem: ContactProblem, obstacle: RigidObstacle, bounds: np.ndarray):
    if isinstance(obstacle, RigidPlane):
        return obstacle_outline("plane", obstacle.point.value, bounds,
                                normal=obstacle.normal.value)
    assert isinstance(obstacle, RigidBall)
    return obstacle_outline("ball", obstacle.point.value, bounds,
                            radius=float(obstacle.radius.value))


def obstacle_outline(kind: str, point, bounds: np.ndarray, *, normal=None,
                     radius: float | None = None):
    """A rigid obstacle to draw beside bodies within ``bounds`` (2 x 3, length).

    ``kind`` 'plane' (through ``point``, unit ``normal``: a segment in 2D, a
    square in 3D, 1.5 times the bodies' span) or 'ball' (centre ``point``,
    ``radius``: a circle in 2D, a sphere in 3D). The dimension is ``point``'s.
    """
    import pyvista

    gdim = len(point)
    centre = np.zeros(3)
    centre[:gdim] = point
    span = float(np.max(bounds[1] - bounds[0]))
    if kind == "plane":
        normal_3 = np.zeros(3)
        normal_3[:gdim] = normal
        normal = normal_3 / np.linalg.norm(normal_3)
        mid = 0.5 * (bounds[0] + bounds[1])
        # the point of the plane nearest the body's centre
        foot = mid - np.dot(mid - centre, normal) * normal
        if gdim == 2:
            tangent = np.array([normal[1], -normal[0], 0.0])
            return pyvista.Line(foot - 0.75 * span * tangent, foot + 0.75 * span * tangent)
        return pyvista.Plane(center=foot, direction=normal, i_size=1.5 * span, j_size=1.5 * span)
    radius = float(radius)  # type: ignore[arg-type]
    if gdim == 2:
        angles = np.linspace(0.0, 2.0 * np.pi, 721)
        ring = np.column_stack([np.cos(angles), np.sin(angles), 0.0 * angles]) * radius
        return pyvista.MultipleLines(ring + centre)
    return pyvista.Sphere(radius=radius, center=centre, theta_resolution=60, phi_resolution=60)


def _contact_zones(grid, size: float, most: int = 3) -> list[np.ndarray]:
    """2D: bounds around each group of pressed nodes spanning under a fifth of the body.

    Pressed nodes closer than 5 % of the body's size (or three times their
    median spacing, if more) form one group; the ``most`` groups with the
    largest summed pressure get a window each.
    """
    pressure = np.asarray(grid.point_data[PRESSURE])
    pressed = np.asarray(grid.points)[pressure > 0]
    if pressed.shape[0] == 0:
        return []
    apart = np.linalg.norm(pressed[:, None, :] - pressed[None, :, :], axis=2)
    np.fill_diagonal(apart, np.inf)
    spacing = float(np.median(apart.min(axis=1))) if pressed.shape[0] > 1 else 0.0
    near_enough = max(0.05 * size, 3.0 * spacing)
    group = -np.ones(pressed.shape[0], dtype=int)
    for seed in range(pressed.shape[0]):
        if group[seed] >= 0:
            continue
        group[seed] = seed
        front = [seed]
        while front:
            near = np.linalg.norm(pressed - pressed[front.pop()], axis=1) < near_enough
            new = np.flatnonzero(near & (group < 0))
            group[new] = seed
            front.extend(new.tolist())
    weight = pressure[pressure > 0]
    order = sorted(set(group.tolist()), key=lambda g: -weight[group == g].sum())[:most]
    windows = []
    for g in sorted(order, key=lambda g: pressed[group == g][:, 0].min()):
        points = pressed[group == g]
        lo, hi = points.min(axis=0), points.max(axis=0)
        if float(np.max(hi - lo)) > 0.2 * size:
            continue
        margin = max(float(np.max(hi - lo)), 0.025 * size)
        windows.append(np.array([lo - margin, hi + margin]))
    return windows


def _contact_lines(grid):
    """2D: the boundary edges pressed at both ends, with the pressure (PolyData)."""
    edges = grid.extract_surface(algorithm="dataset_surface").extract_feature_edges(
        boundary_edges=True, feature_edges=False, manifold_edges=False,
        non_manifold_edges=False)
    pressure = np.asarray(edges.point_data[PRESSURE])
    lines = np.asarray(edges.lines).reshape(-1, 3)[:, 1:]
    touching = np.flatnonzero(pressure[lines].min(axis=1) > 0)
    return edges.extract_cells(touching)


def _surface_fields(problem: ContactProblem) -> dict[str, np.ndarray]:
    """Local body P1 values of the contact pressure (-lam >= 0) and, with friction, stick/slip.

    A frictionless contact of a frictional problem marks its pressed nodes as
    slipping (2), as in the XDMF output.
    """
    mapper = ContactsToBody(problem)
    states = [c.contact_state() for c in problem.contacts]
    fields = {PRESSURE: mapper.field("p", [-s.pressure for s in states], add=True).x.array}
    if problem.frictional:
        codes = [s.node_state.astype(float) if c.friction is not None  # type: ignore[attr-defined]
                 else 2.0 * s.active for c, s in zip(problem.contacts, states, strict=True)]
        fields[STICK_SLIP] = mapper.field("s", codes).x.array
    return {name: values.copy() for name, values in fields.items()}


def _gathered_grid(problem: ContactProblem):
    """The deformed bodies with their contact fields, whole on rank 0 (None elsewhere).

    Collective. Each process contributes its owned cells and their nodes with
    global numbers; rank 0 keeps one copy of each node (its owner's), so
    partition boundaries leave no inner faces. Several bodies get the cell field
    :data:`BODY`.
    """
    import pyvista

    topology, cell_types, geometry = plot.vtk_mesh(problem.V)
    gdim = problem.domain.geometry.dim
    points = np.array(geometry, dtype=np.float64).reshape(-1, 3)
    points[:, :gdim] += problem.u.x.array.reshape(-1, gdim)
    index_map = problem.V.dofmap.index_map
    local = np.arange(index_map.size_local + index_map.num_ghosts, dtype=np.int32)
    numbers = index_map.local_to_global(local)
    owned = local < index_map.size_local
    body = problem.body_ids()
    kinds = np.asarray(cell_types)
    bodies = (np.asarray(body.x.array[: kinds.size]).copy() if body is not None
              else np.zeros(kinds.size))
    part = (np.asarray(topology), kinds, points, numbers, owned, _surface_fields(problem),
            bodies)
    parts = problem.comm.gather(part, root=0)
    if parts is None:
        return None
    all_numbers = np.concatenate([p[3] for p in parts])
    all_owned = np.concatenate([p[4] for p in parts])
    # one copy of each node, its owner's (ghost copies may hold no surface values)
    order = np.lexsort((~all_owned, all_numbers))
    _, first_sorted, inverse = np.unique(all_numbers[order], return_index=True,
                                         return_inverse=True)
    first = order[first_sorted]
    renumber = np.empty_like(inverse)
    renumber[order] = inverse
    cells, offset = [], 0
    for topo, kinds_i, pts, *_ in parts:
        if kinds_i.size:
            per_cell = topo.reshape(kinds_i.size, -1).copy()  # one cell type a mesh
            per_cell[:, 1:] = renumber[per_cell[:, 1:] + offset]
            cells.append(per_cell.ravel())
        offset += pts.shape[0]
    coords = np.concatenate([p[2] for p in parts])[first]
    grid = pyvista.UnstructuredGrid(
        np.concatenate(cells), np.concatenate([p[1] for p in parts]), coords
    )
    for name in parts[0][5]:
        grid.point_data[name] = np.concatenate([p[5][name] for p in parts])[first]
    if body is not None:
        grid.cell_data[BODY] = np.concatenate([p[6] for p in parts])
    return grid


def deformed_contact_picture(problem: ContactProblem, path: Path, title: str = ""
                             ) -> Picture | None:
    """Render the deformed body coloured by contact pressure into a PNG.

    Collective: on more processes the body is gathered to rank 0, which draws
    and returns what the picture shows (None on the other ranks).
    """
    import pyvista

    grid = _gathered_grid(problem)
    if grid is None:
        return None
    pyvista.OFF_SCREEN = True
    # without a display VTK warns once that X is missing, then renders off-screen
    pyvista.vtk_verbosity("off")
    if problem.domain.geometry.dim == 2:
        picture, plotter = _plane_picture(problem, grid)
    else:
        picture, plotter = _solid_picture(problem, grid)
    plotter.subplot(0, 0)
    if title:
        plotter.add_text(title, font_size=12)
    path.parent.mkdir(parents=True, exist_ok=True)
    plotter.screenshot(str(path))
    plotter.close()
    return picture


def _pressure_style(grid) -> dict[str, object]:
    """``add_mesh`` keywords of the pressure colouring, one scale for every panel."""
    top = max(float(np.max(grid.point_data[PRESSURE], initial=0.0)), 1e-300)
    return {"scalars": PRESSURE, "cmap": "inferno_r", "clim": (0.0, top),
            "scalar_bar_args": {"title": "p = -lam", "vertical": True,
                                "position_x": 0.86, "position_y": 0.2, "height": 0.6}}


#: Light fills of the bodies in 2D, one per body (the pressure colours the contact lines).
BODY_FILLS = ("#e4e4e4", "#c9dbef", "#eedcc2", "#d2ebd2", "#e6d3ea")
#: Screen fractions of a 2D panel kept free below (scalar bar, label) and above (title).
BELOW, ABOVE = 0.17, 0.06


def _body_style(grid) -> dict[str, object]:
    """``add_mesh`` keywords of the 2D body fill: one light colour per body, told apart."""
    if BODY not in grid.cell_data:
        return {"color": BODY_FILLS[0]}
    ids = np.asarray(grid.cell_data[BODY]).astype(int)
    if np.unique(ids).size < 2:
        return {"color": BODY_FILLS[0]}
    fills = [BODY_FILLS[k % len(BODY_FILLS)] for k in range(int(ids.max()) + 1)]
    return {"scalars": BODY, "preference": "cell", "cmap": fills, "n_colors": len(fills),
            "clim": (-0.5, len(fills) - 0.5), "show_scalar_bar": False}


def _frame(plotter, window: np.ndarray, aspect: float) -> None:
    """Fit ``window`` (2 x 3 bounds) in a parallel 2D panel, clear of the bar and the title.

    The window, padded by a tenth, fills the panel's width or the height
    between the bottom :data:`BELOW` and the top :data:`ABOVE` of it.
    """
    pad = 0.1 * float(np.max(window[1] - window[0]))
    lo, hi = window[0] - pad, window[1] + pad
    plotter.reset_camera(bounds=(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]))
    usable = 1.0 - BELOW - ABOVE
    scale = 0.5 * max((hi[1] - lo[1]) / usable, (hi[0] - lo[0]) / aspect)
    camera = plotter.camera
    camera.parallel_scale = scale
    # move the view so that the window's centre sits in the middle of the free band
    shift = (0.5 * (BELOW - ABOVE)) * 2.0 * scale
    focal, position = np.array(camera.focal_point), np.array(camera.position)
    middle = 0.5 * (lo[1] + hi[1])
    focal[1], position[1] = middle - shift, middle - shift
    camera.focal_point, camera.position = tuple(focal), tuple(position)


def _plane_picture(problem: ContactProblem, grid):
    """2D: the bodies in grey, the pressed boundary coloured; a window on each small zone."""
    import pyvista

    bounds = np.array(grid.bounds).reshape(3, 2).T
    zooms = _contact_zones(grid, float(np.max(bounds[1] - bounds[0])))
    pressed = grid.point_data[PRESSURE] > 0
    nodes = pyvista.PolyData(grid.points[pressed])
    nodes.point_data[PRESSURE] = grid.point_data[PRESSURE][pressed]
    lines = _contact_lines(grid) if nodes.n_points else None
    lift = np.array([0.0, 0.0, 1e-3 * float(np.max(bounds[1] - bounds[0]))])
    nodes.points = np.asarray(nodes.points) + lift  # drawn over the obstacles' lines
    if lines is not None:
        lines.points = np.asarray(lines.points) + lift
    style = _pressure_style(grid)
    style["scalar_bar_args"] = {"title": "contact pressure -lam", "position_x": 0.3,
                                "position_y": 0.02, "width": 0.45, "height": 0.08}
    extent = bounds[1] - bounds[0]
    wide = float(np.clip(extent[0] / max(float(extent[1]), 1e-300), 1.0, 2.0))  # alone
    width = 700 * (1 + len(zooms)) if zooms else int(700 * wide)
    plotter = pyvista.Plotter(off_screen=True, window_size=(width, 700),
                              shape=(1, 1 + len(zooms)))
    views = [(bounds, "whole body")] + [
        (zoom, "contact zone" if len(zooms) == 1 else f"contact zone {k + 1}")
        for k, zoom in enumerate(zooms)]
    picture = Picture(bar=str(style["scalar_bar_args"]["title"]))  # type: ignore[index]
    for column, (window, label) in enumerate(views):
        plotter.subplot(0, column)
        plotter.add_mesh(grid.copy(), show_edges=True, edge_color="#9a9a9a", **_body_style(grid))
        if lines is not None and lines.n_cells:  # the pressed boundary, coloured
            plotter.add_mesh(lines.copy(), line_width=7 if column else 5, **style)
        if nodes.n_points:  # the pressed nodes, visible at any zoom
            plotter.add_mesh(
                nodes.copy(), scalars=PRESSURE, cmap="inferno_r", clim=style["clim"],
                render_points_as_spheres=True, point_size=11 if column else 7,
                show_scalar_bar=False,
            )
        for obstacle in problem.obstacles():  # deformable partners are in the grid
            plotter.add_mesh(_obstacle_mesh(problem, obstacle, bounds), color="#555555",
                             line_width=3)
        plotter.view_xy()
        plotter.camera.parallel_projection = True
        _frame(plotter, window, aspect=width / (1 + len(zooms)) / 700)
        if zooms:
            plotter.add_text(label, position="lower_left", font_size=10)
        picture.panels.append(label)
    return picture, plotter


def _solid_picture(problem: ContactProblem, grid):
    """3D: the pressed surfaces from their partners' side (and stick/slip), then the bodies."""

    def obstacles(plotter, bounds: np.ndarray) -> None:
        grow = 0.15 * (bounds[1] - bounds[0])
        near = np.concatenate([bounds[0] - grow, bounds[1] + grow])[[0, 3, 1, 4, 2, 5]]
        for obstacle in problem.obstacles():  # only its part near the bodies
            shape = _obstacle_mesh(problem, obstacle, bounds).clip_box(tuple(near), invert=False)
            plotter.add_mesh(shape, color="#555555", opacity=0.3)

    names = [b.name for b in problem.solid.bodies]
    return draw_solid(grid, _pressure_style(grid), name="contact pressure",
                      stick_slip=True, context=obstacles, body_names=names)
