"""The paper tables' deterministic iteration counts, as the README lists them.

Each cell is what ``python benchmarks/research/study.py paper-ex1`` /
``paper-ex2`` (``make paper-tables``) prints
(absolute r, tolerance 1e-8, at most 500 iterations a load step, no cut-back).
The counts are deterministic (direct solver, fixed meshes), so they are
asserted exactly: a change in the stopping test, the residual measure, the
Jacobian or the update order shows up here. The expensive Uzawa cells
(hundreds of iterations at r = 1 and 10) are left to the study command.
"""

import math

import pytest

from benchmarks.cases import bar_on_cradle, wedge_on_corner
from benchmarks.research.paper_ex1 import exact_corner
from fenics_contact.sweeps.study import paper_table, run_study

R = [1.0, 10.0, 100.0, 1000.0, 10000.0]

# (method, r): (status, Newton iterations, multiplier updates)
TABLE_1 = {
    **{("penalty", r): ("converged", n, 0) for r, n in zip(R, [2, 3, 3, 4, 4], strict=True)},
    **{("gnrm", r): ("converged", 2, 0) for r in R},
    ("sua", 100.0): ("converged", 39, 39),
    ("sua", 1000.0): ("converged", 13, 13),
    ("sua", 10000.0): ("converged", 8, 8),
    ("nua", 100.0): ("converged", 59, 38),
    ("nua", 1000.0): ("converged", 17, 10),
    ("nua", 10000.0): ("converged", 9, 5),
}

TABLE_2 = {
    **{("penalty", r): ("converged", n, 0) for r, n in zip(R, [31, 33, 34, 40, 42], strict=True)},
    **{("gnrm", r): ("converged", n, 0) for r, n in zip(R, [40, 40, 40, 40, 42], strict=True)},
    ("nua", 1000.0): ("converged", 112, 74),
    ("nua", 10000.0): ("converged", 77, 42),
    ("sua", 100.0): ("cycling", None, None),
}


def run_cells(case, cells, exact=None):
    records = []
    for method in dict.fromkeys(m for m, _ in cells):
        rs = [r for m, r in cells if m == method]
        records += run_study(case, [method], rs, exact=exact)
    return {(rec.method, rec.r): rec for rec in records}


def check(records, table):
    for key, (status, iterations, updates) in table.items():
        rec = records[key]
        got = (rec.status, rec.iterations, rec.updates)
        want = (status, iterations if iterations is not None else rec.iterations,
                updates if updates is not None else rec.updates)
        assert got == want, f"{key}: {got} != {want}"


def test_table_1_example_1():
    records = run_cells(wedge_on_corner(), TABLE_1, exact_corner(-0.5))
    check(records, TABLE_1)
    # GNRM and the Uzawa schemes give the exact corner displacement, the penalty
    # method's error shrinks with r (README: -0.0004 ... -0.473 against -0.5)
    assert all(records[("gnrm", r)].error < 1e-8 for r in R)
    assert records[("nua", 1000.0)].error < 1e-6
    penalty = [records[("penalty", r)].error for r in R]
    assert penalty == sorted(penalty, reverse=True) and penalty[0] > 0.99
    table = paper_table(list(records.values()))
    assert "| GNRM | 2 | 2 | 2 | 2 | 2 |" in table
    assert "| Penalty | 2 | 3 | 3 | 4 | 4 |" in table


def test_table_2_example_2():
    records = run_cells(bar_on_cradle(), TABLE_2)
    check(records, TABLE_2)
    # README: penalty relative L2 error 1.0, 0.64, 0.26, 0.039, 0.004 for r = 1 ... 1e4
    errors = [records[("penalty", r)].error for r in R]
    for got, want in zip(errors, [1.0, 0.64, 0.26, 0.039, 0.004], strict=True):
        assert got == pytest.approx(want, rel=0.06, abs=0.0)
    assert all(math.isfinite(records[("gnrm", r)].error) for r in R)
    assert max(records[("gnrm", r)].error for r in R) < 1e-8
