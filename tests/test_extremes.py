"""Every extreme of the stability grid ends with a status, finite outputs and the right answer.

The answers are references, not the run's own numbers: with the nodal rule the
discrete solution does not depend on r, and for a hyperelastic frictionless
contact the state at load factor 1 does not depend on the load path, so an
extreme of r or of the number of steps must give the contact force and the
displacement of plain GNRM at r = 1 E/h with 10 steps. A crash (status
``error``) fails every test that meets it, with its message.
"""

import json
import math
from dataclasses import replace

import pytest

from benchmarks.cases import bar_on_cradle
from benchmarks.robustness.stability_grid import full_grid
from fenics_contact.sweeps.stability import ERROR, StabilityCase, run_case, select

CASES = {c.name: c for c in full_grid()}


def finite(record):
    numbers = [v for v in record.row().values() if isinstance(v, float | int)]
    return all(math.isfinite(v) for v in numbers)


def run(name, method="auto", **options):
    record = run_case(CASES[name], method, **options)
    assert record.status != ERROR, f"{name} {method} crashed: {record.message}"
    assert finite(record), record
    return record


#: The reference of each extreme: GNRM at r = 1 on this case (r extremes: the
#: r = 1 case; step-count extremes: the 10-step case).
REFERENCE = {
    "bar-r1e-8": "bar-r1e0", "bar-r1e12": "bar-r1e0", "hertz-r1e12": "hertz-r1e0",
    "bar-steps1": "bar-r1e0", "bar-steps100": "bar-r1e0",
}
_references: dict = {}


def reference(name):
    key = REFERENCE.get(name, name)
    if key not in _references:
        record = run_case(replace(CASES[key], r=1.0), "gnrm")
        assert record.status == "converged", record
        _references[key] = record
    return _references[key]


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
    ref = reference(name)
    assert record.contact_force == pytest.approx(ref.contact_force, rel=1e-8)
    assert record.u_rms == pytest.approx(ref.u_rms, rel=1e-8)
    assert record.u_rms > 0.1 * record.max_abs_u  # a displacement field, not zeros


def test_reference_answers_are_the_known_ones():
    """Pin the references themselves, so that a change of all answers shows."""
    assert reference("bar-r1e0").contact_force == pytest.approx(119.025678295, rel=1e-8)
    # Hertz line contact on this mesh: P = 1.0642 against the analytic 1.064 (push 0.01)
    assert reference("hertz-r1e0").contact_force == pytest.approx(1.06422645717, rel=1e-8)


def test_forces_scale_with_E_and_the_stopping_test_with_them():
    """E = 1e-3 and 1e12: the same iterations, the same contact force per unit E."""
    low, high = run("bar-E1e-3"), run("bar-E1e12")
    assert low.status == high.status == "converged"
    assert low.iterations == high.iterations
    assert low.contact_force / low.E == pytest.approx(high.contact_force / high.E, rel=1e-9)
    # displacement loading: the same displacements, forces E / 210 times the E = 210 bar's
    ref = reference("bar-r1e0")
    assert high.u_rms == pytest.approx(ref.u_rms, rel=1e-8)
    assert high.contact_force / high.E == pytest.approx(ref.contact_force / ref.E, rel=1e-8)
    assert high.atol / low.atol == pytest.approx(1e15)


def test_initial_penetration_is_pushed_out():
    record = run("bar-penetrating")
    assert record.status == "converged" and record.max_penetration < 1e-12
    ref = reference("bar-penetrating")
    assert record.contact_force == pytest.approx(ref.contact_force, rel=1e-8)
    # pushed 0.02 further than the 10-step bar: a larger force, not the same one
    assert record.contact_force > 1.002 * reference("bar-r1e0").contact_force


def test_no_contact_and_full_contact():
    free = run("bar-no-contact", method="gnrm")
    assert free.status == "converged" and free.contact_force == 0.0
    assert free.max_penetration == 0.0 and free.u_rms > 0.0
    full = run("block-full-contact")
    scene = CASES["block-full-contact"].scene
    assert full.status == "converged"
    # homogeneous uniaxial plane-strain compression of a unit SVK block (stretch
    # l = 1 - delta, lateral faces free): first Piola stress E' l (l^2 - 1) / 2 with
    # E' = E / (1 - nu^2). 10.6875 here; E' delta = 11.54 and E delta = 10.5 both fail.
    stretch = 1.0 - 0.05  # the block's top is pushed down by delta = 0.05
    exact = scene.E / (1 - scene.nu**2) * stretch * (1 - stretch**2) / 2
    assert full.contact_force == pytest.approx(exact, rel=1e-9)


def test_failures_end_with_a_status_and_keep_completed_steps(tmp_path):
    stalled = run("bar-r1e-8", method="sua", max_iterations=20, out=tmp_path)
    assert stalled.status == "max_iterations"
    # simultaneous Uzawa at r = 10 (absolute): ~35 iterations a step until step 6 stalls
    case = StabilityCase("bar-sua", "r", bar_on_cradle(), r=10.0 / 210.0)
    cut = run_case(case, "sua", max_iterations=100, out=tmp_path)
    assert finite(cut)
    assert cut.status != "converged" and 0 < cut.steps_completed < cut.load_steps
    saved = json.loads((tmp_path / "cases" / "bar-sua__sua.json").read_text())
    assert saved["status"] == cut.status
    done = [s for s in saved["steps"] if s["status"] == "converged"]
    assert len(done) == cut.steps_completed and saved["steps"][-1]["status"] == cut.status
    # a scene file with nu = 0.5 is refused by its checks; one changed past them fails
    # when the model is built, and the run says so
    bad = replace(bar_on_cradle(), nu=0.5)
    broken = run_case(StabilityCase("bad-nu", "nu", bad), "auto")
    assert broken.status == ERROR and "nu" in broken.message and finite(broken)


def test_case_selection_by_name_and_group():
    assert {c.group for c in select(full_grid(), ["E"])} == {"E"}
    assert [c.name for c in select(full_grid(), ["bar-steps1"])] == ["bar-steps1"]
    with pytest.raises(ValueError, match="groups"):
        select(full_grid(), ["nonsense"])


STEEL_BLOCK = """
[scene]
name = "steel"
dimension = 2
[mesh]
generator = "rectangle"
size = [1.0, 0.5]
cells = [8, 4]
cell = "triangle"
[material]
law = "linear"
E = 2.1e11
nu = 0.3
[obstacle]
type = "plane"
point = [0.0, 0.0]
normal = [0.0, 1.0]
[contact]
tag = "bottom"
[[dirichlet]]
tag = "left"
value = [0.0, "free"]
[[dirichlet]]
tag = "top"
value = ["free", -0.01]
[solver]
steps = 2
"""


def test_a_scene_in_si_units_converges_with_the_default_tolerance(tmp_path):
    """Steel in Pa (E h^(d-1) = 2.6e10): atol left out follows the forces.

    An absolute 1e-8 lay below the round-off of forces of 1e9: the second
    step was refused as cycling at a residual of 1e-6. Uniaxial plane strain:
    the contact force is E / (1 - nu^2) times the strain 0.02 times the width.
    """
    from fenics_contact.runner import run_scene
    from fenics_contact.scene.schema import load_scene

    path = tmp_path / "steel.toml"
    path.write_text(STEEL_BLOCK)
    scene = load_scene(path)
    assert not scene.solver.atol_given and scene.solver.atol == 1e-8
    steps = run_scene(scene, tmp_path / "out", pictures=False).path.steps
    assert [s.status for s in steps] == ["converged", "converged"]
    exact = 2.1e11 / (1 - 0.3**2) * 0.02
    assert abs(steps[-1].contact_force - exact) <= 1e-8 * exact
    given = load_scene(_with_atol(path, 1e-3))
    assert given.solver.atol_given and given.solver.atol == 1e-3


def _with_atol(path, atol: float):
    text = path.read_text().replace("[solver]\n", f"[solver]\natol = {atol}\n")
    out = path.with_name("given.toml")
    out.write_text(text)
    return out


PRESSED_FROM_TOUCHING = """
[scene]
name = "pressed-from-touching"
dimension = 2
[mesh]
generator = "rectangle"
size = [2.0, 1.0]
cells = [8, 4]
[material]
law = "neo-hookean"
E = 210.0
nu = 0.3
[[dirichlet]]
tag = "left"
value = [0.0, "free"]
[[traction]]
tag = "top"
value = [0.0, -50.0]
[obstacle]
type = "plane"
point = [0.0, 0.0]
normal = [0.0, 1.0]
[contact]
tag = "bottom"
r = 1.0
[solver]
method = "penalty"
steps = 2
"""


@pytest.mark.parametrize("r", [1.0, 1e3])
def test_penalty_presses_a_body_that_starts_touching(tmp_path, r):
    """A block resting on the floor (gap 0), only a traction pressing it: the penalty
    tangent took the open branch at g = 0, so nothing held the block vertically and the
    first Newton step went to 1e16 ("diverged" at every cut-back). The floor carries the
    traction's resultant 50 x 2 exactly, whatever the penalty's own penetration."""
    from fenics_contact.runner import run_scene
    from fenics_contact.scene.schema import load_scene

    path = tmp_path / "touching.toml"
    path.write_text(PRESSED_FROM_TOUCHING.replace("r = 1.0", f"r = {r}"))
    steps = run_scene(load_scene(path), tmp_path / "out", pictures=False).path.steps
    assert [s.status for s in steps] == ["converged", "converged"]
    assert steps[-1].contact_force == pytest.approx(100.0, rel=1e-9)
    assert sum(s.iterations for s in steps) <= 12
