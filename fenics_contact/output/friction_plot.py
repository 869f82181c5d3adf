"""Picture of the tangential traction against the Coulomb limit along each frictional contact.

Matplotlib (Agg backend, no display). Collective: every process gives its
owned contact nodes, process 0 draws one panel per frictional contact.

In 2D the abscissa is the reference coordinate along which the contact
surface extends most (x for a horizontal plane, y for a vertical wall); the
traction drawn is the tangential traction the partner puts on the body,
its component along that axis, between the limits +-mu p. In 3D the nodes
of a surface have no order along one coordinate (joined by lines in x
order they drew a sawtooth): each node is drawn at its reference distance
from the centre of the contact zone (the mu p weighted centroid of its
nodes), with |tangential traction| beside mu p, as points. Sticking nodes
are filled dots, slipping nodes crosses. A contact zone spanning under half
the surface is shown alone.
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

AXES = "xyz"


def friction_profile_data(problem: ContactProblem) -> dict[str, dict[str, np.ndarray]] | None:
    """Gathered nodal data of each frictional contact on process 0 (None elsewhere).

    By contact name, sorted along the abscissa. Keys: s (abscissa, length:
    the reference coordinate in 2D, the distance from the zone's centre in
    3D), axis (the coordinate's name; "r" in 3D), traction (stress: along
    the axis in 2D, |tau| in 3D), limit (mu p >= 0, stress), state (0 open,
    1 stick, 2 slip).
    """
    comm = problem.comm
    out: dict[str, dict[str, np.ndarray]] = {}
    for contact in problem.contacts:
        if contact.friction is None:
            continue
        state = contact.contact_state()
        coords = contact.nodal_coordinates()[:, : problem.gdim]
        ranges = comm.allgather((np.min(coords, axis=0, initial=np.inf),
                                 np.max(coords, axis=0, initial=-np.inf)))
        lo = np.min([r[0] for r in ranges], axis=0)
        hi = np.max([r[1] for r in ranges], axis=0)
        axis = int(np.argmax(hi - lo))
        # the traction on the body as a vector: the same sign for obstacles and pairs,
        # whatever way each contact's tangent frame turns
        vector, _ = contact.friction.tangential_fields()
        limit = np.asarray(state.coulomb_limit)  # type: ignore[attr-defined]
        if problem.gdim == 2:
            traction, s = vector[:, axis], coords[:, axis]
        else:
            traction = np.linalg.norm(vector, axis=1)
            s = np.linalg.norm(coords - _zone_centre(comm, coords, limit), axis=1)
        local = np.column_stack([s, traction, limit,
                                 state.node_state])  # type: ignore[attr-defined]
        parts = comm.gather(local, root=0)
        if comm.rank == 0:
            data = np.vstack(parts)
            data = data[np.argsort(data[:, 0], kind="stable")]
            out[contact.name] = {"s": data[:, 0],
                                 "axis": AXES[axis] if problem.gdim == 2 else "r",
                                 "traction": data[:, 1],
                                 "limit": data[:, 2], "state": data[:, 3]}
    return out if comm.rank == 0 else None


def _zone_centre(comm, coords: np.ndarray, limit: np.ndarray) -> np.ndarray:
    """The mu p weighted centroid of the contact nodes (their plain centroid if none carry)."""
    weight = np.maximum(limit, 0.0)
    sums = comm.allreduce(np.concatenate([weight @ coords, [weight.sum()],
                                          coords.sum(axis=0), [len(coords)]]))
    d = coords.shape[1]
    if sums[d] > 0.0:
        return sums[:d] / sums[d]
    return sums[d + 1:2 * d + 1] / max(sums[-1], 1.0)


def contact_window(s: np.ndarray, touching: np.ndarray) -> tuple[float, float] | None:
    """Abscissa limits around the touching nodes when they span under half the surface.

    The window holds the touching nodes and a quarter of their span (at
    least one node spacing) on each side; None when nothing touches or the
    zone is wide enough to read on the whole surface.
    """
    if not np.any(touching) or s.size < 2:
        return None
    lo, hi = float(s[touching].min()), float(s[touching].max())
    whole = float(s.max() - s.min())
    if hi - lo >= 0.5 * whole:
        return None
    spacing = float(np.median(np.diff(np.unique(s)))) if np.unique(s).size > 1 else 0.0
    margin = max(0.25 * (hi - lo), 2.0 * spacing, 1e-3 * whole)
    return lo - margin, hi + margin


def friction_profile(problem: ContactProblem, path: Path, title: str = "") -> None:
    """Draw tangential traction and the Coulomb limit +-mu p along each frictional contact."""
    profiles = friction_profile_data(problem)
    if not profiles:
        return
    fig, axes = plt.subplots(len(profiles), 1, figsize=(7, 3.8 * len(profiles)), squeeze=False)
    for ax, (name, data) in zip(axes[:, 0], profiles.items(), strict=True):
        if data["axis"] == "r":
            _radial_panel(ax, name, data, several=len(profiles) > 1)
            continue
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
        window = contact_window(s, (data["limit"] > 0) | (data["state"] != 0))
        if window is not None:
            ax.set_xlim(*window)
        ax.set_xlabel(f"reference {data['axis']} along the contact surface"
                      + (f" '{name}'" if len(profiles) > 1 else "")
                      + (" (its touching part)" if window is not None else ""))
        ax.set_ylabel("tangential traction on the body")
        ax.axhline(0.0, color="k", lw=0.4)
        ax.legend(fontsize=8)
    if title:
        axes[0, 0].set_title(title, fontsize=10)
    save_figure(fig, path)


def _radial_panel(ax, name: str, data: dict[str, np.ndarray], several: bool) -> None:
    """3D: |t| and mu p of every node against its distance from the zone's centre."""
    s, traction, limit = data["s"], data["traction"], data["limit"]
    ax.plot(s, limit, ".", color="#888888", ms=3, label="Coulomb limit mu p")
    stick = data["state"] == STICK
    slip = data["state"] == SLIP
    ax.plot(s[stick], traction[stick], "o", color="#1f77b4", ms=4, label="|t|, stick")
    ax.plot(s[slip], traction[slip], "x", color="#d62728", ms=5, label="|t|, slip")
    window = contact_window(s, (limit > 0) | (data["state"] != 0))
    if window is not None:
        ax.set_xlim(0.0, window[1])
    ax.set_xlabel("reference distance from the centre of the contact zone"
                  + (f" '{name}'" if several else ""))
    ax.set_ylabel("|tangential traction| on the body")
    ax.set_ylim(bottom=0.0)
    ax.legend(fontsize=8)
