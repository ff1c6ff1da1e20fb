"""Every SCXML file fsmbt writes is valid SCXML (issue 26 item 5): state ids are NCNames, and the
file validates against the structural core of the W3C SCXML 1.0 schema
(tests/data/schema/scxml_core_subset.xsd, written from the Recommendation: its header says
which parts). The files are those the conversions write: BT -> FSM of every example tree and of
a seeded sample of the corpus Nav2 trees (explored states named ``q0:...`` in the model), and
SCXML -> SCXML translations of a corpus sample."""

from __future__ import annotations

import random
from pathlib import Path

import pytest
from lxml import etree

from fsmbt import api
from support.corpus import CORPUS

REPO = Path(__file__).resolve().parents[2]
SCHEMA = etree.XMLSchema(etree.parse(str(REPO / "tests/data/schema/scxml_core_subset.xsd")))
BT_EXAMPLES = sorted((REPO / "examples").glob("*_bt.xml"))


def _errors(path: Path) -> list[str]:
    """The schema's errors, then every ``target`` / ``initial`` token naming no id (the schema
    types them xs:IDREFS, but libxml2 does not resolve IDREFs when validating a schema)."""
    document = etree.parse(str(path))
    if not SCHEMA.validate(document):
        return [str(e) for e in SCHEMA.error_log]
    ids = {e.get("id") for e in document.iter() if e.get("id") is not None}
    return [
        f"line {e.sourceline}: {attr} names no state: {token}"
        for e in document.iter()
        for attr in ("target", "initial")
        for token in (e.get(attr) or "").split()
        if token not in ids
    ]


@pytest.mark.parametrize("source", BT_EXAMPLES, ids=lambda p: p.name)
def test_example_tree_written_as_scxml_is_valid(source: Path, tmp_path: Path) -> None:
    out = tmp_path / f"{source.stem}.scxml"
    assert api.convert_file(source, out).equivalent is True
    assert _errors(out) == []


def test_corpus_nav2_sample_written_as_scxml_is_valid(tmp_path: Path) -> None:
    trees = sorted((CORPUS / "bt" / "nav2").glob("*.xml"))
    if not trees:
        pytest.skip("corpus not available (set FSMBT_CORPUS)")
    sample = [t for t in random.Random(26).sample(trees, 4) if "routing" not in t.name]
    for source in sample:
        out = tmp_path / f"{source.stem}.scxml"
        assert api.convert_file(source, out).equivalent is True
        text = out.read_text(encoding="utf-8")
        assert _errors(out) == [], source.name
        assert 'id="q0:' not in text


def test_corpus_scxml_translated_is_valid(tmp_path: Path) -> None:
    machines = sorted((CORPUS / "fsm" / "scion_tests").glob("*.scxml"))
    if not machines:
        pytest.skip("corpus not available (set FSMBT_CORPUS)")
    for source in random.Random(26).sample(machines, 5):
        out = tmp_path / f"{source.stem}.out.scxml"
        api.write(api.load(source).model, out, "scxml")
        assert _errors(out) == [], source.name


def test_the_schema_refuses_a_colon_id_and_a_dangling_target(tmp_path: Path) -> None:
    """The check can fail: ``q0:X`` is not an NCName, a target must name an existing id."""
    colon = tmp_path / "colon.scxml"
    colon.write_text(
        '<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0"><state id="q0:X"/></scxml>',
        encoding="utf-8",
    )
    assert any("q0:X" in e for e in _errors(colon))
    dangling = tmp_path / "dangling.scxml"
    dangling.write_text(
        '<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0">'
        '<state id="a"><transition event="e" target="nowhere"/></state></scxml>',
        encoding="utf-8",
    )
    assert any("nowhere" in e for e in _errors(dangling))
