"""``fenics-contact mesh``: turn gmsh .geo sources into .msh files."""

from __future__ import annotations

import argparse
from pathlib import Path


def generate(geo: Path, out: Path, parameters: dict[str, float]) -> Path:
    """Mesh ``geo`` in its own dimension and write ``out`` (.msh, format 4.1)."""
    from fenics_contact.scene.meshing import gmsh_session, open_geo

    with gmsh_session() as (gmsh, _):
        gmsh.option.setNumber("General.Terminal", 0)
        open_geo(gmsh, geo, parameters)
        dim = max(d for d, _ in gmsh.model.getPhysicalGroups())
        gmsh.model.mesh.generate(dim)
        out.parent.mkdir(parents=True, exist_ok=True)
        gmsh.write(str(out))
    return out


def _parameter(text: str) -> tuple[str, float]:
    name, _, value = text.partition("=")
    try:
        return name.strip(), float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected NAME=VALUE, got {text!r}") from None


def _mesh(args: argparse.Namespace) -> int:
    sources = args.geo or sorted(Path("meshes").glob("*.geo"))
    if not sources:
        raise FileNotFoundError("No .geo files given and none in meshes/.")
    for geo in sources:
        if not geo.exists():
            raise FileNotFoundError(f"No such .geo file: {geo}")
        out = (args.out or geo.parent) / (geo.stem + ".msh")
        generate(geo, out, dict(args.set))
        print(f"{geo} -> {out}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``mesh`` subcommand."""
    mesh = sub.add_parser(
        "mesh",
        help="generate .msh files from the gmsh .geo sources",
        description="Mesh gmsh .geo files (default: every meshes/*.geo) into .msh files "
        "beside them, keeping their physical groups (the tags scenes refer to).",
    )
    mesh.add_argument("geo", nargs="*", type=Path, help=".geo files (default meshes/*.geo)")
    mesh.add_argument("--out", type=Path, default=None, help="folder for the .msh files")
    mesh.add_argument(
        "--set", type=_parameter, action="append", default=[], metavar="NAME=VALUE",
        help="set a .geo parameter, e.g. --set h_contact=0.002 (repeatable)",
    )
    mesh.set_defaults(func=_mesh)
