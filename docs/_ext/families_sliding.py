"""Tables and figures of the sliding families.

Ironing (mortar against node-to-segment, and with friction), the sliding
block, and Cattaneo-Mindlin with a mortar pair.

Each ``*_table`` turns the JSON its benchmark wrote into (header, rows) and
each ``*_figure`` into a matplotlib figure; :mod:`validation_families`
names them in ``FAMILIES``.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

Rows = tuple[list[str], list[list[object]]]
PAIRS = ("node-to-segment", "mortar")
WINDOW = (0.6, 2.4)  # the steady window of the ironing slide, in radii


def ironing_mortar_table(data: dict) -> Rows:
    """Per pair: status, iterations, the horizontal reaction over the steady window."""
    header = ["pair", "status", "Newton", "R_x amplitude", "R_x RMS", "mean R_x", "mean -R_y",
              "median order", "largest surface depth"]
    rows = [[d, r["status"], r["iterations"], r["rx_amplitude"], r["rx_rms"], r["rx_mean"],
             -r["ry_mean"], r["median_order"], r["max_surface_depth"]]
            for d in PAIRS for r in [data[d]]]
    rows.append(["mortar / node-to-segment", "", "", data["amplitude_ratio"], data["rms_ratio"],
                 "", "", "", ""])
    # the indenter replaced by an exact rigid circle over the same block mesh (--rigid)
    rows += [[name, r["status"], r["iterations"], r["rx_amplitude"], r["rx_rms"], r["rx_mean"],
              -r["ry_mean"], r["median_order"], r["max_surface_depth"]]
             for name, r in data.get("rigid", {}).items()]
    return header, rows


def ironing_mortar_figure(data: dict) -> Figure:
    """The horizontal reaction on the indenter against the slide, both pairs."""
    fig, ax = plt.subplots(figsize=(6.5, 3.8))
    for d, style in zip(PAIRS, ("s-", "o-"), strict=True):
        rows = data[d]["rows"]
        ax.plot([r["slide_over_R"] for r in rows], [-r["reaction_x"] for r in rows], style,
                ms=3, label=f"{d} (amplitude {data[d]['rx_amplitude']:.3f})")
    ax.axvspan(*WINDOW, color="0.93", zorder=0, label="steady window")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlabel("slide / R (press phase at 0)")
    ax.set_ylabel("horizontal reaction on the indenter")
    ax.set_title(f"Frictionless ironing, {data['mesh']} mesh, the {data['striker']} strikes")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def _interval(pair: list[float]) -> str:
    return f"{pair[0]:.4g} ... {pair[1]:.4g}"


def ironing_friction_table(data: dict) -> Rows:
    """The summary over the steady window: force ratios, tilt, iterations, order."""
    s = data["summary"]
    rows: list[list[object]] = [
        ["status (friction / frictionless)", f"{s['status']} / {s['status_frictionless']}"],
        ["steps in the steady window", s["steady_steps"]],
        ["reaction ratio R_x / -R_y", _interval(s["reaction_ratio"])],
        ["frictionless (ploughing) ratio", _interval(s["ploughing_ratio"])],
        ["mean reaction ratio", s["mean_reaction_ratio"]],
        ["tilt of the normal resultant, degrees", _interval(s["normal_tilt_deg"])],
        ["reaction ratio with the tilt rotated out", _interval(s["corrected_ratio"])],
        ["friction over normal resultant", _interval(s["resultant_ratio"])],
        ["frame ratio int abs(tau) dA / N", _interval(s["frame_ratio"])],
        ["every contact node slips", s["all_slip_in_window"]],
        ["Newton iterations (friction / frictionless)",
         f"{s['iterations']} / {s['iterations_frictionless']}"],
        ["order of the last iterations while sliding (median, min)",
         f"{s['median_order_sliding']:.2f}, {s['min_order_sliding']:.2f}"],
        ["largest penetration / R", s["max_penetration_over_R"]],
    ]
    return [f"quantity (mu = {s['mu']})", "value"], rows


def ironing_friction_figure(data: dict) -> Figure:
    """Force ratios against the slide, with mu; iterations per step."""
    rows = [r for r in data["friction"]["rows"] if "corrected_ratio" in r]
    mu = data["summary"]["mu"]
    slide = [r["slide_over_R"] for r in rows]
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 3.6))
    left.plot(slide, [r["reaction_ratio"] for r in rows], "o-", ms=3, label="R_x / -R_y")
    left.plot(slide, [r["corrected_ratio"] for r in rows], "s-", ms=3,
              label="tilt rotated out")
    left.plot(slide, [r["ploughing_ratio"] for r in rows], "^-", ms=3,
              label="frictionless run")
    left.axhline(mu, color="k", lw=0.8, ls="--", label=f"mu = {mu}")
    left.axvspan(*WINDOW, color="0.93", zorder=0)
    left.set_xlabel("slide / R")
    left.set_ylabel("force ratio")
    left.legend(fontsize=7)
    for key, label in (("friction", f"mu = {mu:g}"), ("frictionless", "frictionless")):
        steps = data[key]["rows"]
        right.plot([r["step"] for r in steps], [r["iterations"] for r in steps], "o-", ms=3,
                   label=label)
    right.set_xlabel("load step (10 pressing, then sliding)")
    right.set_ylabel("Newton iterations")
    right.legend(fontsize=8)
    fig.suptitle("Ironing with Coulomb friction")
    fig.tight_layout()
    return fig


def friction_block_table(data: dict) -> Rows:
    """Every run: method, r, the r_t cap, mu, load path, status, iterations, forces."""
    header = ["method", "r (E/h)", "r_t cap (E/h)", "mu", "load path", "status", "Newton",
              "max per step", "updates", "cut-backs", "N", "F_t,x", "F_t / (mu N)",
              "max abs(u - u_ref)"]
    rows = [[r["method"], r["r_relative"], "r" if r["rt_max"] is None else r["rt_max"],
             "none" if r["mu"] is None else r["mu"], r["load_path"], r["status"],
             r["iterations"], max(r["per_step"]), r["updates"], r["cutbacks"],
             r["normal_force"], r["tangential_force_x"], r["ratio"], r["max_du_vs_reference"]]
            for r in data["records"]]
    return header, rows


def friction_block_figure(data: dict) -> Figure:
    """Newton iterations against r (r_t capped or not); the reference's tangential force."""
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 3.6))
    press_slide = [r for r in data["records"]
                   if r["load_path"] == "press, slide" and r["mu"] == 0.3]
    for method, cap, marker in (("gnrm", 2.0, "o-"), ("gnrm", None, "s--"),
                                ("auto", 2.0, "^-")):
        recs = sorted((r for r in press_slide if r["method"] == method and r["rt_max"] == cap),
                      key=lambda r: r["r_relative"])
        cap_text = "r_t = r" if cap is None else f"r_t capped at {cap:g} E/L"
        left.semilogx([r["r_relative"] for r in recs], [r["iterations"] for r in recs],
                      marker, label=f"{method}, {cap_text}")
    left.set_xlabel("r / (E/h)")
    left.set_ylabel("Newton iterations, 20 steps")
    left.set_yscale("log")
    left.legend(fontsize=7)
    ref = data["reference"]
    steps = np.arange(1, len(ref["tangential_forces"]) + 1)
    right.plot(steps, ref["tangential_forces"], "o-", ms=3, label="F_t (GNRM, r = 1 E/h)")
    right.axhline(ref["mu"] * ref["normal_force"], color="k", ls="--", lw=0.8,
                  label="mu N at the end")
    right.set_xlabel("load step")
    right.set_ylabel("tangential force")
    right.legend(fontsize=8)
    fig.suptitle("Block sliding on a rigid plane (mu = 0.3)")
    fig.tight_layout()
    return fig


def cattaneo_mortar_table(data: dict) -> Rows:
    """Per shift step: the stick half-width against theory and the traction error."""
    header = ["Q/(mu P)", "c/a measured", "c/a analytic", "c error", "half node spacing / c",
              "traction L2 error", "stick nodes", "slip nodes"]
    rows = [[r["load_ratio"], r["c_over_a"], r["c_over_a_analytic"], r["c_error"],
             r["c_resolution"], r["traction_error"], r["stick_nodes"], r["slip_nodes"]]
            for r in data["records"]]
    return header, rows


def cattaneo_mortar_figure(data: dict) -> Figure:
    """The stick half-width against Q/(mu P), mortar pair, against Cattaneo-Mindlin."""
    fig, ax = plt.subplots(figsize=(6, 4))
    ratio = np.linspace(0.0, 1.0, 200)
    ax.plot(ratio, np.sqrt(1.0 - ratio), "k-", label="Cattaneo-Mindlin")
    recs = data["records"]
    ax.plot([r["load_ratio"] for r in recs], [r["c_over_a"] for r in recs], "o", mfc="none",
            label=f"mortar, h = {data['h_contact']:g}, target_ratio {data['target_ratio']:g}")
    ax.set_xlabel("Q / (mu P)")
    ax.set_ylabel("stick half-width c / a")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig
