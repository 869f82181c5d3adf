"""The site's generated pages: every demo and every benchmark family has its page."""

import json
import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
INDEX = (DOCS / "index.md").read_text()


@pytest.fixture(scope="module")
def extension():
    """docs/_ext's validation page generator (imported as Sphinx imports it)."""
    pytest.importorskip("sphinx")  # the docs extra
    sys.path.insert(0, str(DOCS / "_ext"))
    try:
        import validation_pages
    finally:
        sys.path.remove(str(DOCS / "_ext"))
    return validation_pages


@pytest.mark.parametrize("demo", sorted(p.stem for p in (ROOT / "demos").glob("*.py")))
def test_every_demo_is_in_the_index_and_on_the_demos_page(demo):
    assert f"_generated/demos/{demo}\n" in INDEX
    assert f"`{demo}.py`" in (DOCS / "demos.md").read_text()


def test_every_benchmark_json_has_a_family_and_a_page(extension):
    committed = {p.stem for p in (DOCS / "data").glob("*.json")}
    assert committed == set(extension.FAMILIES)
    for name in committed:
        assert f"_generated/validation/{name}\n" in INDEX
        assert (ROOT / "benchmarks" / "validation" / f"{name}.py").exists()


@pytest.mark.parametrize("name", sorted(p.stem for p in (DOCS / "data").glob("*.json")))
def test_a_validation_page_holds_every_record_and_a_figure(extension, name):
    family = extension.FAMILIES[name]
    data = json.loads((DOCS / "data" / f"{name}.json").read_text())
    text = extension.page(name, family, data, ROOT)
    header, rows = family.table(data)
    table = [line for line in text.splitlines() if line.startswith("|")]
    assert len(table) == 2 + len(rows) and rows
    assert all(len(re.split(r"(?<!\\)\|", line)) == len(header) + 2 for line in table)
    assert f"![{family.title}]({name}.png)" in text
    assert data["machine"]["date"] in text
    figure = family.figure(data)
    assert figure.axes and all(ax.lines or ax.collections for ax in figure.axes)
