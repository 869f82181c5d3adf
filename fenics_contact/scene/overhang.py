"""After a run: node-to-segment striker nodes held in contact past the free edge of the target.

A node-to-segment pair measures a striker node's gap to the plane of its
target facet. Past the end of the target surface (its free edge) that plane
is the last facet's extended, so a striker that runs on beyond the target,
level with it, is held there and its force counted although nothing supports
it (a bridge across two blocks: the force 21 % high). Such nodes are found at
the end of a run and named in one warning per pair.
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING

import numpy as np

from fenics_contact.model.pairs import NodeToSegmentContact

if TYPE_CHECKING:
    from fenics_contact.model.problem import ContactProblem
    from fenics_contact.scene.schema import Scene


def warn_overhanging_pairs(scene: Scene, problem: ContactProblem) -> int:
    """Warn per node-to-segment pair with nodes in contact past its target's free edge.

    Returns how many such nodes there are over the pairs (collective).
    """
    from fenics_contact.scene.checks import SceneWarning

    comm, total = problem.comm, 0
    gdim = problem.domain.geometry.dim
    for contact in problem.contacts:
        if not isinstance(contact, NodeToSegmentContact) or contact.self_contact:
            continue
        pressed = contact.contact_state().active
        beyond = contact.pair.past_free_edge()[: pressed.size] & pressed
        where = contact.nodal_coordinates()[beyond][:, :gdim]
        found = np.concatenate(comm.allgather(where))
        if found.shape[0] == 0:
            continue
        total += found.shape[0]
        point = ", ".join(f"{v:.4g}" for v in found[0])
        warnings.warn(SceneWarning(
            f"{scene.path.name}: [[pair]] {contact.name!r}: {found.shape[0]} striker node(s) in "
            f"contact lie past the free edge of the target surface (one at ({point})): "
            "node-to-segment holds them on the extension of the target's last facet and counts "
            "their force. Tag the striker only where it can meet the target, or use "
            'discretisation = "mortar" or [pairing] automatic = true.'), stacklevel=2)
    return total


__all__ = ["warn_overhanging_pairs"]
