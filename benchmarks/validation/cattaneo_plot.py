"""Picture of Cattaneo-Mindlin runs: nodal tangential traction against q(x).

Shared by benchmarks/validation/cattaneo_mindlin.py (two cylinders) and
benchmarks/validation/cattaneo_cylinder.py (a cylinder on a rigid plane).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from fenics_contact.model.friction import STICK
from fenics_contact.output.plotting import save_figure
from fenics_contact.references.cattaneo import ContactProfile, StickZone, analytic_traction


def traction_picture(
    panels: list[tuple[ContactProfile, StickZone]], mu: float, path: Path, title: str = ""
) -> None:
    """Nodal tangential traction and Coulomb limit against Cattaneo-Mindlin's q(x).

    One panel per (profile, zone), side by side. Abscissa (x - centre)/a;
    the traction is drawn along Q's direction. Call on one process (the
    profiles are gathered everywhere).
    """
    fig, axes = plt.subplots(1, len(panels), figsize=(6.2 * len(panels), 3.9), squeeze=False)
    for ax, (profile, zone) in zip(axes[0], panels, strict=True):
        x = profile.x - zone.centre
        closed = profile.pressure < 0
        tau = profile.tau_along_resultant()
        stick = profile.state == STICK
        s = np.linspace(-zone.a, zone.a, 401)
        ax.plot(s / zone.a, analytic_traction(s, zone.a, zone.c_analytic, zone.p0, mu),
                "k-", lw=1, label="Cattaneo-Mindlin q(x)")
        ax.plot(s / zone.a, mu * zone.p0 * np.sqrt(1 - (s / zone.a) ** 2), "k:", lw=0.8,
                label="mu p (Hertz fit)")
        ax.plot(x[closed] / zone.a, profile.limit[closed], "+", color="#888888",
                label="nodal mu p")
        ax.plot(x[closed & stick] / zone.a, tau[closed & stick], "o", ms=3.5, label="tau, stick")
        ax.plot(x[closed & ~stick] / zone.a, tau[closed & ~stick], "x", ms=4.5,
                label="tau, slip")
        for side in (-1, 1):
            ax.axvline(side * zone.c_analytic / zone.a, color="k", lw=0.5, ls="--")
        ax.set_xlabel("(x - centre) / a")
        ax.set_ylabel("tangential traction")
        ax.set_title(
            f"Q/(mu P) = {zone.load_ratio:.2f}: c/a {zone.c_measured / zone.a:.3f} "
            f"(analytic {zone.c_analytic / zone.a:.3f}), L2 error "
            f"{100 * zone.traction_error:.1f} %",
            fontsize=9,
        )
        ax.legend(fontsize=7, loc="lower center")
    if title:
        fig.suptitle(title, fontsize=10)
    save_figure(fig, path)
