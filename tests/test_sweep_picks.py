"""What the sweeps name from their records: picks, outcomes, labels (no solve).

The records here carry the numbers a user's trade-off and stability sweeps
measured on a ball pressed into an 8 x 4 block (``blk_ball``) and on the
same scene grazing (``graze_small``, r = 1e10 E/h).
"""

import math

import matplotlib.pyplot as plt
import pytest

from fenics_contact.solvers.stepping import (
    RAISE_TOLERANCE,
    RunRecord,
    StepRecord,
    name_tolerance,
)
from fenics_contact.sweeps.stability import OFF_REFERENCE, CaseRecord, loose_tolerances
from fenics_contact.sweeps.study import paper_table
from fenics_contact.sweeps.sweep_plots import (
    STATUS_COLOURS,
    stability_figure,
    time_label,
    tradeoff_figure,
)
from fenics_contact.sweeps.tradeoff import (
    TradeoffRecord,
    fastest,
    mark_pareto,
    markdown_table,
    most_accurate,
)


def point(method: str, r: float, error: float, wall_s: float, r_working: float | None = None,
          repeats: int = 1) -> TradeoffRecord:
    return TradeoffRecord(status="converged", method=method, r_relative=r, error=error,
                          wall_s=wall_s, scene="blkball", mesh="8x4", repeats=repeats,
                          r_working=r if r_working is None else r_working)


#: GNRM on 8 x 4 (u error against the reference, wall time).
GNRM = [point("gnrm", 1e-4, 2.4e-13, 0.0337), point("gnrm", 1e-2, 2.0e-15, 0.0327),
        point("gnrm", 1.0, 4.6e-16, 0.0370), point("gnrm", 1e2, 1.3e-15, 0.0336),
        point("gnrm", 1e4, 1.9e-15, 0.0450)]
NUA = [point("nua", 1.0, 6.7e-11, 0.206), point("nua", 1e2, 9.6e-13, 0.0837),
       point("nua", 1e4, 5.3e-15, 0.0604)]
#: auto works at r clamped to [1e-2, 1] E/h: at 1 E/h for every r >= 1 (the reference's r).
AUTO = [point("auto", 1e-4, 2.0e-15, 0.0380, 1e-2), point("auto", 1e-2, 2.0e-15, 0.0296),
        point("auto", 1.0, 4.6e-16, 0.0294), point("auto", 1e2, 0.0, 0.0356, 1.0),
        point("auto", 1e4, 4.3e-16, 0.0354, 1.0)]


def test_most_accurate_names_every_point_at_round_off_and_skips_the_reference():
    """Before: GNRM "0.0001, 2.4e-13" (the worst), NUA "100, 9.6e-13", auto r = 1."""
    assert most_accurate(GNRM) == ("r = 0.01, 100, 10000 reach the reference to round-off "
                                   "(u error <= 2.0e-15)")
    assert most_accurate(NUA) == "10000, 5.3e-15"
    # auto at r >= 1 works at 1 E/h: the reference's own run, left out
    assert most_accurate(AUTO) == ("r = 0.0001, 0.01 reach the reference to round-off "
                                   "(u error <= 2.0e-15)")
    assert fastest(AUTO).startswith("0.01, 0.030, ")  # not auto at r = 1 (0.029 s)
    only = [GNRM[2]]
    assert most_accurate(only) == "1, 4.6e-16 (the reference's own path)"
    assert fastest(only).endswith("(the reference's own path)")


def test_the_table_and_the_front_follow_the_same_rule():
    records = [*GNRM, *NUA, *AUTO]
    mark_pareto(records)
    table = markdown_table(records)
    gnrm = next(line for line in table.splitlines() if "| GNRM |" in line)
    assert "r = 0.01, 100, 10000 reach the reference to round-off" in gnrm
    # the front: the reference's own run is not on it; at round-off only time counts
    front = {(r.method, r.r_relative) for r in records if r.pareto_u}
    assert front == {("auto", 1e-2)}


def test_the_trade_off_picture_says_median_only_for_repeats_and_marks_errors_drawn_at_the_floor():
    assert time_label(AUTO) == "wall time, whole load path (s)"
    three = [point("gnrm", 1e-2, 2e-15, 0.03, repeats=3)]
    assert time_label(three) == "wall time, whole load path (s, median of 3 runs)"
    fig = tradeoff_figure([*GNRM, *AUTO])  # auto at r = 100: error 0
    (ax,) = fig.axes
    assert ax.get_xlabel() == "wall time, whole load path (s)"
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "error < 1e-15 (0 too), drawn at 1e-15" in labels
    plt.close(fig)
    fig = tradeoff_figure(NUA)  # no error below the floor: no such entry
    assert not any("drawn at" in t.get_text() for t in fig.axes[0].get_legend().get_texts())
    plt.close(fig)


def case(method: str, force: float, deviation: float | None, atol: float = 0.0544,
         reference_force: float = 0.058541) -> CaseRecord:
    step = StepRecord(step=1, load_factor=1.0, status="converged", contact_force=force)
    return CaseRecord(status="converged", steps=[step], method=method, case="graze-r1e+10",
                      atol=atol, reference="gnrm r=1", reference_deviation=deviation,
                      reference_force=reference_force)


def test_a_converged_run_off_the_reference_is_shown_so_with_its_deviation():
    """graze_small at r = 1e10 E/h: atol 0.0544 against N = 0.0585; penalty 1.38 % off."""
    off, on = case("penalty", 0.05773, 0.0138), case("auto", 0.058541, 1e-15)
    assert off.outcome == OFF_REFERENCE and on.outcome == "converged"
    assert off.row()["outcome"] == "converged, off the reference by 1.4e-02"
    assert on.row()["outcome"] == "converged"
    fig = stability_figure([off, on])
    ax = fig.axes[0]
    texts = {t.get_text() for t in ax.texts}
    assert texts == {"0 off 1e-02", "0"}
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert OFF_REFERENCE in legend
    assert STATUS_COLOURS[OFF_REFERENCE] != STATUS_COLOURS["converged"]
    plt.close(fig)
    assert off.row()["atol_share"] == pytest.approx(0.0544 / 0.058541)
    (line,) = loose_tolerances([off, on])
    assert line == "graze-r1e+10: atol = 0.0544 is 93 % of the reference's contact force 0.0585"
    assert loose_tolerances([case("gnrm", 1.0, 0.0, atol=2.5e-8, reference_force=86.3)]) == []


def test_the_stability_row_has_the_terms_of_ft_ratio():
    step = StepRecord(step=1, load_factor=1.0, status="converged", contacts={
        "wall": {"normal_force": 2.0, "tangential_force": 0.35, "tangential_magnitude": 0.4},
        "floor": {"normal_force": 5.0, "tangential_force": 0.0, "tangential_magnitude": 0.0}})
    rec = CaseRecord(status="converged", steps=[step], mus={"wall": 0.2})
    row = rec.row()
    assert row["tangential_magnitude"] == pytest.approx(0.4)
    assert row["mu_normal_force"] == pytest.approx(0.4)
    assert row["ft_ratio"] == pytest.approx(row["tangential_magnitude"] / row["mu_normal_force"])
    assert CaseRecord(status="converged", steps=[step]).row()["tangential_magnitude"] is None


def test_a_stall_note_names_the_front_end_setting_once():
    message = ("cycling at load factor 1 after 1 attempt, no cut-back; the residual stalls at "
               f"3e-05, ..., above atol = 1e-08; {RAISE_TOLERANCE} 5e-06")
    record = RunRecord(status="cycling", message=f"load step 1: {message}",
                       steps=[StepRecord(step=1, load_factor=0.0, status="cycling",
                                         message=message)])
    name_tolerance(record, "study's --tol")
    name_tolerance(record, "study's --tol")
    assert record.message.endswith(f"{RAISE_TOLERANCE} 5e-06 (study's --tol)")
    assert record.steps[0].message.endswith("(study's --tol)")
    assert "[solver]" not in record.message and "scene" not in record.message


def test_a_relative_study_table_says_its_r_is_relative():
    rec = RunRecord(status="converged", method="gnrm", r_absolute=4e-3, r_relative=1e-6)
    assert paper_table([rec], relative=True).splitlines()[0] == "| Method | r = 1e-06 E/h |"
    assert paper_table([rec]).splitlines()[0] == "| Method | r = 0.004 |"
    assert math.isnan(rec.error)
