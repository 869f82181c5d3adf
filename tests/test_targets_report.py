"""The targets report reads the benchmarks' records as they write them."""

from __future__ import annotations

import json
from pathlib import Path

from benchmarks import targets


def _write(path: Path, data: dict) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(data))


def _prediction(newton: dict[str, tuple[int, list[int]]]) -> dict:
    """An active_set_prediction.json: runs keyed case/predictor/contact set."""
    return {"runs": {f"{case}/active-set/exact": {"newton": n, "per_step": steps}
                     for case, (n, steps) in newton.items()}}


def _rows(bench: Path) -> dict[str, dict]:
    return {row["target"]: row for row in targets.report(bench)}


def test_met_missed_and_missing_targets_read_from_the_records(tmp_path: Path) -> None:
    _write(tmp_path / "active_set_prediction.json", _prediction({
        "hertz-medium": (10, [1] * 10),
        "hertz-fine": (18, [9] + [1] * 9),  # over 16: missed
        "two-cylinders": (22, [5] + [2] * 8 + [1]),  # 22 in all, but step 1 over 4
        "two-cylinders-mortar": (20, [2] * 10),
        "paper-ex2": (31, [3] * 9 + [4]),
    }))
    _write(tmp_path / "cost_of_contact.json", {
        "ratio": {"active-set/exact": 1.26, "dirichlet": 1.0},
        "ratio_to_bare_loop": {"active-set/exact": 1.39, "dirichlet": 1.1}})
    two = {"per_iteration_s": 3.4, "iterations": 21, "search_share": 0.005,
           "transfer_share": 0.034}
    _write(tmp_path / "two_body_3d_iterative.json", {
        "cost_ratio_per_iteration": 1.21, "cost_ratio_per_round": [1.21, 1.25, 1.19],
        "two_bodies": two})
    _write(tmp_path / "two_body_3d_iterative_np2.json", {
        "cost_ratio_per_iteration": 1.39, "cost_ratio_per_round": [1.45, 1.39, 1.32],
        "two_bodies": {**two, "per_iteration_s": 1.7, "transfer_share": 0.07}})
    _write(tmp_path / "first_iteration.json", {"runs": [
        {"scene": "hertz_cylinder", "warm_s": 1.1}, {"scene": "o_ring", "warm_s": 2.5}]})
    rows = _rows(tmp_path)
    medium = rows["2D Hertz, 10 steps, medium mesh: <= 12 Newton iterations"]
    assert (medium["before"], medium["met"]) == ("17", "yes")
    assert medium["now"].startswith("10 (1 1 1")
    assert rows["2D Hertz, 10 steps, fine mesh: <= 16"]["met"] == "no"
    assert rows["two cylinders (node-to-segment), 10 steps: <= 22, step 1 <= 4"]["met"] == "no"
    assert rows["two cylinders (mortar, shipped), 10 steps: <= 22, step 1 <= 4"]["met"] == "yes"
    cost = rows["cost of contact: time per step <= 1.3x the Dirichlet equivalent"]
    assert cost["met"] == "yes" and "1.26x" in cost["now"] and "1.39x" in cost["now"]
    assert rows["two bodies, 1e5 DOFs, 3D: iteration <= 1.3x one body, serially"]["met"] == "yes"
    assert rows["the same on 2 ranks"]["met"] == "no"
    share = rows["the same: search + transfer <= 10 % of an iteration"]
    assert share["met"] == "yes" and "3.9%" in share["now"] and "7.5%" in share["now"]
    speed = rows["the same: 2 ranks >= 1.7x faster than 1, same Newton counts"]
    assert speed["met"] == "yes" and speed["now"].startswith("2.00x")
    warm = rows["warm start of every shipped scene: <= 3 s"]
    assert warm["met"] == "yes" and "o_ring" in warm["now"]
    cold = rows["first start of the frictional 3D two-body scene: <= 0.5x"]
    assert cold["met"] == "not measured" and "--friction 0.3" in cold["now"]
    million = rows["inexact Newton, 1e6 DOFs on 2 ranks: <= 150 s, memory per rank"]
    assert million["met"] == "not measured" and "ladder3d.py --dofs 1e6" in million["now"]


def test_the_largest_inexact_record_counts_and_the_report_is_written(tmp_path: Path) -> None:
    median = {"inexact": {"ratio": 0.37, "total_s": 6.5, "newton_extra": 0,
                          "u_difference": 7e-12}}
    _write(tmp_path / "inexact_newton_1000_np1.json", {"median": {
        "inexact": {**median["inexact"], "ratio": 0.9}}})
    _write(tmp_path / "inexact_newton_100575_np1.json", {"median": median})
    _write(tmp_path / "ladder3d" / "inexact_985527_np2.json", {"median": {
        "total_s": 151.0, "u_dofs": 985527, "peak_rss_gb_max": 3.29}})
    targets.main(["--bench", str(tmp_path)])
    rows = {r["target"]: r for r in json.loads((tmp_path / "targets.json").read_text())["targets"]}
    inexact = rows["inexact Newton, 1e5 DOFs: <= 0.5x the time, Newton +1 at most, "
                   "answer to 1e-8"]
    assert inexact["met"] == "yes" and inexact["now"].startswith("0.37x")
    million = rows["inexact Newton, 1e6 DOFs on 2 ranks: <= 150 s, memory per rank"]
    assert million["met"] == "no" and "3.29 GB per rank" in million["now"]
    assert (tmp_path / "targets.md").read_text().startswith("| target | before | now | met? |")
