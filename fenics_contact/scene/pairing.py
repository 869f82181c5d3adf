"""[pairing] automatic = true: contact pairs found from the bodies instead of declared.

Read into a :class:`~.spec.PairingSpec`; built into one node-to-segment
contact per pair of bodies that can meet (:mod:`fenics_contact.model.automatic_pairing`).
Body pairs a [[pair]] block already joins are left to it.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from dolfinx import mesh

from fenics_contact.model.automatic_pairing import (
    automatic_contacts,
    body_surfaces,
    surface_box,
    symmetry_cut_facets,
)
from fenics_contact.model.body import Body
from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.friction import FrictionSettings
from fenics_contact.model.pairs import NodeToSegmentContact
from fenics_contact.scene.contact_sections import _contact_r, _friction
from fenics_contact.scene.reader import _table
from fenics_contact.scene.spec import PairingSpec, Scene, SceneError


def read_pairing(path: Path, data: dict[str, Any]) -> PairingSpec | None:
    """The [pairing] table (None when absent); ``automatic`` must be true."""
    if "pairing" not in data:
        return None
    reader = _table(path, data, "pairing")
    if reader.table.get("automatic") is not True:
        raise reader.fail("automatic", "set automatic = true to pair every body with every "
                          "other, or remove [pairing] and declare [[pair]] blocks.")
    margin = reader.number("margin", positive=True) if "margin" in reader.table else None
    return PairingSpec(
        r=_contact_r(reader), relative=reader.flag("relative", True), mu=_friction(reader),
        tangential_r_max=reader.number("tangential_r_max", 2.0, positive=True), margin=margin,
    )


def load_path_reach(scene: Scene) -> float:
    """Largest displacement the scene prescribes: Dirichlet values and paths, obstacle motions."""
    values = [abs(v) for d in scene.dirichlet for v in d.value if v is not None]
    values += [abs(v) for d in scene.dirichlet for knot in d.path for v in knot[1:]]
    for o in scene.obstacles:
        values.append(float(np.linalg.norm(o.obstacle.motion)) if o.obstacle.motion else 0.0)
        values += [float(np.linalg.norm(row[1:])) for row in o.obstacle.schedule]
    return max(values, default=0.0)


def pairing_contacts(
    scene: Scene, domain: mesh.Mesh, cell_tags: mesh.MeshTags, bodies: Sequence[Body],
    paired: set[frozenset[str]], conditions: Sequence[object] = (),
) -> list[NodeToSegmentContact]:
    """The automatic contacts of a scene with [pairing] (none without it).

    Each body's box is enlarged by the load path's reach plus the margin
    (default: a tenth of the smaller diagonal of the bodies' boxes). The
    faces of symmetry cuts among the Dirichlet ``conditions`` are no
    contact surface (:func:`~.automatic_pairing.symmetry_cut_facets`).
    """
    spec = scene.pairing
    if spec is None:
        return []
    margin = spec.margin
    if margin is None:
        surfaces = body_surfaces(domain, cell_tags, bodies)
        diagonals = [float(np.linalg.norm(hi - lo))
                     for lo, hi in (surface_box(domain, f) for f in surfaces.values())]
        margin = 0.1 * min(diagonals)
    friction = None if spec.mu is None else FrictionSettings(spec.mu, spec.tangential_r_max)
    contacts, _ = automatic_contacts(
        domain, cell_tags, bodies, ContactSettings(r=spec.r, relative=spec.relative),
        load_path_reach(scene) + margin, skip=paired, friction=friction,
        cuts=symmetry_cut_facets(domain, conditions))
    if not contacts and not scene.pairs:
        raise SceneError(
            f"{scene.path.name}: [pairing] automatic = true found no two bodies that can meet "
            f"(their boxes, enlarged by the load path and margin = {margin:.4g}, are apart); "
            "raise [pairing] margin or declare [[pair]] blocks."
        )
    return contacts


__all__ = ["load_path_reach", "pairing_contacts", "read_pairing"]
