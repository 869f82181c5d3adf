"""Pictures of a solved problem: the deformed body coloured by contact pressure.

PyVista renders off-screen (no display needed). The body is drawn deformed
(true scale) and coloured by the contact pressure -lam (zero off the
contact surface, so the colour shows where and how hard the body presses);
the rigid obstacle is drawn in grey.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from dolfinx import plot

from fenics_contact.model.obstacles import RigidBall, RigidObstacle, RigidPlane
from fenics_contact.model.problem import ContactProblem
from fenics_contact.output.io import ContactsToBody


def _obstacle_mesh(problem: ContactProblem, obstacle: RigidObstacle, bounds: np.ndarray):
    import pyvista

    gdim = problem.domain.geometry.dim
    centre = np.zeros(3)
    centre[:gdim] = obstacle.point.value
    span = float(np.max(bounds[1] - bounds[0]))
    if isinstance(obstacle, RigidPlane):
        normal = np.zeros(3)
        normal[:gdim] = obstacle.normal.value
        mid = 0.5 * (bounds[0] + bounds[1])
        # the point of the plane nearest the body's centre
        foot = mid - np.dot(mid - centre, normal) * normal
        if gdim == 2:
            tangent = np.array([normal[1], -normal[0], 0.0])
            return pyvista.Line(foot - 0.75 * span * tangent, foot + 0.75 * span * tangent)
        return pyvista.Plane(center=foot, direction=normal, i_size=1.5 * span, j_size=1.5 * span)
    assert isinstance(obstacle, RigidBall)
    radius = float(obstacle.radius.value)
    if gdim == 2:
        angles = np.linspace(0.0, 2.0 * np.pi, 721)
        ring = np.column_stack([np.cos(angles), np.sin(angles), 0.0 * angles]) * radius
        return pyvista.MultipleLines(ring + centre)
    return pyvista.Sphere(radius=radius, center=centre, theta_resolution=60, phi_resolution=60)


def _contact_window(grid, bounds: np.ndarray, gdim: int) -> np.ndarray | None:
    """2D: bounds around the pressed nodes when they span under a fifth of the body."""
    pressed = grid.points[grid.point_data["contact pressure"] > 0]
    if gdim != 2 or pressed.shape[0] == 0:
        return None
    lo, hi = pressed.min(axis=0), pressed.max(axis=0)
    size = float(np.max(bounds[1] - bounds[0]))
    if float(np.max(hi - lo)) > 0.2 * size:
        return None
    margin = max(float(np.max(hi - lo)), 0.02 * size)
    return np.array([lo - margin, hi + margin])


def _gathered_grid(problem: ContactProblem):
    """The deformed body with its contact pressure, whole on rank 0 (None elsewhere).

    Collective. Each process contributes its owned cells; nodes on partition
    boundaries appear once per process that draws a cell there (the picture
    does not change).
    """
    import pyvista

    pressures = [-c.contact_state().pressure for c in problem.contacts]
    pressure = ContactsToBody(problem).field("p", pressures, add=True)
    topology, cell_types, geometry = plot.vtk_mesh(problem.V)
    gdim = problem.domain.geometry.dim
    points = np.array(geometry, dtype=np.float64).reshape(-1, 3)
    points[:, :gdim] += problem.u.x.array.reshape(-1, gdim)
    part = (np.asarray(topology), np.asarray(cell_types), points, pressure.x.array.copy())
    parts = problem.comm.gather(part, root=0)
    if parts is None:
        return None
    cells, types, coords, values = [], [], [], []
    offset = 0
    for topo, kinds, pts, val in parts:
        if kinds.size:
            per_cell = topo.reshape(kinds.size, -1).copy()  # one cell type a mesh
            per_cell[:, 1:] += offset
            cells.append(per_cell.ravel())
        types.append(kinds)
        coords.append(pts)
        values.append(val)
        offset += pts.shape[0]
    grid = pyvista.UnstructuredGrid(
        np.concatenate(cells), np.concatenate(types), np.concatenate(coords)
    )
    grid.point_data["contact pressure"] = np.concatenate(values)
    return grid


def deformed_contact_picture(problem: ContactProblem, path: Path, title: str = "") -> None:
    """Render the deformed body coloured by contact pressure into a PNG.

    Collective: on more processes the body is gathered to rank 0, which draws.
    """
    import pyvista

    grid = _gathered_grid(problem)
    if grid is None:
        return
    pyvista.OFF_SCREEN = True
    # without a display VTK warns once that X is missing, then renders off-screen
    pyvista.vtk_verbosity("off")
    gdim = problem.domain.geometry.dim
    bounds = np.array(grid.bounds).reshape(3, 2).T
    zoom = _contact_window(grid, bounds, gdim)
    pressed = grid.point_data["contact pressure"] > 0
    nodes = pyvista.PolyData(grid.points[pressed])
    nodes.point_data["contact pressure"] = grid.point_data["contact pressure"][pressed]
    clim = (0.0, max(float(grid.point_data["contact pressure"].max()), 1e-300))
    shape = (1, 2) if zoom is not None else (1, 1)
    plotter = pyvista.Plotter(
        off_screen=True, window_size=(1600 if zoom is not None else 1200, 800), shape=shape
    )
    views = [(bounds, "whole body")] + ([(zoom, "contact zone")] if zoom is not None else [])
    for column, (window, label) in enumerate(views):
        plotter.subplot(0, column)
        plotter.add_mesh(
            grid.copy(), scalars="contact pressure", cmap="inferno_r", show_edges=gdim == 2,
            edge_color="#777777", clim=clim, scalar_bar_args={"title": "contact pressure -lam"},
        )
        if nodes.n_points and gdim == 2:  # the pressed nodes, visible at any zoom
            plotter.add_mesh(
                nodes.copy(), scalars="contact pressure", cmap="inferno_r", clim=clim,
                render_points_as_spheres=True, point_size=9 if column else 6,
                show_scalar_bar=False,
            )
        for obstacle in problem.obstacles():  # deformable partners are in the grid
            plotter.add_mesh(
                _obstacle_mesh(problem, obstacle, bounds), color="#555555", line_width=3,
                opacity=1.0 if gdim == 2 else 0.25,
            )
        if gdim == 2:
            plotter.view_xy()
            plotter.camera.parallel_projection = True
        else:  # from below and aside, where the contact is usually seen
            plotter.view_vector((1.0, -1.3, -0.8), viewup=(0.0, 0.0, 1.0))
        pad = 0.1 * float(np.max(window[1] - window[0]))
        lo, hi = window[0] - pad, window[1] + pad
        plotter.reset_camera(bounds=(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]))
        if zoom is not None:
            plotter.add_text(label, position="lower_left", font_size=10)
    plotter.subplot(0, 0)
    if title:
        plotter.add_text(title, font_size=12)
    path.parent.mkdir(parents=True, exist_ok=True)
    plotter.screenshot(str(path))
    plotter.close()
