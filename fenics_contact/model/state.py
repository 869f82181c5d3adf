"""Records of a problem's state: nodal contact diagnostics and snapshots.

Sign conventions as in :mod:`.contact`: lam <= 0 is the pressure, g >= 0 open.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from mpi4py import MPI


@dataclass(frozen=True)
class ProblemState:
    """A copy of the unknowns and the load factor, for undoing a failed increment.

    Attributes:
        u: displacement dof values (owned and ghost), length.
        multipliers: every multiplier's dof values (owned and ghost), in the
            order of the problem's ``multipliers()`` (stress).
        load_factor: the load factor the state belongs to.
    """

    u: np.ndarray
    multipliers: tuple[np.ndarray, ...]
    load_factor: float


@dataclass(frozen=True)
class ContactState:
    """Nodal contact diagnostics at the current iterate.

    Attributes:
        gap: nodal gaps at the owned multiplier nodes (length).
        pressure: nodal contact pressure (<= 0, stress): the multiplier for
            multiplier strategies, r min(g, 0) for the penalty method.
        multiplier: nodal multiplier lam.
        active: owned nodes with a pressure < 0.
        active_count: global number of nodes with a pressure < 0.
        max_penetration: global max of -min(g, 0) (length).
        contact_force: global normal force -int p dA on the reference surface
            (force; per unit thickness in 2D). Multiplier strategies report
            -int lam dA: at convergence lam = p, and lam does not carry the
            round-off of r g that p carries at huge r (at r = 1e12 E/h a gap
            of 1e-15 makes r g of order one). The penalty method, whose
            multiplier is zero, reports -int r min(g, 0) dA.
        constraint_penetration: two deformable bodies: the max penetration by
            the discretisation's own gap (to the plane of each node's assigned
            facet), while ``max_penetration`` is the depth inside the actual
            target surface; None where the two are one (rigid obstacles).
        tangential_force: global |int T tau dA| (force); 0 without friction.
        stick_count: global number of sticking contact nodes (0 without friction).
        slip_count: global number of slipping contact nodes (0 without friction).
    """

    gap: np.ndarray
    pressure: np.ndarray
    multiplier: np.ndarray
    active: np.ndarray
    active_count: int
    max_penetration: float
    contact_force: float
    constraint_penetration: float | None = None
    tangential_force: float = 0.0
    stick_count: int = 0
    slip_count: int = 0

    def summary(self) -> dict[str, float | int]:
        """The global numbers of the state (for a step's record): forces, counts, depth."""
        return {
            "normal_force": self.contact_force, "active_count": self.active_count,
            "max_penetration": self.max_penetration,
            "tangential_force": self.tangential_force, "stick_count": self.stick_count,
            "slip_count": self.slip_count,
        }

    @classmethod
    def gathered(
        cls,
        comm: MPI.Comm,
        gap: np.ndarray,
        pressure: np.ndarray,
        multiplier: np.ndarray,
        local_force: float,
        active: np.ndarray | None = None,
    ) -> ContactState:
        """The state from this rank's nodal values, with the summaries reduced over ``comm``.

        Args:
            comm: communicator of the problem.
            gap: owned nodal gaps (length).
            pressure: owned nodal pressure (<= 0, stress); active where < 0.
            multiplier: owned nodal multipliers.
            local_force: this rank's share of the contact force (force).
            active: owned active nodes (default: where ``pressure`` < 0).
        """
        if active is None:
            active = pressure < 0.0
        active_count = comm.allreduce(int(active.sum()), op=MPI.SUM)
        force = comm.allreduce(local_force, op=MPI.SUM)
        return cls(
            gap=gap,
            pressure=pressure,
            multiplier=multiplier,
            active=active,
            active_count=active_count,
            max_penetration=comm.allreduce(
                float(np.max(-np.minimum(gap, 0.0), initial=0.0)) + 0.0, op=MPI.MAX
            ),
            # no node in contact: the force of the round-off multipliers (1e-207) is none
            contact_force=force if active_count else 0.0,
        )


def combined_state(states: Sequence[ContactState]) -> ContactState:
    """One state for several contacts: nodal arrays joined, counts and forces summed.

    The penetrations are the largest over the contacts; ``contact_force`` is
    the sum of the contacts' normal forces (each -int p dA on its own surface).
    """
    if len(states) == 1:
        return states[0]
    constraint = [s.constraint_penetration for s in states if s.constraint_penetration is not None]
    return ContactState(
        gap=np.concatenate([s.gap for s in states]),
        pressure=np.concatenate([s.pressure for s in states]),
        multiplier=np.concatenate([s.multiplier for s in states]),
        active=np.concatenate([s.active for s in states]),
        active_count=sum(s.active_count for s in states),
        max_penetration=max(s.max_penetration for s in states),
        contact_force=sum(s.contact_force for s in states),
        constraint_penetration=max(constraint) if constraint else None,
        tangential_force=sum(s.tangential_force for s in states),
        stick_count=sum(s.stick_count for s in states),
        slip_count=sum(s.slip_count for s in states),
    )
