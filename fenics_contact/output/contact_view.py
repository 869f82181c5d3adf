"""Where to look at a 3D contact: the pressed surfaces seen from their partners' side.

Shared by ``deformed.png`` (:mod:`fenics_contact.output.pictures`) and
``fenics-contact render`` (:mod:`fenics_contact.output.render`). Both hand in
a PyVista grid of the deformed bodies with the point field
:data:`PRESSURE` (the contact pressure -lam >= 0, stress; zero off the
contact surface) and, for several bodies, the cell field :data:`BODY`.

The contact normal n is the pressure-weighted principal direction of the
outward normals of the boundary faces that carry pressure, oriented to
agree with most of them: it points out of the pressed body towards its
partner (a rigid obstacle or the target body). A pressed surface is the part
of one body's boundary facing +n or -n (outward normal within 72 degrees),
cut to a window around its pressed nodes. Each is seen from its partner's
side: the camera sits on +n and looks along -n, surfaces facing -n are
turned half a turn about the screen's horizontal, and several surfaces are
laid side by side. The partner is left out, so nothing hides the contact.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

#: Point field: contact pressure -lam >= 0 (stress), zero off the contact surface.
PRESSURE = "contact pressure"
#: Point field with friction: 0 open, 1 stick, 2 slip.
STICK_SLIP = "stick/slip"
#: Cell field: the body index (several bodies only).
BODY = "body"
#: Cosine of the largest angle between a face's outward normal and +-n on a pressed surface.
FACING = 0.3


@dataclass(frozen=True)
class ContactView:
    """The camera and the laid-out pressed surfaces of one 3D contact picture.

    Attributes:
        normal: unit contact normal n, out of the pressed bodies towards their partners.
        up: unit screen vertical (perpendicular to n).
        right: unit screen horizontal, ``up x n``.
        surface: the pressed surfaces (PyVista PolyData, every field of the grid),
            laid out side by side and all facing +n.
        focal: the centre of the laid-out surfaces (length).
        labels: one (position, text) per pressed surface when there are several
            (the text: its body's name, see :func:`body_label`).
    """

    normal: np.ndarray
    up: np.ndarray
    right: np.ndarray
    surface: object
    focal: np.ndarray
    labels: tuple[tuple[np.ndarray, str], ...]

    @property
    def position(self) -> np.ndarray:
        """The camera position: on +n from the focal point (length)."""
        size = float(np.max(np.ptp(np.asarray(self.surface.points), axis=0)))  # type: ignore
        return self.focal + self.normal * 4.0 * max(size, 1e-12)


@dataclass
class Picture:
    """What a picture shows (rank 0): its panels and where each panel's camera looks from.

    Attributes:
        panels: panel titles, left to right.
        directions: per 3D panel title, the unit direction from the focal point to the camera.
        view: the 3D contact view (None in 2D or without contact).
        bar: the colour bar's title.
    """

    panels: list[str] = field(default_factory=list)
    directions: dict[str, np.ndarray] = field(default_factory=dict)
    view: ContactView | None = None
    bar: str = ""


def body_label(body: int | None, names: Sequence[str] = ()) -> str:
    """What a pressed surface of body number ``body`` is called: its name, else "body N".

    ``body`` None: the grid has one body ("body"); ``names``: the bodies'
    names in the order of their numbers (the scene's [[body]] blocks).
    """
    if body is None:
        return "body"
    return names[body] if 0 <= body < len(names) else f"body {body}"



def outward_faces(grid):
    """The boundary faces of ``grid`` with their outward unit normals (cell field ``normal``).

    Each face's normal is turned away from the centroid of the cell it bounds.
    """
    surface = grid.extract_surface(
        pass_pointid=False, pass_cellid=True, algorithm="dataset_surface")
    cells = np.asarray(surface.cell_data["vtkOriginalCellIds"])
    centres = np.asarray(grid.cell_centers().points)[cells]
    points = np.asarray(surface.points)
    faces = _face_lists(surface)
    normals = np.empty((len(faces), 3))
    middles = np.empty((len(faces), 3))
    for i, face in enumerate(faces):
        corners = points[face]
        middles[i] = corners.mean(axis=0)
        normals[i] = _polygon_normal(corners)
    flip = np.einsum("ij,ij->i", normals, middles - centres) < 0
    normals[flip] *= -1.0
    lengths = np.linalg.norm(normals, axis=1)
    surface.cell_data["area"] = lengths
    surface.cell_data["normal"] = normals / np.maximum(lengths, 1e-300)[:, None]
    surface.cell_data["middle"] = middles
    if BODY in grid.cell_data:
        surface.cell_data[BODY] = np.asarray(grid.cell_data[BODY])[cells]
    return surface


def _face_lists(surface) -> list[np.ndarray]:
    """The point indices of every polygon of ``surface``."""
    flat = np.asarray(surface.faces)
    faces, i = [], 0
    while i < flat.size:
        faces.append(flat[i + 1 : i + 1 + flat[i]])
        i += flat[i] + 1
    return faces


def _polygon_normal(corners: np.ndarray) -> np.ndarray:
    """Area vector of a planar or slightly warped polygon (Newell's sum; length = area)."""
    following = np.roll(corners, -1, axis=0)
    return 0.5 * np.cross(corners, following).sum(axis=0)


def _face_pressure(surface) -> np.ndarray:
    """Per face: the smallest and the mean nodal pressure of its corners (two columns)."""
    pressure = np.asarray(surface.point_data[PRESSURE], dtype=float)
    faces = _face_lists(surface)
    return np.array([[pressure[f].min(), pressure[f].mean()] for f in faces])


def contact_normal(surface) -> np.ndarray | None:
    """The contact normal n from the outward faces (see the module); None without pressure."""
    per_face = _face_pressure(surface)
    area = np.asarray(surface.cell_data["area"])
    normals = np.asarray(surface.cell_data["normal"])
    weights = area * per_face[:, 0]  # faces pressed at every corner
    if not np.any(weights > 0):
        weights = area * per_face[:, 1]  # a single pressed node: the faces around it
    if not np.any(weights > 0):
        return None
    tensor = np.einsum("i,ij,ik->jk", weights, normals, normals)
    n = np.linalg.eigh(tensor)[1][:, -1]
    if float(weights @ (normals @ n)) < 0:
        n = -n
    return n / np.linalg.norm(n)


def screen_axes(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Screen (up, right) for a camera on +n: up the global axis z, y or x least along n."""
    candidates = np.eye(3)[[2, 1, 0]]
    along = np.abs(candidates @ normal)
    # the first of the least (a tie within round-off keeps that order: the same
    # picture from any partition of the mesh)
    axis = candidates[int(np.flatnonzero(along <= along.min() + 1e-9)[0])]
    up = axis - (axis @ normal) * normal
    up /= np.linalg.norm(up)
    return up, np.cross(up, normal)


def _regions(surface, normal: np.ndarray) -> list[tuple[int, int, np.ndarray]]:
    """(body, side, face mask) of every pressed surface; side +1 faces +n, -1 faces -n."""
    per_face = _face_pressure(surface)
    along = np.asarray(surface.cell_data["normal"]) @ normal
    bodies = (np.asarray(surface.cell_data[BODY]).astype(int) if BODY in surface.cell_data
              else np.zeros(surface.n_cells, dtype=int))
    out = []
    for body in np.unique(bodies):
        for side in (1, -1):
            mask = (bodies == body) & (side * along > FACING)
            if np.any(per_face[mask, 1] > 0):
                out.append((int(body), side, mask))
    return out


def _piece(faces, cells: np.ndarray):
    """The faces ``cells`` of ``faces`` as PolyData with every field."""
    return faces.extract_cells(cells).extract_surface(algorithm="dataset_surface")


def contact_view(grid, margin: float = 0.4, body_names: Sequence[str] = ()
                 ) -> ContactView | None:
    """The view of the pressed surfaces of the deformed ``grid``; None when nothing presses.

    Args:
        grid: the deformed bodies (PyVista UnstructuredGrid) with :data:`PRESSURE`.
        margin: the window around each surface's pressed nodes, as a fraction of
            their extent (at least 4 % of the body's size on each side).
        body_names: the bodies' names by their number in :data:`BODY` (labels;
            "body N" without).
    """
    import pyvista

    faces = outward_faces(grid)
    normal = contact_normal(faces)
    if normal is None:
        return None
    up, right = screen_axes(normal)
    basis = np.vstack([right, up, normal])  # rows: screen x, screen y, depth
    size = float(np.max(np.ptp(np.asarray(grid.points), axis=0)))
    middles = np.asarray(faces.cell_data["middle"])
    pieces, labels, cursor = [], [], 0.0
    regions = _regions(faces, normal)
    for body, side, mask in regions:
        piece = _piece(faces, np.flatnonzero(mask))
        pressed = np.asarray(piece.points)[np.asarray(piece.point_data[PRESSURE]) > 0]
        if pressed.shape[0] == 0:  # pressed only at a corner shared with another side
            continue
        local = (pressed - pressed.mean(axis=0)) @ basis.T
        lo, hi = local.min(axis=0), local.max(axis=0)
        pad = np.maximum(margin * (hi - lo), 0.04 * size)
        centre = pressed.mean(axis=0)
        flat = (middles[mask] - centre) @ basis.T
        inside = np.all((flat[:, :2] >= lo[:2] - pad[:2]) & (flat[:, :2] <= hi[:2] + pad[:2]),
                        axis=1)
        piece = _piece(faces, np.flatnonzero(mask)[inside])
        turn = np.diag([1.0, float(side), float(side)])  # half a turn about screen x for -n
        coords = (np.asarray(piece.points) - centre) @ basis.T @ turn
        shift = cursor - (lo[0] - pad[0])  # the half turn keeps screen x
        coords[:, 0] += shift
        piece.points = coords @ basis  # back to world axes, laid out
        cursor += float(hi[0] - lo[0] + 2 * pad[0]) * 1.15
        pieces.append(piece)
        name = body_label(body if BODY in faces.cell_data else None, body_names)
        top = (shift + 0.5 * (lo[0] + hi[0])) * right + (
            (hi[1] if side > 0 else -lo[1]) + pad[1]) * up
        labels.append((top, name if side > 0 else f"{name}, pressed on -n (turned over)"))
    if not pieces:
        return None
    surface = pieces[0] if len(pieces) == 1 else pyvista.merge(pieces, merge_points=False)
    bounds = np.array(surface.bounds).reshape(3, 2).T
    return ContactView(
        normal=normal, up=up, right=right, surface=surface, focal=bounds.mean(axis=0),
        labels=tuple(labels) if len(pieces) > 1 else (),
    )


def look_at_contact(plotter, view: ContactView) -> None:
    """Put the current panel's camera on +n of the laid-out surfaces (parallel projection).

    The surfaces fill the left four fifths of a square panel; the colour scale
    stands in the last fifth.
    """
    screen = np.asarray(view.surface.points) @ np.vstack([view.right, view.up]).T  # type: ignore
    width, height = np.ptp(screen, axis=0)
    scale = 0.55 * max(float(height), float(width) / 0.8)  # the right fifth: the colour scale
    focal = view.focal + view.right * 0.2 * scale
    plotter.camera.parallel_projection = True
    plotter.camera.focal_point = tuple(focal)
    plotter.camera.position = tuple(focal + (view.position - view.focal))
    plotter.camera.up = tuple(view.up)
    plotter.camera.parallel_scale = scale
    plotter.reset_camera_clipping_range()
    for where, text in view.labels:
        plotter.add_point_labels(
            np.array([where]), [text], font_size=11, point_size=1, shape_opacity=0.5,
            always_visible=True,
        )


def stick_slip_style() -> dict[str, object]:
    """PyVista ``add_mesh`` keywords for the stick/slip map: open grey, stick blue, slip red."""
    from matplotlib.colors import ListedColormap

    return {
        "scalars": STICK_SLIP, "cmap": ListedColormap(["#d0d0d0", "#1f77b4", "#d62728"]),
        "clim": (-0.5, 2.5),
        "n_colors": 3,
        "annotations": {0.0: "open", 1.0: "stick", 2.0: "slip"},
        "scalar_bar_args": {"title": "stick/slip", "n_labels": 0, "vertical": True,
                            "position_x": 0.86, "position_y": 0.2, "height": 0.6},
    }


def add_contact_panel(plotter, view: ContactView, title: str, *, nodal: bool = False,
                      **style: object) -> np.ndarray:
    """Draw the laid-out pressed surfaces into the current panel, camera on +n.

    ``style``: ``add_mesh`` keywords, ``scalars`` (the field to colour by) among
    them. ``nodal``: draw the surfaces grey and the field on the nodes where it
    is positive (for a nodal state such as stick/slip, not to be interpolated).
    Returns the unit direction from the focal point to the camera as set.
    """
    surface = view.surface.copy()  # type: ignore[attr-defined]
    if nodal:
        _add_nodal(plotter, surface, grey="#eeeeee", show_edges=True, edge_color="#888888",
                   lighting=False, **style)
    else:
        plotter.add_mesh(surface, show_edges=True, edge_color="#888888", lighting=False,
                         **style)
    look_at_contact(plotter, view)
    plotter.add_text(title, position="lower_left", font_size=10)
    return camera_direction(plotter)


def _add_nodal(plotter, mesh, *, grey: str, point_size: int = 12, **style: object) -> None:
    """``mesh`` in ``grey`` and the nodal field ``style["scalars"]`` as dots where it is > 0.

    Edge and lighting keywords (``show_edges``, ``edge_color``, ``lighting``)
    go to the grey mesh, the others to the dots.
    """
    import pyvista

    look = {k: style.pop(k) for k in ("show_edges", "edge_color", "lighting") if k in style}
    plotter.add_mesh(mesh, color=grey, **look)
    values = np.asarray(mesh.point_data[style["scalars"]])
    nodes = pyvista.PolyData(np.asarray(mesh.points)[values > 0])
    nodes.point_data[style["scalars"]] = values[values > 0]  # type: ignore[index]
    plotter.add_mesh(nodes, render_points_as_spheres=True, point_size=point_size, **style)


def camera_direction(plotter) -> np.ndarray:
    """The current panel's unit direction from the focal point to the camera."""
    away = np.asarray(plotter.camera.position) - np.asarray(plotter.camera.focal_point)
    return away / np.linalg.norm(away)


def oblique_direction(normal: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """(camera direction, up) for the whole deformed bodies: aside, a little from +n.

    The screen's up is the global z axis (the bodies stand as they do in the
    scene), the camera above them, unless it looks nearly along z; then the up
    of :func:`screen_axes`. Without contact: from below and aside.
    """
    z = np.eye(3)[2]
    if normal is None:
        return np.array([1.0, -1.3, -0.8]) / np.linalg.norm([1.0, -1.3, -0.8]), z
    up, right = screen_axes(normal)
    direction = 0.5 * normal + 0.6 * right - 0.6 * up
    direction /= np.linalg.norm(direction)
    if abs(float(direction @ z)) < 0.9:
        up = z
        if direction[2] < 0.0:  # seen from above, as the bodies stand
            direction = direction * np.array([1.0, 1.0, -1.0])
    return direction, up


#: Draws what surrounds the bodies into a panel: ``context(plotter, bounds)``.
Context = Callable[[object, np.ndarray], None]


def draw_solid(grid, style: dict[str, object], *, name: str, nodal: bool = False,
               stick_slip: bool = False, context: Context | None = None, size: int = 700,
               body_names: Sequence[str] = ()):
    """The 3D panels of one picture; returns (Picture, PyVista plotter) for the caller to save.

    Left to right: the pressed surfaces seen from their partners along n,
    then (with friction) their stick/slip map, then the whole deformed
    ``grid`` seen aside. Without pressure only the last panel is drawn.

    Args:
        grid: the deformed bodies with :data:`PRESSURE` (and :data:`STICK_SLIP`).
        style: ``add_mesh`` keywords of the field, ``scalars`` among them.
        name: the field's name in the panel titles.
        nodal: draw the field on the pressed surfaces' nodes only (a nodal state).
        stick_slip: add the stick/slip panel when the grid has :data:`STICK_SLIP`.
        context: ``context(plotter, bounds)`` draws what surrounds the bodies
            (the rigid obstacles) in the last panel; bounds (2, 3), length.
        size: the height and the width of one panel in pixels.
        body_names: the bodies' names by their number in :data:`BODY` (the labels
            of the pressed surfaces).
    """
    import pyvista

    view = contact_view(grid, body_names=body_names)
    stick_slip = stick_slip and view is not None and STICK_SLIP in grid.point_data
    columns = 1 + (view is not None) + stick_slip
    plotter = pyvista.Plotter(off_screen=True, window_size=(size * columns, size),
                              shape=(1, columns))
    bar = style.get("scalar_bar_args", {}).get("title", "")  # type: ignore[union-attr]
    picture = Picture(view=view, bar=str(bar))
    panels: list[tuple[str, dict[str, object], bool]] = []
    if view is not None:
        panels.append((f"{name}, seen from the partner along n", style, nodal))
    if stick_slip:
        panels.append(("stick/slip, seen from the partner along n", stick_slip_style(), True))
    for column, (label, look, on_nodes) in enumerate(panels):
        plotter.subplot(0, column)
        picture.directions[label] = add_contact_panel(
            plotter, view, label, nodal=on_nodes, **look)  # type: ignore[arg-type]
        picture.panels.append(label)
    label = "deformed bodies" if BODY in grid.cell_data else "deformed body"
    plotter.subplot(0, columns - 1)
    if nodal:  # a nodal state is not interpolated over the faces (stick between slip and open)
        _add_nodal(plotter, grid.copy(), grey="#dddddd", **style)
    else:
        plotter.add_mesh(grid.copy(), show_edges=False, **style)
    bounds = np.array(grid.bounds).reshape(3, 2).T
    if context is not None:
        context(plotter, bounds)
    direction, up = oblique_direction(None if view is None else view.normal)
    plotter.view_vector(tuple(direction), viewup=tuple(up))
    pad = 0.1 * float(np.max(bounds[1] - bounds[0]))
    lo, hi = bounds[0] - pad, bounds[1] + pad
    plotter.reset_camera(bounds=(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]))
    plotter.add_text(label, position="lower_left", font_size=10)
    picture.directions[label] = camera_direction(plotter)
    picture.panels.append(label)
    return picture, plotter


__all__ = [
    "BODY",
    "PRESSURE",
    "STICK_SLIP",
    "ContactView",
    "Picture",
    "add_contact_panel",
    "body_label",
    "camera_direction",
    "contact_normal",
    "contact_view",
    "draw_solid",
    "look_at_contact",
    "oblique_direction",
    "outward_faces",
    "screen_axes",
    "stick_slip_style",
]
