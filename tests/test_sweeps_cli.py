"""The tradeoff and stability commands on tiny grids: files and columns."""

import csv
import json

from fenics_contact.cli import main


def read_csv(path):
    with path.open() as f:
        return list(csv.DictReader(f))


def test_tradeoff_command_writes_json_csv_table_and_plot(tmp_path):
    code = main(["tradeoff", "--scene", "bar", "--methods", "gnrm,auto", "--r", "1,1e10",
                 "--meshes", "1", "--repeats", "1", "--out", str(tmp_path)])
    assert code == 0
    rows = read_csv(tmp_path / "tradeoff.csv")
    columns = {"scene", "mesh", "displacement_dofs", "method", "r_relative", "status", "iterations",
               "linear_solves", "wall_s", "repeats", "max_penetration", "u_error", "p0_error",
               "pareto_u"}
    assert columns <= set(rows[0])
    assert len(rows) == 4
    status = {(r["method"], float(r["r_relative"])): r["status"] for r in rows}
    assert status[("auto", 1e10)] == "converged" and status[("gnrm", 1e10)] != "converged"
    assert any(r["pareto_u"] == "True" for r in rows)
    assert len(json.loads((tmp_path / "tradeoff.json").read_text())) == 4
    assert "| bar | 6x2 | Auto |" in (tmp_path / "table.md").read_text()
    assert (tmp_path / "tradeoff.png").stat().st_size > 10_000


def test_stability_command_writes_csv_plot_and_step_records(tmp_path):
    code = main(["stability", "--cases", "bar-r1e12,bar-no-contact", "--methods", "gnrm,auto",
                 "--out", str(tmp_path)])
    assert code == 0
    rows = read_csv(tmp_path / "stability.csv")
    columns = {"case", "group", "method", "status", "iterations", "steps_completed",
               "max_penetration", "contact_force", "max_abs_u", "atol", "switches"}
    assert columns <= set(rows[0])
    status = {(r["case"], r["method"]): r["status"] for r in rows}
    assert status == {
        ("bar-r1e12", "gnrm"): "diverged", ("bar-r1e12", "auto"): "converged",
        ("bar-no-contact", "gnrm"): "converged", ("bar-no-contact", "auto"): "converged",
    }
    assert all("nan" not in v.lower() and "inf" not in v.lower()
               for r in rows for v in r.values())
    assert (tmp_path / "stability.png").stat().st_size > 5_000
    assert len(list((tmp_path / "cases").glob("*.json"))) == 4
