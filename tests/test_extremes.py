"""Every extreme of the stability grid ends with a status and finite outputs."""

import json
import math

import pytest

from fenics_contact.studies.stability import (
    ERROR,
    StabilityCase,
    full_grid,
    run_case,
    select,
)
from fenics_contact.verification.bench_scenes import BarScene

CASES = {c.name: c for c in full_grid()}


def finite(record):
    numbers = [v for v in record.row().values() if isinstance(v, float | int)]
    return all(math.isfinite(v) for v in numbers)


def run(name, method="auto", **options):
    record = run_case(CASES[name], method, **options)
    assert finite(record), record
    return record


@pytest.mark.parametrize(
    "name",
    ["bar-r1e-8", "bar-r1e12", "hertz-r1e12", "bar-nu0", "bar-nu0.4999", "bar-steps1",
     "bar-steps100", "bar-grazing", "hertz-grazing", "bar-coarse-3x1", "bar-fine-48x16"],
)
def test_auto_converges_at_the_extreme(name):
    record = run(name)
    assert record.status == "converged", record
    assert record.steps_completed == record.load_steps
    assert record.max_penetration < 1e-9


def test_forces_scale_with_E_and_the_stopping_test_with_them():
    """E = 1e-3 and 1e12: the same iterations, the same contact force per unit E."""
    low, high = run("bar-E1e-3"), run("bar-E1e12")
    assert low.status == high.status == "converged"
    assert low.iterations == high.iterations
    assert low.contact_force / low.E == pytest.approx(high.contact_force / high.E, rel=1e-9)
    assert high.atol / low.atol == pytest.approx(1e15)


def test_initial_penetration_is_pushed_out():
    record = run("bar-penetrating")
    assert record.status == "converged" and record.max_penetration < 1e-12


def test_no_contact_and_full_contact():
    free = run("bar-no-contact", method="gnrm")
    assert free.status == "converged" and free.contact_force == 0.0
    full = run("block-full-contact")
    scene = CASES["block-full-contact"].scene
    assert full.status == "converged"
    # uniaxial compression of a unit block: force ~ E' delta (finite strain within 10 %)
    assert full.contact_force == pytest.approx(scene.E / (1 - scene.nu**2) * scene.delta, rel=0.1)


def test_failures_end_with_a_status_and_keep_completed_steps(tmp_path):
    stalled = run("bar-r1e-8", method="sua", max_iterations=20, out=tmp_path)
    assert stalled.status == "max_iterations"
    # simultaneous Uzawa at r = 10 (absolute): ~35 iterations a step until step 6 stalls
    case = StabilityCase("bar-sua", "r", BarScene(), r=10.0 / 210.0)
    cut = run_case(case, "sua", max_iterations=100, out=tmp_path)
    assert finite(cut)
    assert cut.status != "converged" and 0 < cut.steps_completed < cut.load_steps
    saved = json.loads((tmp_path / "cases" / "bar-sua__sua.json").read_text())
    assert saved["status"] == cut.status
    done = [s for s in saved["steps"] if s["status"] == "converged"]
    assert len(done) == cut.steps_completed and saved["steps"][-1]["status"] == cut.status
    broken = run_case(StabilityCase("bad-nu", "nu", BarScene(nu=0.5)), "auto")
    assert broken.status == ERROR and "nu" in broken.message and finite(broken)


def test_case_selection_by_name_and_group():
    assert {c.group for c in select(full_grid(), ["E"])} == {"E"}
    assert [c.name for c in select(full_grid(), ["bar-steps1"])] == ["bar-steps1"]
    with pytest.raises(ValueError, match="groups"):
        select(full_grid(), ["nonsense"])
