"""Picture of the tangential traction against the Coulomb limit along the contact surface.

Matplotlib (Agg backend, no display). Collective: every process gives its
owned contact nodes, process 0 draws. In 2D the abscissa is the reference
coordinate along the plane's tangent (x for a horizontal plane); in 3D it
is the first reference coordinate. The traction drawn is the tangential
traction the obstacle puts on the body (its component along t in 2D, its
magnitude in 3D) with the limits +-mu p; sticking nodes are drawn as
filled dots, slipping nodes as crosses.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from fenics_contact.model.friction import SLIP, STICK
from fenics_contact.model.problem import ContactProblem
from fenics_contact.output.plotting import save_figure


def friction_profile_data(problem: ContactProblem) -> dict[str, np.ndarray] | None:
    """Gathered nodal data on process 0 (None elsewhere), sorted along the abscissa.

    Keys: s (abscissa, length), traction (stress: -tau in 2D, |tau| in 3D),
    limit (mu p >= 0, stress), state (0 open, 1 stick, 2 slip).
    """
    state = problem.contact_state()
    coords = problem.nodal_coordinates()
    tau = state.tangential_traction
    traction = -tau[:, 0] if problem.gdim == 2 else np.linalg.norm(tau, axis=1)
    local = np.column_stack([coords[:, 0], traction, state.coulomb_limit, state.node_state])
    parts = problem.comm.gather(local, root=0)
    if problem.comm.rank != 0:
        return None
    data = np.vstack(parts)
    data = data[np.argsort(data[:, 0], kind="stable")]
    return {"s": data[:, 0], "traction": data[:, 1], "limit": data[:, 2], "state": data[:, 3]}


def friction_profile(problem: ContactProblem, path: Path, title: str = "") -> None:
    """Draw tangential traction and the Coulomb limit +-mu p along the contact surface."""
    data = friction_profile_data(problem)
    if data is None:
        return
    fig, ax = plt.subplots(figsize=(7, 3.8))
    s = data["s"]
    ax.fill_between(
        s, -data["limit"], data["limit"], color="#dddddd", label="Coulomb disc |t| <= mu p"
    )
    ax.plot(s, data["limit"], "k-", lw=0.8)
    ax.plot(s, -data["limit"], "k-", lw=0.8)
    ax.plot(s, data["traction"], "-", color="#1f77b4", lw=1)
    stick = data["state"] == STICK
    slip = data["state"] == SLIP
    ax.plot(s[stick], data["traction"][stick], "o", color="#1f77b4", ms=4, label="stick")
    ax.plot(s[slip], data["traction"][slip], "x", color="#d62728", ms=5, label="slip")
    ax.set_xlabel("reference position along the contact surface")
    ax.set_ylabel("tangential traction on the body")
    ax.axhline(0.0, color="k", lw=0.4)
    ax.legend(fontsize=8)
    if title:
        ax.set_title(title, fontsize=10)
    save_figure(fig, path)
