"""A 2D mortar pair whose striker nodes overlap more target facets than they may see.

A striker node's weighted gap integrates over its two striker facets, cut
at the target facets that overlap them. The compiled forms hold a fixed
number of such target facets per node, its *slots*, chosen at the start
from the facet sizes where the surfaces first meet (``[[pair]] slots``
overrides). Where the target is finer than that elsewhere (a graded mesh,
a coarse striker sliding onto a fine part of the target), a node overlaps
more facets than it has slots: its weighted gap then leaves part of its
support out, and jumps as the facets it keeps change, which makes Newton
cycle. These checks say so, with the number of slots that would do.
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING

from fenics_contact.model.segments import MOST_SLOTS

if TYPE_CHECKING:
    from fenics_contact.model.problem import ContactProblem


def _fix(slots: int) -> str:
    return f"set [[pair]] slots = {slots}, or refine the striker surface there"


def warn_slots_capped(problem: ContactProblem) -> None:
    """Warn where the meshes asked for more slots than are chosen unasked (collective)."""
    from fenics_contact.scene.checks import SceneWarning

    for use in problem.slot_uses():
        if use.wanted > use.slots:
            kept = (f"at most {MOST_SLOTS} are chosen unasked (each costs compile time)"
                    if use.slots == MOST_SLOTS else f"the pair keeps {use.slots}")
            warnings.warn(SceneWarning(
                f"mortar pair {use.pair!r}: where the surfaces meet, a striker node's two "
                f"facets overlap up to {use.wanted} target facets, and {kept}: "
                f"{_fix(use.wanted)}."), stacklevel=2)


def slot_shortfall(problem: ContactProblem) -> str | None:
    """The fix when a striker node overlapped more target facets than its slots (collective)."""
    short = [u for u in problem.slot_uses() if max(u.now, u.most) > u.slots]
    if not short:
        return None
    return "; ".join(f"mortar pair {u.pair!r}: a striker node overlapped "
                     f"{max(u.now, u.most)} target facets with {u.slots} slots "
                     f"({_fix(max(u.now, u.most) + 1)})" for u in short)


def warn_slot_overflow(problem: ContactProblem) -> None:
    """Warn per 2D mortar pair whose nodes overlapped more target facets than slots (collective)."""
    from fenics_contact.scene.checks import SceneWarning

    for use in problem.slot_uses():
        most = max(use.now, use.most)
        if most <= use.slots:
            continue
        if use.now > use.slots:
            what = (f"in the last state a striker node in contact overlaps {use.now} target "
                    f"facets with {use.slots} slots: its weighted gap leaves part of its "
                    "support out, so the pressures and gaps there are not the mortar answer")
        else:
            what = (f"in an earlier converged state a striker node overlapped up to "
                    f"{use.most} target facets with {use.slots} slots (not in the last "
                    "state); its weighted gap left part of its support out there")
        warnings.warn(SceneWarning(
            f"mortar pair {use.pair!r}: {what}. The target is finer there than the "
            f"slots allow: {_fix(most + 1)}."), stacklevel=2)


__all__ = ["slot_shortfall", "warn_slot_overflow", "warn_slots_capped"]
