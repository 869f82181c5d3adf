"""The many-contacts group of the stability grid: GNRM and auto on two of its cases.

The stack of three blocks (the middle one touching two others) has the
exact answer E / (1 - nu^2) * strain at each of its three contacts; the
block on two blocks (one node on both) has GNRM's answer as the reference,
which auto must reach to 1e-8, contact by contact.
"""

import pytest

from mpi4py import MPI

from benchmarks.robustness.stability_grid import many_contacts_grid
from fenics_contact.sweeps.stability import run_case

CASES = {c.name: c for c in many_contacts_grid()}
EXACT = 200.0 / (1 - 0.3**2) * 0.01  # each interface of the stack


def forces(record):
    return {k: v["normal_force"] for k, v in record.steps[-1].contacts.items()}


def test_many_contacts_group_holds_the_shipped_scenes():
    assert {c.group for c in CASES.values()} == {"many-contacts"}
    assert {"stack-automatic", "junction", "junction-slide-off", "junction-slide-off-held",
            "tube-self-contact"} <= set(CASES)


@pytest.mark.parametrize("method", ["gnrm", "auto"])
def test_stack_gives_the_exact_force_at_every_contact(method):
    record = run_case(CASES["stack-automatic"], method, comm=MPI.COMM_SELF)
    assert record.status == "converged", record.message
    assert record.steps_completed == 2
    assert sorted(forces(record)) == ["floor", "middle-on-bottom", "top-on-middle"]
    for name, force in forces(record).items():
        assert force == pytest.approx(EXACT, rel=1e-9), name


def test_junction_auto_reaches_the_gnrm_answer():
    ref = run_case(CASES["junction"], "gnrm", comm=MPI.COMM_SELF)
    record = run_case(CASES["junction"], "auto", comm=MPI.COMM_SELF)
    assert ref.status == record.status == "converged"
    assert len(forces(ref)) == 5
    for name, force in forces(ref).items():
        assert forces(record)[name] == pytest.approx(force, rel=1e-8), name
    assert record.u_rms == pytest.approx(ref.u_rms, rel=1e-8)
    # r = 1e8 E/h: GNRM diverges there; auto reaches the r = 1 answer (10 Newton iterations)
    huge = run_case(CASES["junction-r1e8"], "auto", comm=MPI.COMM_SELF)
    assert huge.status == "converged", huge.message
    assert sum(s.iterations for s in huge.steps) <= 15
    for name, force in forces(ref).items():
        assert forces(huge)[name] == pytest.approx(force, rel=1e-8), name


def test_slide_off_converges_once_the_left_block_is_held():
    """The top block leaves the left block (that contact opens, the right one grows).

    With the left block's outer wall holding it vertically the problem is
    well posed at every step and GNRM passes all 10 (42 Newton iterations
    measured); without it (``junction-slide-off``) nothing holds the left
    block down once the top block has left, and the frictionless joint
    pushes it up: there is no static solution (docs/contacts.md).
    """
    record = run_case(CASES["junction-slide-off-held"], "gnrm", comm=MPI.COMM_SELF)
    assert record.status == "converged", record.message
    assert record.steps_completed == 10
    assert sum(s.iterations for s in record.steps) <= 50
    for step in record.steps[-2:]:
        off, on = step.contacts["top-on-left"], step.contacts["top-on-right"]
        assert off["active_count"] == 0 and off["normal_force"] == 0.0
        assert on["active_count"] > 0
        # the right block carries the top one: the joint's share of it is small
        right_floor = step.contacts["right-floor"]["normal_force"]
        assert right_floor == pytest.approx(on["normal_force"], rel=1e-3)
    auto = run_case(CASES["junction-slide-off-held"], "auto", comm=MPI.COMM_SELF)
    assert auto.status == "converged"
    for name, force in forces(record).items():
        assert forces(auto)[name] == pytest.approx(force, rel=1e-8, abs=1e-12), name
