"""One facet tag set for every surface integral of a problem.

A DOLFINx form takes one subdomain data per integral type, so every ``ds``
of a problem (each contact surface, each traction) must read the same
facet tags. A facet may play several roles (a traction on a candidate
contact surface, a surface that meets two partners): each distinct
combination of roles gets its own tag value, and role i integrates over
the tuple of tag values whose combination holds i, ``ds(ids[i])``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from dolfinx import mesh


def check_facet_indices(domain: mesh.Mesh, facets: np.ndarray, where: str) -> None:
    """Refuse facet indices outside the mesh's local facets (ValueError naming them).

    ``where`` names the argument, e.g. "ObstacleContact 'floor': facets".
    Local facet indices (owned and ghosts) run from 0 to the count - 1.
    """
    fdim = domain.topology.dim - 1
    domain.topology.create_entities(fdim)
    im = domain.topology.index_map(fdim)
    count = im.size_local + im.num_ghosts
    bad = np.unique(facets[(facets < 0) | (facets >= count)])
    if bad.size:
        shown = ", ".join(str(int(f)) for f in bad[:5]) + (", ..." if bad.size > 5 else "")
        raise ValueError(
            f"{where}: {bad.size} facet index(es) out of range ({shown}); the mesh's local "
            f"facet indices run from 0 to {count - 1}. Give facets of this mesh (e.g. "
            "facet_tags.find(tag) or mesh.locate_entities_boundary(mesh, dim - 1, where)).")


def facet_roles(
    domain: mesh.Mesh, groups: Sequence[np.ndarray]
) -> tuple[mesh.MeshTags, list[tuple[int, ...]]]:
    """Facet tags for role groups (local facet indices) and each group's tag values.

    Tag values start at 1 and are numbered by the sorted combinations of
    roles, the same on every rank. A group with no facet on any rank gets
    an empty tuple.
    """
    fdim = domain.topology.dim - 1
    n_facets = domain.topology.index_map(fdim).size_local + \
        domain.topology.index_map(fdim).num_ghosts
    bits = np.zeros(n_facets, dtype=np.int64)
    if len(groups) > 62:
        raise ValueError(f"{len(groups)} surface roles; at most 62 fit in one facet tag set.")
    for i, facets in enumerate(groups):
        facets = np.unique(np.asarray(facets, dtype=np.int32))
        bits[facets] |= np.int64(1) << i
    used = np.flatnonzero(bits)
    combos = sorted(set().union(*domain.comm.allgather(set(np.unique(bits[used]).tolist()))))
    value_of = {c: k + 1 for k, c in enumerate(combos)}
    values = np.array([value_of[int(b)] for b in bits[used]], dtype=np.int32)
    tags = mesh.meshtags(domain, fdim, used.astype(np.int32), values)
    ids = [tuple(value_of[c] for c in combos if c >> i & 1) for i in range(len(groups))]
    return tags, ids


def own_tag_values(ids: Sequence[tuple[int, ...]]) -> list[tuple[int, ...]]:
    """Per role, its tag values that no other role reads (facets with that role alone).

    ``ids``: each role's tag values, as :func:`facet_roles` gives them. A
    solver may integrate a role's terms over fewer of these facets without
    touching another role's integrals.
    """
    out = []
    for i, values in enumerate(ids):
        others = {t for j, group in enumerate(ids) if j != i for t in group}
        out.append(tuple(t for t in values if t not in others))
    return out
