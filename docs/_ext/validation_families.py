"""The validation families: per benchmark JSON, its table, its figure and how to read it.

Each :class:`Family` turns the JSON a ``benchmarks/validation/<name>.py``
script wrote into table rows and a matplotlib figure; ``FAMILIES`` maps the
script's name to its family; the tables and figures of the pressed bodies
live in :mod:`families_squeeze`, those of sliding in :mod:`families_sliding`.
Adding a family: a JSON in ``docs/data/``, a ``Family`` here, and a line in
``docs/index.md``'s Validation toctree.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import families_sliding as sliding
import families_squeeze as squeeze
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

Rows = tuple[list[str], list[list[object]]]


@dataclass(frozen=True)
class Family:
    """One benchmark family's page: title, table, figure and a reading of them."""

    title: str
    table: Callable[[dict], Rows]
    figure: Callable[[dict], Figure]
    reading: str


def _hertz2d_table(data: dict) -> Rows:
    header = ["r / (E/h)", "predictor", "Newton", "per step", "P", "p0 nodal vs Hertz",
              "a fit vs Hertz", "max penetration", "solve s"]
    rows = [[r["r_relative"], r["predictor"], r["newton_total"], r["newton_per_step"],
             r["force_P"], r["p0_nodal_error"], r["a_error"], r["max_penetration"],
             r["total_s"]] for r in data["records"]]
    return header, rows


def _hertz2d_figure(data: dict) -> Figure:
    records = [r for r in data["records"] if r["predictor"] == "extrapolate"]
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 3.6))
    rs = [r["r_relative"] for r in records]
    left.semilogx(rs, [r["newton_total"] for r in records], "o-")
    left.set_ylim(0, max(r["newton_total"] for r in records) * 1.3)
    left.set_xlabel("r / (E/h)")
    left.set_ylabel("Newton iterations, 10 steps")
    left.set_title("GNRM: the same count at every r")
    right.semilogx(rs, [100 * r["p0_nodal_error"] for r in records], "s-", label="peak (nodal)")
    right.semilogx(rs, [100 * r["a_error"] for r in records], "o-", label="half-width (fit)")
    right.axhline(0, color="k", lw=0.6)
    right.set_xlabel("r / (E/h)")
    right.set_ylabel("error against Hertz (%)")
    right.legend(fontsize=8)
    fig.tight_layout()
    return fig


def _hertz3d_table(data: dict) -> Rows:
    header = ["h", "law", "status", "u DOFs", "Newton per step", "P", "a fit vs Hertz",
              "p0 fit vs Hertz", "p0 nodal vs Hertz", "nodes in contact"]
    rows = [[r["h_contact"], r["law"], r["status"], r["u_dofs"], r["newton_per_step"], r["P"],
             r["a_error"], r["p0_fit_error"], r["p0_nodal_error"], r["n_contact"]]
            for r in data["records"]]
    return header, rows


def _hertz3d_figure(data: dict) -> Figure:
    fig, ax = plt.subplots(figsize=(6, 3.8))
    for law, marker in (("linear", "o"), ("neo-hookean", "s")):
        recs = sorted((r for r in data["records"] if r["law"] == law), key=lambda r: r["h_contact"])
        h = [r["h_contact"] for r in recs]
        ax.semilogx(h, [100 * r["a_error"] for r in recs], marker + "-", label=f"{law}: a")
        ax.semilogx(h, [100 * r["p0_fit_error"] for r in recs], marker + "--",
                    label=f"{law}: p0 (fit)")
    ax.axhline(0, color="k", lw=0.6)
    ax.set_xlabel("contact element size h / R")
    ax.set_ylabel("error against Hertz (%)")
    ax.set_title("Sphere octant on a rigid plane")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def _mortar_table(data: dict) -> Rows:
    header = ["h", "pair", "status", "Newton", "largest nodal p vs p0", "L2 |x| < 1.5 a",
              "the exact profile's P1 interpolant", "L2 |x| < a - 2h"]
    rows = [[r["h"], r["discretisation"], r["status"], r["iterations"], r["peak_error"],
             r["l2_whole"], r.get("exact_interpolant", ""), r["l2_inside"]]
            for r in data["runs"]]
    return header, rows


def _peak_l2_figure(data: dict, region: str, title: str) -> Figure:
    """Largest nodal pressure error and L2 error against h, both pairs."""
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 3.6))
    for kind, marker in (("node-to-segment", "s"), ("mortar", "o")):
        runs = sorted((r for r in data["runs"] if r["discretisation"] == kind),
                      key=lambda r: r["h"])
        h = [r["h"] for r in runs]
        left.loglog(h, [abs(r["peak_error"]) for r in runs], marker + "-", label=kind)
        right.loglog(h, [r["l2_inside"] for r in runs], marker + "-", label=kind)
    left.set_ylabel("|largest nodal pressure / p0 - 1|")
    right.set_ylabel(f"relative L2 error, {region}")
    for ax in (left, right):
        ax.set_xlabel("contact element size h / R")
        ax.legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def _mortar_figure(data: dict) -> Figure:
    return _peak_l2_figure(data, "|x| < a - 2h",
                           "Two cylinders on non-matching meshes against Hertz")


def _patch_table(data: dict) -> Rows:
    header = ["", "pair", "status", "Newton", "pressure spread / exact", "force error"]
    rows = [[r["dimension"], r["discretisation"], r["status"], r["iterations"], r["spread"],
             r["force_error"]] for r in data["runs"]]
    return header, rows


def _patch_figure(data: dict) -> Figure:
    fig, ax = plt.subplots(figsize=(6.4, 3.6))
    runs = data["runs"]
    labels = [f"{r['dimension']} {r['discretisation']}" for r in runs]
    ax.scatter(range(len(runs)), [max(r["spread"], 1e-16) for r in runs], s=60,
               c=["C0" if r["discretisation"] == "node-to-segment" else "C1" for r in runs])
    ax.set_xticks(range(len(runs)), labels, fontsize=8)
    ax.set_yscale("log")
    ax.set_ylabel("(max - min) / exact nodal pressure")
    ax.set_title("Patch test on non-matching meshes")
    fig.tight_layout()
    return fig


def _hemispheres_table(data: dict) -> Rows:
    header = ["h", "pair", "DOFs", "status", "Newton", "a fit vs Hertz", "p0 fit vs Hertz",
              "largest nodal p vs p0", "L2 r < a - 2h", "solve s"]
    rows = [[r["h"], r["discretisation"], r["u_dofs"], r["status"], r["iterations"],
             r["a_error"], r["p0_fit_error"], r["peak_error"], r["l2_inside"], r["solve_s"]]
            for r in data["runs"]]
    return header, rows


def _hemispheres_figure(data: dict) -> Figure:
    return _peak_l2_figure(data, "r < a - 2h",
                           "Two hemispheres on non-matching tetrahedra against Hertz")


def _cattaneo_table(data: dict) -> Rows:
    header = ["mesh", "Q/(mu P)", "c/a measured", "c/a analytic", "c error",
              "half node spacing / c", "traction L2 error"]
    rows = [[r["case"], r["load_ratio"], r["c_over_a"], r["c_over_a_analytic"], r["c_error"],
             r["c_resolution"], r["traction_error"]] for r in data["records"]]
    return header, rows


def _cattaneo_figure(data: dict) -> Figure:
    fig, ax = plt.subplots(figsize=(6, 4))
    ratio = np.linspace(0.0, 1.0, 200)
    ax.plot(ratio, np.sqrt(1.0 - ratio), "k-", label="Cattaneo-Mindlin")
    cases = list(dict.fromkeys(r["case"] for r in data["records"]))
    for case, marker in zip(cases, ("o", "s", "^", "D"), strict=False):
        recs = [r for r in data["records"] if r["case"] == case]
        ax.plot([r["load_ratio"] for r in recs], [r["c_over_a"] for r in recs], marker,
                mfc="none", label=case)
    ax.set_xlabel("Q / (mu P)")
    ax.set_ylabel("stick half-width c / a")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


FAMILIES: dict[str, Family] = {
    "hertz2d": Family(
        "Hertz line contact (2D)", _hertz2d_table, _hertz2d_figure,
        "GNRM takes the same Newton iterations at every r; the answer, and so its "
        "error against Hertz, does not depend on r (nodal rule).",
    ),
    "hertz3d": Family(
        "Hertz point contact (3D)", _hertz3d_table, _hertz3d_figure,
        "The contact radius and the peak pressure approach Hertz as the mesh is refined, "
        "for the small-strain and the neo-Hookean law.",
    ),
    "mortar_hertz": Family(
        "Two cylinders: mortar and node-to-segment pairs", _mortar_table, _mortar_figure,
        "On non-matching meshes the one-pass node-to-segment pressures scatter node to "
        "node and their error does not fall with h; inside the zone the mortar pair's "
        "error falls with h (the whole-zone L2 error also holds the edge of the zone, whose "
        "square root even the exact profile's own P1 interpolant misses by the percentages "
        "shown, least and largest over where the nodes fall; the shipped scene is h = 0.005).",
    ),
    "mortar_patch": Family(
        "Patch test on non-matching meshes (2D and 3D)", _patch_table, _patch_figure,
        "Uniaxial stress makes the exact contact pressure uniform. The mortar pair "
        "reproduces it to round-off on non-matching segments and tetrahedra; the one-pass "
        "node-to-segment pair spreads by tens of per cent, since each striker node reads "
        "the target surface at one point.",
    ),
    "mortar_hemispheres": Family(
        "Two hemispheres (3D): mortar and node-to-segment pairs", _hemispheres_table,
        _hemispheres_figure,
        "The shipped quarter model on non-matching tetrahedra. The node-to-segment nodal "
        "pressures scatter (the largest 7-17 % above p0) while the fitted radius and peak "
        "stay close; the mortar pair's nodal pressures are smooth, the largest within 1.5 % "
        "of p0 on the finest mesh, in the same Newton iterations. The L2 error levels off "
        "near 3.6 %: the tetrahedra, not the pair, then limit it.",
    ),
    "cattaneo_mindlin": Family(
        "Cattaneo-Mindlin partial slip", _cattaneo_table, _cattaneo_figure,
        "The measured stick half-width is the midpoint between the last sticking and the "
        "first slipping node: its error is to be read against the half node spacing.",
    ),
    "cattaneo_mortar": Family(
        "Cattaneo-Mindlin partial slip, mortar pair", sliding.cattaneo_mortar_table,
        sliding.cattaneo_mortar_figure,
        "The shipped Cattaneo-Mindlin scene: non-matching arcs (h = 0.002, ratio 1.37), a "
        "mortar pair, the slip measured at each node's projection. The measured stick "
        "half-width is the midpoint between the last sticking and the first slipping node: "
        "read its error against the half node spacing. The traction error is largest at "
        "small Q, where the traction itself is small.",
    ),
    "two_cylinders": Family(
        "Two cylinders against Hertz (node-to-segment)", squeeze.two_cylinders_table,
        squeeze.two_cylinders_figure,
        "The scene `scenes/two_cylinders_node_to_segment.toml` (node-to-segment pair, "
        "non-matching meshes) against Hertz for two identical cylinders at the computed force; the same "
        "scene solved at r = 0.01 and 100 E/h gives the same force and pressures (last rows: "
        "the relative force difference), with more Newton iterations at the large r.",
    ),
    "ironing_mortar": Family(
        "Ironing: mortar against node-to-segment", sliding.ironing_mortar_table,
        sliding.ironing_mortar_figure,
        "Frictionless elastic ironing dissipates nothing, so the horizontal reaction should "
        "vanish while the indenter slides; what remains is the oscillation of the "
        "discretisation as nodes cross target vertices. On the same meshes the mortar pair's "
        "oscillation is the smaller one (row 3: mortar over node-to-segment). The rigid "
        "circle rows replace the indenter by an exact rigid circle over the same block mesh: "
        "what the block's own discretisation leaves, with nodal contact and at Gauss points.",
    ),
    "ironing_friction": Family(
        "Ironing with Coulomb friction", sliding.ironing_friction_table,
        sliding.ironing_friction_figure,
        "While every contact node slips, the friction resultant is mu times the normal "
        "resultant; the reaction ratio R_x / -R_y differs from mu by the tilt of the normal "
        "resultant (the bow wave of the block), and with the tilt rotated out it is mu. The "
        "frictionless run gives the ploughing part alone.",
    ),
    "friction_block": Family(
        "Block sliding with friction: strategies over r and mu", sliding.friction_block_table,
        sliding.friction_block_figure,
        "`scenes/block_slide_friction.toml` pressed, then slid until every node slips: "
        "F_t / (mu N) is 1 at the end of each converged run with mu up to 0.3. GNRM with the "
        "tangential parameter capped (r_t = min(r, 2 E/L)) converges at every r in the "
        "same count; with r_t = r it fails from r = 1 E/h on (status max_iterations). The "
        "penalty method's forces and displacements approach the reference as r grows.",
    ),
    "o_ring": Family(
        "O-ring squeezed between two plates", squeeze.o_ring_table, squeeze.o_ring_figure,
        "Lindley's formula is empirical (fitted to measured O-rings), so the comparison is "
        "of shape and order of magnitude, not a closed-form check: the plane-strain "
        "neo-Hookean force per length lies above Lindley's by a nearly constant ratio from "
        "12 % compression on. The closed-form check is small-strain elasticity (a disc "
        "between rigid plates, exact while the contact is narrow): the FE starts 2 % above "
        "it at c = 0.03 and leaves it as the contact widens and finite strain stiffens the "
        "section; in linear elasticity at c = 0.01 the scene meets it to 0.6 % (tested). "
        "The plates' forces balance to round-off.",
    ),
    "bridge_rim": Family(
        "A bridge across two supports: which surface strikes", squeeze.bridge_rim_table,
        squeeze.bridge_rim_figure,
        "No closed form: four meshes against each other. As the supports spread their top "
        "corners slide out under the bridge, so a striker tagged over the supports only "
        "misses them and carries 3-4 % less on the finer meshes (mortar). Node-to-segment "
        "opens striker nodes past the support's rim by more than a quarter facet and holds "
        "the ones closer, which stand in for the corner below them.",
    ),
    "tube_crush": Family(
        "Tube crushed until its inner wall closes", squeeze.tube_crush_table,
        squeeze.tube_crush_figure,
        "The shipped mesh (4 layers through the wall) against one twice as fine (8 layers). "
        "Before the inner wall touches, the difference is the bending stiffness of linear "
        "triangles and falls about fourfold per halving of the size; finer pairs (8 against "
        "16 and 16 against 32 layers) are measured in [Contacts](../../contacts.md).",
    ),
}
