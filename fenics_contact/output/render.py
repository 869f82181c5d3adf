"""Draw any field of any finished load step of a run, from its files alone (PyVista, off-screen).

Reads ``OUT/solution/step_NNNN.xdmf`` and its HDF5 file (each step's own
files, complete once the index names them), warps the mesh by the
displacement (true scale) and colours it by the chosen field: a point or cell
field, vectors by their magnitude. In 3D the picture looks at the contact as
``deformed.png`` does (:func:`fenics_contact.output.contact_view.draw_solid`):
the pressed surfaces seen from their partners along the contact normal, then
the whole deformed bodies. Nothing of the run is rebuilt: no mesh
object, no forms. The HDF5 data is read with h5py: VTK's own XDMF reader
brings a second HDF5 library that must not meet DOLFINx's in one process.
"""

from __future__ import annotations

import json
from pathlib import Path
from xml.etree import ElementTree

import numpy as np

from fenics_contact.output.contact_view import (
    BODY,
    PRESSURE,
    STICK_SLIP,
    Picture,
    draw_solid,
    stick_slip_style,
)
from fenics_contact.output.xdmf import finished_steps, step_folder

#: VTK cell type of each XDMF topology DOLFINx writes (the same vertex order).
_VTK_CELLS = {"Triangle": 5, "Quadrilateral": 9, "Tetrahedron": 10, "Hexahedron": 12}
#: Colour maps: pressure dark where high (as in deformed.png), the others sequential.
_CMAPS = {"contact_pressure": "inferno_r", "active": "cividis", "stick_slip": "cividis"}
#: Colour-bar titles of the fields whose names are long: the bar stands in a narrow strip
#: at the right of a 3D panel (the panel's title names the field in full).
_BAR_TITLES = {
    "contact_pressure": "p = -lam", "displacement": "|u|", "von_mises": "von Mises",
    "tangential_traction": "|t_T|", "slip": "|slip|", "target_contact_force": "|f_target|",
    "body_id": "body",
}


def field_labels(field: str, vector: bool = False) -> tuple[str, str]:
    """(the panel's name of ``field``, its colour bar's title); ``vector``: drawn by magnitude.

    The title is short enough for the bar's strip of a 3D panel, e.g.
    ("contact pressure -lam", "p = -lam"), ("|tangential traction|", "|t_T|").
    """
    label = field.replace("_", " ")
    if vector:
        label = f"|{label}|"
    if field == "contact_pressure":
        label = "contact pressure -lam"
    return label, _BAR_TITLES.get(field, label)


def body_names(out: Path) -> list[str]:
    """The bodies' names of the run in ``out``, by body number (from its summary.json).

    Empty when the folder has no readable summary.json or it names no bodies.
    """
    try:
        bodies = json.loads((out / "summary.json").read_text()).get("bodies", [])
        return [str(b["name"]) for b in bodies]
    except (OSError, ValueError, TypeError, KeyError, AttributeError):
        return []


def obstacle_outlines(out: Path, step: int, bounds: np.ndarray) -> list:
    """The run's rigid obstacles placed as at load step ``step`` (PyVista meshes).

    From summary.json (each obstacle's shape and its point at every finished
    step); empty when it holds none, or when the run is older than these
    records.
    """
    from fenics_contact.output.pictures import obstacle_outline

    try:
        obstacles = json.loads((out / "summary.json").read_text()).get("obstacles", [])
        shapes = []
        for o in obstacles:
            placed = next(s["point"] for s in o["steps"] if s["step"] == step)
            shapes.append(obstacle_outline(o["type"], placed, bounds, normal=o.get("normal"),
                                           radius=o.get("radius")))
        return shapes
    except (OSError, ValueError, TypeError, KeyError, AttributeError, StopIteration):
        return []


def _step_file(out: Path, step: int | None) -> tuple[Path, int]:
    """The step file of ``step`` (None: the last finished one), or ValueError naming the steps."""
    index = out / "solution.xdmf"
    steps = finished_steps(index) if index.is_file() else []
    if not steps:
        raise ValueError(
            f"{out} holds no finished load step (no {index.name}); give the --out folder of a "
            "run that finished at least one step."
        )
    chosen = steps[-1] if step is None else step
    if chosen not in steps:
        raise ValueError(
            f"Step {chosen} is not among the finished steps of {out} "
            f"({steps[0]}-{steps[-1]}); choose one of those."
        )
    return step_folder(index) / f"step_{chosen:04d}.xdmf", chosen


def _read_step(source: Path):
    """The step's mesh as a PyVista grid with every field of the step file attached."""
    import h5py
    import pyvista

    root = ElementTree.parse(source).getroot()
    mesh = next(g for g in root.iter("Grid") if g.get("GridType") == "Uniform")
    kind = mesh.find("Topology").get("TopologyType")  # type: ignore[union-attr]
    if kind not in _VTK_CELLS:
        raise ValueError(f"{source}: cells of type {kind!r} cannot be drawn here.")
    fields = {a.get("Name"): a for a in root.iter("Attribute")}
    try:
        data = h5py.File(source.with_suffix(".h5"), "r")
    except OSError as exc:
        raise ValueError(
            f"{source.with_suffix('.h5')} cannot be read ({exc}): the step file is damaged; "
            "draw another --step, or run the scene again."
        ) from None
    with data as f:
        x = f["Mesh/mesh/geometry"][()]
        cells = f["Mesh/mesh/topology"][()].astype(np.int64)
        points = np.pad(x, ((0, 0), (0, 3 - x.shape[1])))
        layout = np.hstack([np.full((cells.shape[0], 1), cells.shape[1]), cells]).ravel()
        grid = pyvista.UnstructuredGrid(
            layout, np.full(cells.shape[0], _VTK_CELLS[kind], np.uint8), points
        )
        for name, attribute in fields.items():
            item = attribute.find("DataItem")
            dataset = item.text.strip().split(":", 1)[1]  # type: ignore[union-attr]
            values = f[dataset][()]
            values = values[:, 0] if values.ndim == 2 and values.shape[1] == 1 else values
            target = grid.point_data if attribute.get("Center") == "Node" else grid.cell_data
            target[name] = values
    return grid


def render_step(
    out: Path, *, step: int | None = None, field: str | None = None,
    path: Path | None = None, window: tuple[int, int] = (1200, 800),
) -> Path:
    """Render ``field`` of load step ``step`` of the run in ``out`` on the deformed mesh.

    Args:
        out: the run's output folder (``fenics-contact run ... --out OUT``).
        step: the load step (1-based; None: the last finished one).
        field: a point or cell field of the step file; vectors are drawn by magnitude.
            None: contact_pressure, or displacement where the run wrote no pressure.
        path: the PNG to write (default ``OUT/render_step_NNNN_FIELD.png``).
        window: image size in pixels (2D; in 3D the height of each panel).

    Returns:
        The PNG written. Raises ValueError naming the available steps or fields.
    """
    return draw_step(out, step=step, field=field, path=path, window=window)[0]


def draw_step(
    out: Path, *, step: int | None = None, field: str | None = None,
    path: Path | None = None, window: tuple[int, int] = (1200, 800),
) -> tuple[Path, Picture]:
    """:func:`render_step`, also returning what the picture shows (its panels and cameras)."""
    import pyvista

    source, chosen = _step_file(out, step)
    grid = _read_step(source)
    names = sorted(set(grid.point_data) | set(grid.cell_data))
    if field is None:
        field = next((f for f in ("contact_pressure", "displacement") if f in names), names[0])
    if field not in names:
        raise ValueError(
            f"Field {field!r} is not in step {chosen} of {out}; available: {', '.join(names)}."
        )
    if "displacement" in grid.point_data:
        u = np.asarray(grid.point_data["displacement"], dtype=float)
        grid.points = np.asarray(grid.points) + u[:, :3]
    data = grid.point_data if field in grid.point_data else grid.cell_data
    values = np.asarray(data[field], dtype=float)
    label, bar = field_labels(field, vector=values.ndim > 1)
    if values.ndim > 1:
        values = np.linalg.norm(values, axis=1)
    data[label] = values
    flat = float(np.ptp(np.asarray(grid.points)[:, 2])) == 0.0
    pyvista.OFF_SCREEN = True
    pyvista.vtk_verbosity("off")
    style: dict[str, object] = {
        "scalars": label, "cmap": _CMAPS.get(field, "viridis"),
        "scalar_bar_args": {"title": bar}}
    bounds = np.array(grid.bounds).reshape(3, 2).T
    outlines = obstacle_outlines(out, chosen, bounds)
    if flat:
        nodal = field in ("stick_slip", "active")
        if field == "stick_slip":
            grid.point_data[STICK_SLIP] = values
            style = {**stick_slip_style(), "scalar_bar_args": {"title": "stick/slip",
                                                              "n_labels": 0}}
        picture, plotter = _draw_plane(grid, style, label, bar, window, outlines, nodal)
    else:
        if "contact_pressure" in grid.point_data:
            grid.point_data[PRESSURE] = np.asarray(grid.point_data["contact_pressure"])
        if "stick_slip" in grid.point_data:
            grid.point_data[STICK_SLIP] = np.asarray(grid.point_data["stick_slip"])
        if "body_id" in grid.cell_data:
            grid.cell_data[BODY] = np.asarray(grid.cell_data["body_id"])
        style["scalar_bar_args"] = {"title": bar, "vertical": True, "position_x": 0.86,
                                    "position_y": 0.2, "height": 0.6}
        if field == "stick_slip":
            style = stick_slip_style()
        def context(plotter, near_bounds: np.ndarray) -> None:
            grow = 0.15 * (near_bounds[1] - near_bounds[0])
            box = np.concatenate([near_bounds[0] - grow, near_bounds[1] + grow])[
                [0, 3, 1, 4, 2, 5]]
            for shape in outlines:  # only its part near the bodies
                plotter.add_mesh(shape.clip_box(tuple(box), invert=False), color="#555555",
                                 opacity=0.3)

        picture, plotter = draw_solid(
            grid, style, name=label, nodal=field in ("stick_slip", "active"),
            size=window[1], body_names=body_names(out), context=context)
        plotter.subplot(0, 0)
    plotter.add_text(f"{_run_name(out)}: step {chosen}, {label}", font_size=12)
    target = path or out / f"render_step_{chosen:04d}_{field}.png"
    target.parent.mkdir(parents=True, exist_ok=True)
    plotter.screenshot(str(target))
    plotter.close()
    return target, picture


def _run_name(out: Path) -> str:
    """The scene's name from the run's summary.json, else the folder's name."""
    try:
        return str(json.loads((out / "summary.json").read_text())["scene"])
    except (OSError, ValueError, TypeError, KeyError):
        return out.name


def _draw_plane(grid, style: dict, label: str, bar: str, window: tuple[int, int],
                outlines: list = (), nodal: bool = False):
    """2D: the whole body, and beside it a window on each small contact zone (as deformed.png).

    The zones are those of the step's contact pressure (any field is drawn
    in them); a zone spanning more than a fifth of the body gets none.
    """
    import pyvista

    from fenics_contact.output.pictures import _contact_lines, _contact_zones, _frame

    bounds = np.array(grid.bounds).reshape(3, 2).T
    zooms = []
    if "contact_pressure" in grid.point_data:
        grid.point_data[PRESSURE] = np.asarray(grid.point_data["contact_pressure"], float)
        zooms = _contact_zones(grid, float(np.max(bounds[1] - bounds[0])))
    width = window[0] * (1 + len(zooms)) // (2 if zooms else 1)
    plotter = pyvista.Plotter(off_screen=True, window_size=(width, window[1]),
                              shape=(1, 1 + len(zooms)))
    views = [(bounds, label)] + [
        (zoom, f"{label}, contact zone" + ("" if len(zooms) == 1 else f" {k + 1}"))
        for k, zoom in enumerate(zooms)]
    # the pressure lives on the boundary: its pressed edges drawn thick, as in deformed.png
    pressed = None
    if "pressure" in label and np.any(grid.point_data.get(PRESSURE, np.zeros(1)) > 0):
        pressed = _contact_lines(grid)
    picture = Picture(bar=bar)
    for column, (frame, title) in enumerate(views):
        plotter.subplot(0, column)
        if nodal:  # a nodal state (stick/slip, active): on the nodes, never interpolated
            plotter.add_mesh(grid.copy(), show_edges=True, edge_color="#9a9a9a",
                             color="#eeeeee")
            on = np.asarray(grid.point_data[style["scalars"]]) > 0
            if np.any(on):
                nodes = pyvista.PolyData(np.asarray(grid.points)[on])
                nodes.point_data[style["scalars"]] = np.asarray(
                    grid.point_data[style["scalars"]])[on]
                plotter.add_mesh(nodes, render_points_as_spheres=True,
                                 point_size=12 if column else 9,
                                 **{**style, "show_scalar_bar": column == 0})
        else:
            plotter.add_mesh(grid.copy(), show_edges=True, edge_color="#777777",
                             **{**style, "show_scalar_bar": column == 0})
        if pressed is not None and pressed.n_cells:
            plotter.add_mesh(pressed.copy(), scalars=PRESSURE, cmap=style["cmap"],
                             clim=[0.0, float(np.max(grid.point_data[PRESSURE]))],
                             line_width=8 if column else 5, show_scalar_bar=False)
        for shape in outlines:  # the rigid obstacles, as in deformed.png
            plotter.add_mesh(shape.copy(), color="#555555", line_width=3)
        plotter.view_xy()
        plotter.camera.parallel_projection = True
        if zooms or outlines:  # the bodies framed, not the obstacles' lines
            _frame(plotter, frame, aspect=width / (1 + len(zooms)) / window[1])
        if zooms:
            plotter.add_text(title, position="lower_left", font_size=10)
        picture.panels.append(title)
    plotter.subplot(0, 0)
    return picture, plotter


__all__ = ["body_names", "draw_step", "field_labels", "render_step"]
