"""How much of the load the weak springs of stabilised bodies carry.

``[[body]] stabilise`` ties a body to where it starts by springs meant to
hold only its rigid motions (a share of about ``stabilise`` of the load).
When the contact that should hold the body opens, the springs alone hold
the load and a load step still converges: to a body moved by thousands of
its sizes. The share is measured against the load the problem carries: the
largest of the tractions' resultants, the supports' reactions and the
contacts' normal forces, which stays meaningful when a contact carries
nothing (the tractions still pull).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from fenics_contact.model.scaling import force_scale

if TYPE_CHECKING:
    from fenics_contact.model.problem import ContactProblem

#: Springs carrying more than this share of the load make a step invalid: they shift
#: the answer by about as much, where springs that hold only rigid motions carry
#: about ``stabilise`` (<= 1e-3, 1e-6 advised) of it.
SPRING_HELD_SHARE = 1e-2

#: Loads below this share of the force unit E h^(d-1) are round-off, not a load.
LOAD_FLOOR = 1e-12


@dataclass(frozen=True)
class SpringLoad:
    """What the springs of one stabilised body carry.

    Attributes:
        body: the body's name.
        force: the magnitude of the springs' resultant on it (force).
        share: ``force`` over the problem's load (:func:`load_scale`), at most 1.
        moved: the body's largest nodal displacement (length).
        size: the diagonal of its reference bounding box (length).
    """

    body: str
    force: float
    share: float
    moved: float
    size: float


def load_scale(problem: ContactProblem) -> float:
    """The load the problem carries (force; collective).

    The largest magnitude of a traction's resultant, a support's reaction
    and a contact's normal force at the current state, and at least
    ``LOAD_FLOOR`` E h^(d-1).
    """
    tractions = [float(np.linalg.norm(f)) for f in problem.solid.traction_resultants()]
    supports = [float(np.linalg.norm(v)) for v in problem.support_reactions().values()]
    contacts = [abs(s.contact_force) for s in problem.contact_states().values()]
    return max([LOAD_FLOOR * force_scale(problem), *tractions, *supports, *contacts])


def spring_loads(problem: ContactProblem) -> list[SpringLoad]:
    """The springs' part of the load of each stabilised body (collective; [] without any)."""
    forces = problem.stabilisation_forces()
    if not forces:
        return []
    scale = load_scale(problem)
    out = []
    for name, vector in forces.items():
        size = float(np.linalg.norm(vector))
        out.append(SpringLoad(name, size, size / max(scale, size), problem.solid.body_motion(name),
                              problem.solid.body_size(name)))
    return out


def spring_held(problem: ContactProblem, share: float = SPRING_HELD_SHARE) -> str | None:
    """Why the state is no answer when springs hold a body (above ``share``), else None.

    Collective. The message names the body, what the springs carry, how far
    the body moved against its size, and what to try.
    """
    held = [s for s in spring_loads(problem) if s.share > share]
    if not held:
        return None
    worst = max(held, key=lambda s: s.share)
    return (f"held by springs: the stabilising springs of body {worst.body!r}, not the "
            f"contacts or the supports, hold it: they carry {worst.force:.4g}, "
            f"{worst.share:.1%} of the load (above {share:g}), and the body moved by "
            f"{worst.moved:.4g}, its size being {worst.size:.4g}: the contact that should "
            "hold it carries nothing (it opened, or its first Newton iteration pulled the body "
            "off). Stabilise only holds rigid motions. To try: smaller first load steps, a "
            "load that presses before it pulls (a [[dirichlet]] or obstacle that closes the "
            "contact first), or a support that holds the body")


__all__ = ["LOAD_FLOOR", "SPRING_HELD_SHARE", "SpringLoad", "load_scale", "spring_held",
           "spring_loads"]
