"""Read a run's solution.xdmf with three independent readers; print a JSON report.

Usage: ``python read_solution.py DIR/solution.xdmf [REFERENCE/solution.xdmf]``.
Run in its own interpreter (no fenics_contact, no DOLFINx): h5py opens every
HDF5 dataset the index names, meshio reads the temporal collection, VTK's
XDMF reader (through PyVista) reads every time value. With a reference,
each step's fields are compared with the reference's step of the same time,
nodes matched by coordinates and cells by centroids (so runs on different
numbers of processes compare too).
"""

import json
import sys
from pathlib import Path
from xml.etree import ElementTree

import h5py
import meshio
import numpy as np
import pyvista

FIELDS = ("displacement", "contact_pressure", "gap", "active", "von_mises")


def with_h5py(index: Path) -> list[dict]:
    steps = []
    for grid in ElementTree.parse(index).getroot().iter("Grid"):
        if grid.get("GridType") != "Uniform":
            continue
        step = {"t": float(grid.find("Time").get("Value")), "datasets": {}}
        for node in grid:
            item = node.find("DataItem")
            if item is None:
                continue
            file, dataset = item.text.strip().split(":")
            with h5py.File(index.parent / file, "r") as f:
                data = f[dataset][()]
            dims = [int(d) for d in item.get("Dimensions").split()]
            name = node.get("Name", node.tag)
            step["datasets"][name] = {
                "shape_ok": list(data.shape) == dims, "finite": bool(np.isfinite(data).all()),
            }
        steps.append(step)
    return steps


def keyed(points: np.ndarray) -> list[tuple]:
    return [tuple(np.round(p, 9)) for p in points]


class Series:
    """meshio's reading of a temporal collection: per step, time and fields."""

    def __init__(self, index: Path) -> None:
        reader = meshio.xdmf.TimeSeriesReader(str(index))
        points, cells = reader.read_points_cells()
        self.points = points
        conn = cells[0].data
        self.centroids = points[conn].mean(axis=1)
        self.steps = []
        for k in range(reader.num_steps):
            t, point_data, cell_data = reader.read_data(k)
            fields = dict(point_data)
            fields.update({name: blocks[0] for name, blocks in cell_data.items()})
            self.steps.append((float(t), fields))

    def rows(self, other: "Series") -> tuple[np.ndarray, np.ndarray]:
        """Row of each of our nodes and cells in ``other``."""
        nodes = {k: i for i, k in enumerate(keyed(other.points))}
        cells = {k: i for i, k in enumerate(keyed(other.centroids))}
        return (
            np.array([nodes[k] for k in keyed(self.points)]),
            np.array([cells[k] for k in keyed(self.centroids)]),
        )


def with_meshio(index: Path, reference: Path | None) -> list[dict]:
    series = Series(index)
    ref = Series(reference) if reference is not None else None
    if ref is not None:
        node_rows, cell_rows = series.rows(ref)
        ref_steps = {round(t, 12): f for t, f in ref.steps}
    steps = []
    for t, fields in series.steps:
        step = {
            "t": t, "fields": sorted(fields),
            "finite": all(bool(np.isfinite(v).all()) for v in fields.values()),
        }
        if ref is not None:
            other = ref_steps[round(t, 12)]
            step["difference"] = {
                name: float(np.abs(
                    value - other[name][cell_rows if name == "von_mises" else node_rows]
                ).max())
                for name, value in fields.items()
            }
        steps.append(step)
    return steps


def with_vtk(index: Path) -> list[dict]:
    reader = pyvista.XdmfReader(str(index))
    steps = []
    for t in reader.time_values:
        reader.set_active_time_value(t)
        grid = reader.read()
        names = sorted(set(grid.point_data.keys()) | set(grid.cell_data.keys()))
        steps.append({
            "t": float(t), "fields": names, "cells": grid.n_cells,
            "finite": all(bool(np.isfinite(grid[n]).all()) for n in names),
        })
    return steps


def main() -> None:
    index = Path(sys.argv[1])
    reference = Path(sys.argv[2]) if len(sys.argv) > 2 else None
    if not index.exists():  # stopped before its first load step finished
        print(json.dumps({"h5py": [], "meshio": [], "vtk": [], "index": False}))
        return
    print(json.dumps({
        "index": True,
        "h5py": with_h5py(index),
        "meshio": with_meshio(index, reference),
        "vtk": with_vtk(index),
    }))


if __name__ == "__main__":
    main()
