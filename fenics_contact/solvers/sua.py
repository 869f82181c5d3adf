"""SUA: simultaneous Uzawa, a multiplier update after every Newton iteration."""

from __future__ import annotations

from fenics_contact.solvers.uzawa import UzawaBase


class SimultaneousUzawa(UzawaBase):
    """Newton in u with lam fixed; lam <- min(lam + r g, 0) after each iteration."""

    name = "sua"
    updates_each_step = True

    def after_step(self) -> None:
        """The Uzawa update (paper eq. 10)."""
        self.problem.update_multiplier()
