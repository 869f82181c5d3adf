"""Cattaneo-Mindlin interim check: stick half-width and traction profile of a cylinder.

Small-strain half-cylinder (R = 1, E = 200) clamped at its flat top; the
rigid plane moves up by 0.01 (pressing, 4 steps), then sideways by 0.003
(8 steps), mu = 0.3, GNRM at r = 0.01 E/h, vertex rule. Pressing is
frictionless unless ``frictional press`` (then mu acts from the start).
Per shear step: Q / (mu P), measured and analytic stick half-width c, the
relative error of c, the node spacing at the stick edge relative to c and
the relative L2 error of the nodal tangential traction against
Cattaneo-Mindlin's profile. See :mod:`fenics_contact.verification.cattaneo`.

Run: ``python benchmarks/cattaneo_cylinder.py [--out results/bench]``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import harness

import fenics_contact  # noqa: F401  (before dolfinx)
from fenics_contact.verification.cattaneo import CattaneoCylinder, solve_cattaneo

CASES = [  # (nu, h_contact, degree, frictionless pressing)
    (0.3, 0.004, 1, True), (0.45, 0.004, 1, True), (0.49, 0.004, 1, True),
    (0.3, 0.002, 1, True), (0.45, 0.002, 1, True), (0.45, 0.004, 2, True),
    (0.45, 0.004, 1, False), (0.49, 0.004, 2, True),
]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=harness.OUT)
    parser.add_argument("--picture-only", action="store_true", help="only draw the profile")
    args = parser.parse_args()
    picture(args.out / "cattaneo_traction.png")
    if args.picture_only:
        return
    records, rows = [], []
    for nu, h, degree, frictionless in CASES:
        cylinder = CattaneoCylinder(nu=nu, h_contact=h, degree=degree, shift=0.003)
        start = time.perf_counter()
        if frictionless:
            _, zones, iterations = solve_cattaneo(cylinder)
        else:  # mu from the start: press_steps = 0 keeps mu on throughout
            _, zones, iterations = solve_frictional_press(cylinder)
        wall = time.perf_counter() - start
        for k, z in enumerate(zones):
            rec = {"nu": nu, "beta": cylinder.dundurs_beta, "h_contact": h, "degree": degree,
                   "frictionless_press": frictionless, "shear_step": k + 1,
                   "Q_over_muP": z.Q / (cylinder.mu * z.P), **z.to_dict(),
                   "iterations": iterations, "wall_s": wall}
            records.append(rec)
            if k in (1, 3, 7):
                rows.append([nu, round(cylinder.dundurs_beta, 3), h, degree,
                             "no" if frictionless else "yes", rec["Q_over_muP"],
                             z.c_measured, z.c_analytic, z.c_error, z.c_resolution,
                             z.traction_error])
                print(*rows[-1], flush=True)
    header = ["nu", "beta", "h", "degree", "friction in pressing", "Q/(mu P)", "c measured",
              "c analytic", "c error", "node spacing / c", "traction L2 error"]
    table = harness.md_table(header, rows)
    harness.write("cattaneo_cylinder", {"machine": harness.machine(), "records": records},
                  table, args.out)
    print(table)


def picture(path: Path, nu: float = 0.45, h: float = 0.002) -> None:
    """Nodal tangential traction and Coulomb limit against Cattaneo-Mindlin (last shear step)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from fenics_contact.model.friction import STICK
    from fenics_contact.verification.cattaneo import analytic_traction

    cylinder = CattaneoCylinder(nu=nu, h_contact=h, shift=0.003)
    problem, zones, _ = solve_cattaneo(cylinder)
    zone = zones[-1]
    state = problem.contact_state()
    x = problem.nodal_coordinates()[:, 0]
    order = np.argsort(x)
    x, closed = x[order], state.pressure[order] < 0
    tau = np.abs(state.tangential_traction[order, 0])
    limit = state.coulomb_limit[order]
    stick = state.node_state[order] == STICK
    s = np.linspace(-zone.a, zone.a, 401)
    fig, ax = plt.subplots(figsize=(7, 3.8))
    ax.plot(s / zone.a, analytic_traction(s, zone.a, zone.c_analytic, zone.p0, cylinder.mu),
            "k-", lw=1, label="Cattaneo-Mindlin q(x)")
    ax.plot(s / zone.a, cylinder.mu * zone.p0 * np.sqrt(1 - (s / zone.a) ** 2), "k:", lw=0.8,
            label="mu p (Hertz fit)")
    ax.plot(x[closed] / zone.a, limit[closed], "+", color="#888888", label="nodal mu p")
    ax.plot(x[closed & stick] / zone.a, tau[closed & stick], "o", ms=4, label="|tau|, stick")
    ax.plot(x[closed & ~stick] / zone.a, tau[closed & ~stick], "x", ms=5, label="|tau|, slip")
    for sign in (-1, 1):
        ax.axvline(sign * zone.c_analytic / zone.a, color="k", lw=0.5, ls="--")
    ax.set_xlabel("x / a")
    ax.set_ylabel("tangential traction")
    ax.set_title(
        f"nu = {nu}, h = {h}: Q/(mu P) = {zone.Q / (cylinder.mu * zone.P):.3f}, "
        f"c error {100 * zone.c_error:+.1f} %, L2 error {100 * zone.traction_error:.1f} %",
        fontsize=9,
    )
    ax.legend(fontsize=7)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def solve_frictional_press(cylinder: CattaneoCylinder):
    """Like :func:`solve_cattaneo` but with friction already while pressing."""
    import numpy as np

    from fenics_contact.model.contact import ContactSettings
    from fenics_contact.solvers import make_strategy
    from fenics_contact.solvers.diagnostics import SolverSettings
    from fenics_contact.verification.cattaneo import measure_stick_zone

    problem = cylinder.build(ContactSettings(r=0.01))
    strategy = make_strategy("gnrm", problem, SolverSettings(atol=1e-10, rtol=1e-10,
                             max_iterations=60), predictor="previous")
    loads = list(np.linspace(0, 0.5, 5)[1:]) + list(np.linspace(0.5, 1.0, 9)[1:])
    zones, iterations = [], []
    for k, t in enumerate(loads):
        problem.commit()
        problem.set_load(float(t))
        result = strategy.solve()
        iterations.append(result.iterations)
        if k >= 4:
            zones.append(measure_stick_zone(problem))
    return problem, zones, iterations


if __name__ == "__main__":
    main()
