"""The documentation cannot drift from the code: every scene key is described, every page listed.

The scene reference (docs, generated) is ``KEYS`` (scene/reader.py) with the
descriptions of ``KEY_DOCS`` (scene/keys.py) and the spec dataclasses'
defaults; these checks run without Sphinx.
"""

import dataclasses
import re
from pathlib import Path

import pytest

from fenics_contact.scene import spec
from fenics_contact.scene.keys import KEY_DOCS, SECTIONS, KeyDoc
from fenics_contact.scene.reader import KEYS

ROOT = Path(__file__).parent.parent
DOCS = ROOT / "docs"


def drift(keys, key_docs, sections):
    """Every disagreement between accepted keys and their descriptions, as text."""
    found = []
    for section in sorted(set(keys) | set(key_docs) | set(sections)):
        accepted, described = set(keys.get(section, ())), set(key_docs.get(section, {}))
        if section not in keys:
            found.append(f"section {section!r} is described but the reader has no such section")
        if section not in sections:
            found.append(f"section {section!r} has no title")
        found += [f"[{section}] {k}: accepted, not described" for k in accepted - described]
        found += [f"[{section}] {k}: described, not accepted" for k in described - accepted]
    return sorted(found)


def test_every_accepted_key_is_described_and_every_description_accepted():
    assert drift(KEYS, KEY_DOCS, SECTIONS) == []


@pytest.mark.parametrize(("change", "message"), [
    (lambda k, d: k["solver"].add("max_time"), "[solver] max_time: accepted, not described"),
    (lambda k, d: d["output"].pop("pictures"), "[output] pictures: accepted, not described"),
    (lambda k, d: d["pair"].update(gap=d["pair"]["r"]), "[pair] gap: described, not accepted"),
    (lambda k, d: k.update(friction={"mu"}), "section 'friction' has no title"),
])
def test_the_check_finds_drift(change, message):
    """The check itself, on copies: a new key without a description is caught."""
    keys = {s: set(v) for s, v in KEYS.items()}
    docs = {s: dict(v) for s, v in KEY_DOCS.items()}
    change(keys, docs)
    assert message in drift(keys, docs, SECTIONS)


def test_choices_named_in_the_reference_are_the_codes():
    """The method and law lists of the reference are the registries'."""
    from fenics_contact.model.materials import MATERIALS

    assert all(f'"{m}"' in KEY_DOCS["solver"]["method"].type for m in spec.METHODS)
    for section in ("material", "body"):
        assert all(f'"{law}"' in KEY_DOCS[section]["law"].type for law in MATERIALS)


def every_doc():
    return [(s, k, d) for s, docs in KEY_DOCS.items() for k, d in docs.items()]


@pytest.mark.parametrize(("section", "key", "doc"), every_doc(),
                         ids=[f"{s or 'top'}.{k}" for s, k, _ in every_doc()])
def test_every_description_is_complete(section, key, doc):
    assert isinstance(doc, KeyDoc)
    assert doc.type and doc.meaning, "type and meaning are required"
    assert doc.default or doc.field, "a default: text, or the spec field that holds it"
    if doc.field:
        cls_name, attribute = doc.field.split(".")
        fields = {f.name: f for f in dataclasses.fields(getattr(spec, cls_name))}
        assert attribute in fields, f"{doc.field} is not a field of spec.{cls_name}"
        f = fields[attribute]
        assert (f.default is not dataclasses.MISSING
                or f.default_factory is not dataclasses.MISSING), f"{doc.field} has no default"


def test_the_generated_reference_lists_every_key():
    pytest.importorskip("sphinx")
    import sys

    sys.path.insert(0, str(DOCS / "_ext"))
    try:
        from scene_reference import coverage, markdown
    finally:
        sys.path.remove(str(DOCS / "_ext"))
    assert coverage() == []
    page = markdown()
    for section, (title, _) in SECTIONS.items():
        body = page.split(f"## {title}\n", 1)[1].split("\n## ", 1)[0]
        listed = set(re.findall(r"^\| `([^`]+)` \|", body, flags=re.M))
        assert listed == KEYS[section], title


def test_every_page_and_demo_is_in_the_site():
    """docs/index.md lists every docs/*.md page and every demo (else `make docs` fails)."""
    index = (DOCS / "index.md").read_text()
    listed = set(re.findall(r"^([\w/]+)$", index, flags=re.M))
    pages = {p.stem for p in DOCS.glob("*.md")} - {"index"}
    demos = {f"_generated/demos/{p.stem}" for p in (ROOT / "demos").glob("*.py")}
    assert pages | demos <= listed
