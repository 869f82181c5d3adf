"""The targets report reads the benchmarks' records as they write them.

The records below have the structure the scripts write (``harness.write`` with
the scripts' dictionaries), with made-up figures.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from benchmarks import harness, targets

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = sorted(p.stem for p in (ROOT / "scenes").glob("*.toml"))
#: active_set_prediction.py's TARGETS: each case's Newton iteration target.
LIMITS = {"hertz-medium": 12, "hertz-fine": 16, "two-cylinders": 22, "two-cylinders-mortar": 22,
          "paper-ex2": 40}
VARIANTS = (("previous", "sign"), ("extrapolate", "sign"), ("active-set", "sign"),
            ("active-set", "exact"))


def _write(bench: Path, name: str, data: dict) -> None:
    """``<bench>/<name>.json`` as harness.write writes it (``name`` may hold a folder)."""
    harness.write(Path(name).name, data, "| table |", bench / Path(name).parent)


def _prediction(exact: dict[str, list[int]]) -> dict:
    """active_set_prediction.json: every case and variant; ``exact``: the per-step counts
    of the active-set predictor with the exact set, the other variants 3 per step."""
    runs = {}
    for case in LIMITS:
        for variant in VARIANTS:
            per_step = exact[case] if variant == ("active-set", "exact") else [3] * 10
            runs[f"{case}/{'/'.join(variant)}"] = {
                "case": case, "predictor": variant[0], "contact_set": variant[1],
                "columns": 4 if variant[1] == "exact" else 0, "newton": sum(per_step),
                "per_step": per_step, "active": [9] * 10, "path_s": 0.8,
                "u_difference": 1e-12, "target": LIMITS[case]}
    return {"machine": {}, "repeats": 3, "runs": runs}


def _cost(exact: float, bare: float) -> dict:
    """cost_of_contact.json: ratios keyed by the '/'-joined contact variants and dirichlet."""
    keys = ("active-set/exact", "active-set/sign", "extrapolate/sign", "previous/sign",
            "dirichlet", "dirichlet-bare")
    ratio = {k: 1.5 for k in keys} | {"active-set/exact": exact, "dirichlet": 1.0}
    to_bare = {k: 1.6 for k in keys} | {"active-set/exact": bare, "dirichlet-bare": 1.0}
    return {"machine": {}, "repeats": 5, "median": {k: {"case": k} for k in keys},
            "ratio": ratio, "ratio_to_bare_loop": to_bare, "contact_nodes": 29,
            "runs": {k: [] for k in keys}}


def _auto(counts: dict[str, list[int]]) -> dict:
    """auto_r_range.json: Newton iterations per scene at r = 1e-8, 1e-6, ..., 1e12 E/h."""
    r_values = [10.0**e for e in range(-8, 13, 2)]
    scenes = {}
    for name, its in counts.items():
        iterations = {f"{r:g}": n for r, n in zip(r_values, its, strict=True)}
        scenes[name] = {"iterations": iterations,
                        "status": {r: "converged" for r in iterations},
                        "ratio": max(its) / iterations["1"]}
    return {"machine": {}, "r_values": r_values, "target_ratio": 1.3, "scenes": scenes}


def _inexact(u_dofs: int, ratio: float) -> tuple[str, dict]:
    """inexact_newton_<dofs>_np1.json: medians per solver with ratio and Newton extra."""
    base = {"u_dofs": u_dofs, "total_s": 17.5, "newton_total": 9, "ratio": 1.0,
            "newton_extra": 0, "u_difference": 0.0, "force_difference": 0.0}
    median = {"iterative": base, "inexact": {**base, "total_s": 17.5 * ratio, "ratio": ratio,
                                             "u_difference": 7e-12}}
    return f"inexact_newton_{u_dofs}_np1", {
        "machine": {}, "rounds": 3, "u_dofs": u_dofs, "ranks": 1, "target_ratio": 0.5,
        "median": median, "runs": {s: [] for s in median}}


def _ladder(solver: str, u_dofs: int, total_s: float) -> tuple[str, dict]:
    """ladder3d/<solver>_<dofs>_np2.json: the median of a ladder case and its runs."""
    median = {"u_dofs": u_dofs, "solver": solver, "ranks": 2, "total_s": total_s,
              "newton_total": 12, "peak_rss_gb_sum": 6.57, "peak_rss_gb_max": 3.29,
              "repeats": 1}
    return f"ladder3d/{solver}_{u_dofs}_np2", {"median": median, "runs": [median]}


def _two_body(ratio: float, per_iteration_s: float, share: tuple[float, float],
              newton: tuple[int, int] = (21, 20)) -> dict:
    """two_body_3d_iterative[_np2].json: both cases' medians and the cost ratios."""
    two = {"dofs": 106347, "iterations": newton[0], "per_iteration_s": per_iteration_s,
           "search_share": share[0], "transfer_share": share[1], "peak_rss_gb_max": 2.0}
    one = {"dofs": 101430, "iterations": newton[1], "per_iteration_s": per_iteration_s / ratio,
           "search_share": 0.0, "transfer_share": 0.0, "peak_rss_gb_max": 1.5}
    return {"h": 0.013, "dim": 3, "solver": "iterative", "steps": 4, "processes": 1,
            "two_bodies": two, "one_body_rigid": one, "cost_ratio_per_iteration": ratio,
            "cost_ratio_per_round": [ratio, ratio + 0.04, ratio - 0.02],
            "runs": {"two_bodies": [two], "one_body_rigid": [one]}, "machine": {}}


def _first(cold: dict[str, float], warm: dict[str, float]) -> dict:
    """first_iteration.json as harness.report writes it: one run per scene."""
    runs = [{"scene": name, "cold_s": cold.get(name, 3.0), "warm_s": warm.get(name, 1.0),
             "import_s": 0.9, "status": "first iteration"} for name in cold | warm]
    return {"machine": {}, "runs": runs}


@pytest.fixture
def bench(tmp_path: Path) -> Path:
    """A records folder with every record: met, missed and borderline targets."""
    _write(tmp_path, "active_set_prediction", _prediction({
        "hertz-medium": [1] * 10,
        "hertz-fine": [9] + [1] * 9,  # 18: over 16
        "two-cylinders": [5] + [2] * 8 + [1],  # 22 in all, step 1 over 4
        "two-cylinders-mortar": [3, 3] + [2] * 8,  # 22, step 1 3
        "paper-ex2": [3] * 9 + [4],
    }))
    _write(tmp_path, "cost_of_contact", _cost(1.26, 1.39))
    _write(tmp_path, "auto_r_range", _auto({
        "two-cylinders": [30, 30, 30, 30, 30, 35, 37, 36, 35, 35, 35],
        "hertz": [16] * 11, "sliding-blocks": [28, 28, 28, 28, 28, 30, 35, 33, 32, 31, 30]}))
    for name, data in (_inexact(100575, 0.37), _inexact(300763, 0.9),
                       _ladder("inexact", 985527, 151.0), _ladder("iterative", 985527, 153.5)):
        _write(tmp_path, name, data)
    _write(tmp_path, "two_body_3d_iterative", _two_body(1.21, 3.4, (0.005, 0.034)))
    _write(tmp_path, "two_body_3d_iterative_np2", _two_body(1.39, 1.7, (0.005, 0.07)))
    shipped_cold = {"two_hemispheres_3d_node_to_segment": 4.9, "two_hemispheres_3d": 12.2,
                    "three_blocks_3d": 9.8, "block_on_block_3d": 12.3}
    _write(tmp_path, "first_iteration",
           _first(shipped_cold, {name: 1.0 for name in SHIPPED} | {"cattaneo_mindlin": 2.16}))
    _write(tmp_path, "friction/first_iteration",
           _first({"two_hemispheres_3d_node_to_segment_mu0.3": 16.8,
                   "two_hemispheres_3d_mu0.3": 25.3}, {}))
    return tmp_path


def _rows(bench: Path) -> dict[str, dict]:
    return {row["target"]: row for row in targets.report(bench)}


def _row(rows: dict[str, dict], start: str) -> dict:
    (row,) = [r for name, r in rows.items() if name.startswith(start)]
    return row


def test_the_records_figures_and_verdicts(bench: Path) -> None:
    rows = _rows(bench)
    medium = _row(rows, "2D Hertz, 10 steps, GNRM, medium")
    assert (medium["before"], medium["now"], medium["met"]) == (
        "17", "10 (1 1 1 1 1 1 1 1 1 1)", "yes")
    fine = _row(rows, "2D Hertz, 10 steps, GNRM, fine")
    assert (fine["before"], fine["now"][:2], fine["met"]) == ("29", "18", "no")
    assert _row(rows, "two cylinders (node-to-segment)")["met"] == "no"  # step 1 is 5
    mortar = _row(rows, "two cylinders (mortar")
    assert (mortar["now"], mortar["met"]) == ("22 (3 3 2 2 2 2 2 2 2 2)", "yes")
    assert mortar["before"] == "30-36, step 1 6-7"
    assert _row(rows, "the paper's Example 2")["now"].startswith("31 ")
    cost = _row(rows, "cost of contact")
    assert cost["before"] == "2.16x" and cost["met"] == "yes"
    assert cost["now"] == "1.26x like for like, 1.39x against the bare Newton loop"
    auto = _row(rows, "auto at r")
    assert auto["met"] == "yes" and "two-cylinders 1.23x (30 at r = 1)" in auto["now"]
    assert "sliding-blocks 1.25x" in auto["now"]
    inexact = _row(rows, "inexact Newton, 1e5")  # the 1e5 record, not the larger one
    assert inexact["met"] == "yes" and inexact["now"].startswith("0.37x the fixed rtol's time")
    assert "6.5 s" in inexact["now"] and "+0" in inexact["now"] and inexact["before"] == "31 s"
    million = _row(rows, "inexact Newton, 1e6")
    assert million["met"] == "no"
    assert million["now"] == "151.0 s, 985527 DOFs, 3.29 GB per rank (fixed rtol 153.5 s)"
    serial = _row(rows, "two bodies, 1e5 DOFs")
    assert (serial["before"], serial["met"]) == ("1.95x", "yes")
    assert serial["now"] == "1.21x (rounds 1.21, 1.25, 1.19)"
    assert _row(rows, "the same on 2 ranks")["met"] == "no"
    share = _row(rows, "the same: search")
    assert share["met"] == "yes" and share["now"] == "3.9% serially, 7.5% on 2 ranks"
    speed = _row(rows, "the same: 2 ranks")
    assert speed["met"] == "yes" and speed["now"] == "2.00x, Newton 21 and 21, 20 and 20"
    cold = _row(rows, "first start of the frictional")
    assert (cold["before"], cold["now"], cold["met"]) == ("39 s", "16.8 s (0.43x)", "yes")
    shipped = _row(rows, "first start of the shipped")
    assert shipped["met"] == "no" and "block_on_block_3d 12.3 s (0.78x)" in shipped["now"]
    warm = _row(rows, "warm start")
    assert warm["met"] == "yes"
    assert warm["now"] == f"at most 2.16 s (cattaneo_mindlin, {len(SHIPPED)} scenes)"


def test_a_missed_threshold_says_no(bench: Path) -> None:
    _write(bench, "cost_of_contact", _cost(1.31, 1.2))
    _write(bench, "two_body_3d_iterative_np2",
           _two_body(1.2, 1.7, (0.005, 0.07), newton=(22, 20)))  # 2.00x, but 21 against 22
    rows = _rows(bench)
    assert _row(rows, "cost of contact")["met"] == "no"
    assert _row(rows, "the same on 2 ranks")["met"] == "yes"
    speed = _row(rows, "the same: 2 ranks")
    assert speed["met"] == "no" and speed["now"] == "2.00x, Newton 21 and 22, 20 and 20"
    _write(bench, "two_body_3d_iterative_np2", _two_body(1.2, 2.1, (0.005, 0.07)))
    speed = _row(_rows(bench), "the same: 2 ranks")
    assert speed["met"] == "no" and speed["now"] == "1.62x, Newton 21 and 21, 20 and 20"


def test_slow_starts_and_auto_over_its_bound_say_no(bench: Path) -> None:
    _write(bench, "friction/first_iteration",
           _first({"two_hemispheres_3d_node_to_segment_mu0.3": 19.6}, {}))  # 0.503x
    _write(bench, "first_iteration", _first({}, {name: 1.0 for name in SHIPPED}
                                            | {"o_ring": 3.01}))
    auto = _auto({"hertz": [16] * 5 + [21] * 6})  # 1.31x
    rows = _rows(bench)
    assert _row(rows, "first start of the frictional")["now"] == "19.6 s (0.50x)"
    assert _row(rows, "first start of the frictional")["met"] == "no"
    assert _row(rows, "warm start")["met"] == "no" and "3.01 s (o_ring" in _row(
        rows, "warm start")["now"]
    _write(bench, "auto_r_range", auto)
    assert _row(_rows(bench), "auto at r")["met"] == "no"
    auto = _auto({"hertz": [16] * 11})
    auto["scenes"]["hertz"]["status"]["1e+12"] = "diverged"
    _write(bench, "auto_r_range", auto)
    row = _row(_rows(bench), "auto at r")
    assert row["met"] == "no" and row["now"].endswith("not every run converged")


def test_missing_records_name_the_command_that_writes_them(tmp_path: Path) -> None:
    rows = _rows(tmp_path)
    assert {r["met"] for r in rows.values()} == {"not measured"}
    assert all(r["now"].startswith("not measured: python ")
               or r["now"].startswith("not measured: mpiexec -n 2 python ") for r in rows.values())
    assert _row(rows, "2D Hertz, 10 steps, GNRM, medium")["now"] == (
        "not measured: python benchmarks/performance/active_set_prediction.py")
    assert _row(rows, "auto at r")["now"] == ("not measured: python benchmarks/performance/"
                                              "auto_r_range.py (asserted by tests/test_auto.py)")
    assert "ladder3d.py --dofs 1e6 --solver inexact" in _row(rows, "inexact Newton, 1e6")["now"]
    assert _row(rows, "the same on 2 ranks")["now"].startswith("not measured: mpiexec -n 2")
    assert "--friction 0.3" in _row(rows, "first start of the frictional")["now"]


def test_a_partial_record_is_not_measured(bench: Path) -> None:
    """A scene left out of the warm starts, a ladder without its 1e6 point, a case left out."""
    _write(bench, "first_iteration", _first({}, {"hertz_cylinder": 1.0}))
    (bench / "ladder3d" / "inexact_985527_np2.json").unlink()
    _write(bench, "ladder3d/inexact_301250_np2", _ladder("inexact", 301250, 20.0)[1])
    data = json.loads((bench / "active_set_prediction.json").read_text())
    del data["runs"]["paper-ex2/active-set/exact"]
    _write(bench, "active_set_prediction", data)
    rows = _rows(bench)
    for start in ("warm start", "first start of the shipped", "inexact Newton, 1e6",
                  "the paper's Example 2"):
        assert _row(rows, start)["met"] == "not measured", start


def test_the_report_is_written(bench: Path, capsys: pytest.CaptureFixture) -> None:
    targets.main(["--bench", str(bench)])
    written = json.loads((bench / "targets.json").read_text())["targets"]
    assert written == targets.report(bench)
    table = (bench / "targets.md").read_text()
    assert table.startswith("| target | before | now | met? |")
    assert len(table.splitlines()) == 2 + len(targets.TARGETS)
    assert table in capsys.readouterr().out + "\n"
