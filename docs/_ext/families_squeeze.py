"""Tables and figures of the pressed-body families: two cylinders, the O-ring, the crushed tube.

Each ``*_table`` turns the JSON its benchmark wrote into (header, rows) and
each ``*_figure`` into a matplotlib figure; :mod:`validation_families`
names them in ``FAMILIES``.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

Rows = tuple[list[str], list[list[object]]]


def two_cylinders_table(data: dict) -> Rows:
    """Hertz quantities against the computed ones, then the answer at each r."""
    header = ["quantity", "computed", "Hertz", "relative error"]
    rows: list[list[object]] = [
        ["contact half-width a (fit)", data["a_fit"], data["a_hertz"], data["a_error"]],
        ["peak pressure p0 (fit)", data["p0_fit"], data["p0_hertz"], data["p0_error"]],
        ["largest nodal pressure", data["p0_nodal"], data["p0_hertz"], data["p0_nodal_error"]],
    ]
    for r, run in data["r_independence"].items():
        rows.append([f"r = {r} E/h: Newton iterations, 10 steps", sum(run["iterations"]),
                     "force vs r = 1", run["force_rel_diff"]])
    return header, rows


def two_cylinders_figure(data: dict) -> Figure:
    """The nodal pressures against the Hertz profile at the computed force."""
    fig, ax = plt.subplots(figsize=(6.5, 3.8))
    a, p0 = data["a_hertz"], data["p0_hertz"]
    xs = np.linspace(-1.3 * a, 1.3 * a, 400)
    ax.plot(xs, p0 * np.sqrt(np.clip(1.0 - (xs / a) ** 2, 0.0, None)), "k-",
            label="Hertz, two cylinders")
    x, p = np.asarray(data["profile"]["x"]), -np.asarray(data["profile"]["p"])
    near = np.abs(x) < 1.5 * a
    ax.plot(x[near], p[near], "o", ms=4, mfc="none", label="nodes (striker side)")
    ax.set_xlabel("x")
    ax.set_ylabel("contact pressure")
    ax.set_title(f"a {data['a_error']:+.2%}, p0 {data['p0_error']:+.2%} against Hertz")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def o_ring_table(data: dict) -> Rows:
    """Per compression: force per length against small-strain elasticity and Lindley, width."""
    header = ["compression c", "F/L", "small-strain elasticity", "F/L over it", "Lindley",
              "F/L over Lindley", "contact width / d", "Newton"]
    rows = [[c, f, el, f / el, lin, ratio, width / 2.0, its]
            for c, f, el, lin, ratio, width, its in zip(
                data["compression"], data["force_per_length"], data["elastic"],
                data["lindley"], data["ratio"], data["contact_width"], data["iterations"],
                strict=True)]
    return header, rows


def o_ring_figure(data: dict) -> Figure:
    """Force per length against compression: FE, small-strain elasticity, Lindley; width."""
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 3.6))
    c = np.asarray(data["compression"])
    left.plot(c, data["force_per_length"], "o-", label="FE (plane strain, neo-Hookean)")
    left.plot(c, data["elastic"], "k:", label="small-strain elasticity (disc between plates)")
    left.plot(c, data["lindley"], "k--", label="Lindley (empirical)")
    left.set_xlabel("compression c")
    left.set_ylabel("force per unit length F/L")
    left.legend(fontsize=8)
    right.plot(c, np.asarray(data["contact_width"]) / 2.0, "s-")
    right.set_xlabel("compression c")
    right.set_ylabel("contact width / d (each plate)")
    fig.suptitle("O-ring cross-section between two rigid plates")
    fig.tight_layout()
    return fig


def tube_crush_table(data: dict) -> Rows:
    """Per load step both meshes reached: plate force on each and the inner wall's contact."""
    coarse, fine = data["coarse"], data["fine"]
    n = min(len(coarse["t"]), len(fine["t"]))
    header = ["plate travel", "force, coarse", "force, fine", "difference",
              "inner-wall nodes touching (coarse, fine)"]
    rows = [[data["travel"] * coarse["t"][i], coarse["top"][i], fine["top"][i],
             abs(coarse["top"][i] - fine["top"][i]) / fine["top"][i],
             f"{coarse['inner_active'][i]}, {fine['inner_active'][i]}"] for i in range(n)]
    return header, rows


def tube_crush_figure(data: dict) -> Figure:
    """Plate force against travel on both meshes; where the inner wall touches."""
    fig, ax = plt.subplots(figsize=(6.5, 3.8))
    for label, marker in (("coarse", "o-"), ("fine", "s--")):
        run = data[label]
        travel = data["travel"] * np.asarray(run["t"])
        ax.semilogy(travel, run["top"], marker, ms=4,
                    label=f"{label} mesh {run['parameters']}")
        touching = np.asarray(run["inner_active"]) > 0
        if touching.any():
            ax.axvline(travel[np.argmax(touching)], color="0.6", lw=0.8, ls=":")
    ax.set_xlabel("plate travel")
    ax.set_ylabel("plate force (per unit length)")
    ax.set_title("Tube crushed between two plates (dotted: the inner wall touches)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def bridge_rim_table(data: dict) -> Rows:
    """Per mesh, striker and pair: Newton iterations and the load the bridge carries."""
    header = ["h bridge", "striker", "pair", "Newton", "load", "status"]
    rows = [[r["h_bridge"], r["striker"], r["discretisation"], r["iterations"], r["load"],
             r["status"]] for r in data["runs"]]
    return header, rows


def bridge_rim_figure(data: dict) -> Figure:
    """The load against the bridge's facet size, for each striker and pair."""
    fig, ax = plt.subplots(figsize=(6.5, 3.8))
    styles = {("whole underside", "mortar"): "o-", ("whole underside", "node-to-segment"): "s-",
              ("over the supports", "mortar"): "o--",
              ("over the supports", "node-to-segment"): "s--"}
    for (striker, pair), style in styles.items():
        runs = [r for r in data["runs"] if r["striker"] == striker
                and r["discretisation"] == pair]
        ax.semilogx([r["h_bridge"] for r in runs], [r["load"] for r in runs], style,
                    mfc="none", label=f"{pair}, {striker}")
    ax.set_xlabel("bridge facet size h")
    ax.set_ylabel("load carried (per unit length)")
    ax.set_title("A bridge across two supports")
    ax.legend(fontsize=7)
    fig.tight_layout()
    return fig
