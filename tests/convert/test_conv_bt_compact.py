"""BT -> FSM, compact (issue 24): memory as SCXML data, one state per leaf, proven equivalent
through the W3C expansion of the data model (docs/conversion.md, "Compact conversion")."""

from __future__ import annotations

import random
from pathlib import Path

import pytest
from lxml import etree

from fsmbt import api
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.formats import dumps, loads
from fsmbt.generate import random_bt
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import FsmbtError, UnsupportedError
from fsmbt.model.flatten import flatten
from fsmbt.model.fsm import FSM
from fsmbt.model.fsm_data import ASSIGN, COND, DATAMODEL, has_data
from support.conv_helpers import check
from support.corpus import CORPUS, profile_options
from support.random_trees import random_tree

NAV2 = CORPUS / "bt" / "nav2"
NAV2_DEFAULT = NAV2 / "navigate_to_pose_w_replanning_and_recovery.xml"
SCXML_STATES = {f"{{http://www.w3.org/2005/07/scxml}}{t}" for t in ("state", "parallel", "final")}


def elements(fsm: FSM) -> int:
    """``<state>`` + ``<parallel>`` + ``<final>`` elements of the SCXML written."""
    root = etree.fromstring(dumps(fsm, "scxml").encode())
    return sum(1 for e in root.iter() if e.tag in SCXML_STATES)


def nodes(doc: BTDocument) -> int:
    count, stack = 0, [doc.main.root]
    while stack:
        node = stack.pop()
        count += 1
        stack.extend(node.children)
        if node.type == "SubTree" and node.attrs.get("ID") in doc.trees:
            stack.append(doc.trees[node.attrs["ID"]].root)
    return count


def nav2_default() -> BTDocument:
    if not NAV2_DEFAULT.exists():
        pytest.skip(f"corpus not found at {CORPUS} (set FSMBT_CORPUS)")
    doc = api.load(NAV2_DEFAULT, options=profile_options(NAV2_DEFAULT)).model
    assert isinstance(doc, BTDocument)
    return doc


def test_nav2_default_tree_is_small_keeps_data_and_is_proven() -> None:
    doc = nav2_default()
    compact = bt_to_hfsm(doc)
    unrolled = bt_to_hfsm(doc, unroll=True)
    size = elements(compact.model)
    assert size < 200 and size <= 4 * nodes(doc) + 10
    assert elements(unrolled.model) > 10 * size  # the product it replaces
    assert has_data(compact.model) and not has_data(unrolled.model)
    assert compact.stats["data_variables"] >= 3 and compact.stats["guarded_transitions"] > 0
    names = compact.model.attrs[DATAMODEL]
    assert "NavigateRecovery_retry_count" in names  # the root RecoveryNode's counter
    report = api.verify_models(doc, compact.model)
    assert report.equivalent, report.to_dict()
    assert "W3C" in report.stats["data_model"]


def test_compact_scxml_reads_back_as_its_proven_meaning() -> None:
    """The SCXML written reads back into the same model (written again byte for byte), and its
    flat meaning - the W3C reading of the data model - is the machine the checker proved:
    equivalent to the BT and to the unrolled conversion."""
    doc = nav2_default()
    text = dumps(bt_to_hfsm(doc).model, "scxml")
    assert "<datamodel>" in text and "<assign" in text and "cond=" in text
    back = loads(text, "scxml")
    assert has_data(back) and back.is_hierarchical and dumps(back, "scxml") == text
    flat = flatten(back)
    assert not has_data(flat) and not flat.is_hierarchical
    assert check(doc, flat).equivalent
    assert api.verify_models(bt_to_hfsm(doc, unroll=True).model, flat).equivalent


def test_corpus_and_generated_trees_within_the_bound_and_proven() -> None:
    """Every corpus BT of a sample (seeded, small regions) and seeded extended trees: at most
    4 * nodes + 10 state elements, and the checker proves each equivalent."""
    rng = random.Random(24)
    docs: list[tuple[str, BTDocument]] = []
    folder = CORPUS / "bt"
    if folder.exists():
        paths = [
            p
            for p in sorted(folder.rglob("*.xml"))
            if "models" not in p.parts and not any(q.startswith("_") for q in p.parts)
        ]
        for path in rng.sample(paths, min(25, len(paths))):
            try:
                doc = api.load(path, options=profile_options(path)).model
            except FsmbtError:
                continue
            if isinstance(doc, BTDocument):
                docs.append((path.name, doc))
    for index in range(30):
        docs.append(
            (f"gen{index}", random_bt(seed=2400 + index, depth=3, breadth=3, extended=True))
        )
    proven = {"corpus": 0, "generated": 0}
    for label, doc in docs:
        try:
            result = bt_to_hfsm(doc, max_states=4000)
        except FsmbtError:
            continue  # refused today as well (time, blackboard, size): not this issue's
        assert elements(result.model) <= 4 * nodes(doc) + 10, label
        report = check(doc, result.model)
        assert report.equivalent, (label, report.to_dict())
        proven["generated" if label.startswith("gen") else "corpus"] += 1
    # without the corpus beside the checkout (a bare clone) only the generated part counts
    assert proven["generated"] >= 25, proven
    assert not folder.exists() or proven["corpus"] >= 15, proven


def test_plain_trees_are_the_papers_hfsm_unchanged() -> None:
    """On plain Sequence/Fallback trees nothing keeps memory: the compact form is the paper's
    HFSM, state for state and transition for transition."""
    rng = random.Random(7)
    sizes = []
    for _ in range(40):
        doc = random_tree(
            rng,
            controls=("Sequence", "Fallback"),
            decorators=("Inverter",),
            leaves=("Action", "Condition"),
        )
        compact = bt_to_hfsm(doc).model
        assert compact == bt_to_hfsm(doc, unroll=True).model and not has_data(compact)
        sizes.append(sum(1 for _ in compact.walk()))
    assert max(sizes) >= 8


def test_a_wrong_update_is_caught_by_the_checker() -> None:
    """The proof reads the data: a counter that counts by two makes the result NOT
    equivalent."""
    doc = nav2_default()
    hfsm = bt_to_hfsm(doc).model
    changed = 0
    for machine in hfsm.machines():
        for t in machine.transitions:
            if "retry_count + 1" in t.attrs.get(ASSIGN, ""):
                t.attrs[ASSIGN] = t.attrs[ASSIGN].replace("retry_count + 1", "retry_count + 2")
                changed += 1
    assert changed
    assert not api.verify_models(doc, hfsm).equivalent


def test_a_dropped_guard_is_caught_by_the_checker() -> None:
    doc = nav2_default()
    hfsm = bt_to_hfsm(doc).model
    guarded = [t for m in hfsm.machines() for t in m.transitions if COND in t.attrs and t.event]
    assert guarded
    del guarded[0].attrs[COND]  # the first transition now always fires
    assert not api.verify_models(doc, hfsm).equivalent


def test_formats_without_a_data_model_refuse_and_json_keeps_it() -> None:
    doc = nav2_default()
    hfsm = bt_to_hfsm(doc).model
    with pytest.raises(UnsupportedError, match="no data model.*--unroll"):
        dumps(hfsm, "paper-text")
    back = loads(dumps(hfsm, "json"), "json")
    assert has_data(back)
    assert api.verify_models(doc, back).equivalent


def test_render_pages_one_level_per_picture_within_4096(tmp_path) -> None:  # noqa: ANN001
    """``fsmbt render --pages``: the top machine (the region closed into a box) and the
    region's own machine, each at most 4096 x 4096 pixels, guards on the arrows."""
    import struct

    from fsmbt.render import render_pages
    from fsmbt.render.fsm_graph import fsm_to_dot

    hfsm = bt_to_hfsm(nav2_default()).model
    pages = render_pages(hfsm, tmp_path / "pages", fmt="png")
    assert [p.name for p in pages] == ["top.png", "NavigateRecovery.png"]
    for page in pages:
        width, height = struct.unpack(">II", page.read_bytes()[16:24])
        assert 0 < width <= 4096 and 0 < height <= 4096
    region = fsm_to_dot(hfsm, level=0, composite="NavigateRecovery")
    assert "NavigateRecovery_retry_count" in region  # the legend
    assert "failure [v" in region and ":= v" in region  # a guard and an update on arrows
    top = fsm_to_dot(hfsm, level=0)
    assert "ProgressCheckerSelector" not in top  # the region is a closed box there


def test_cli_convert_compact_unroll_and_pages(tmp_path, capsys) -> None:  # noqa: ANN001
    """``fsmbt convert`` writes the data model by default and says what the proof checked (a
    format without a data model: the exact expansion, named as a loss);
    ``--unroll`` writes the product; ``fsmbt render --pages`` draws one picture per level."""
    from fsmbt.cli import main

    example = Path(__file__).resolve().parents[2] / "examples" / "game_npc_bt.xml"
    compact, unrolled = tmp_path / "npc.scxml", tmp_path / "npc_unrolled.scxml"
    assert main(["convert", str(example), "-o", str(compact)]) == 0
    shown = capsys.readouterr()
    assert "checked through the data model" in shown.out + shown.err
    assert main(["convert", str(example), "-o", str(unrolled), "--unroll"]) == 0
    capsys.readouterr()
    assert "<datamodel>" in compact.read_text() and "<datamodel>" not in unrolled.read_text()
    small, big = (elements(loads(p.read_text(), "scxml")) for p in (compact, unrolled))
    assert small < big
    assert main(["render", str(compact), "--pages", str(tmp_path / "pages")]) == 0
    assert (tmp_path / "pages" / "top.svg").exists()
    assert len(list((tmp_path / "pages").glob("*.svg"))) >= 2
    # a format without a data model gets the proven machine's exact expansion, named
    assert main(["convert", str(example), "-o", str(tmp_path / "npc.txt")]) == 0
    shown = capsys.readouterr()
    assert "paper-text has no data model: the 11 variable(s)" in shown.out + shown.err
    flat = loads((tmp_path / "npc.txt").read_text(), "paper-text")
    assert isinstance(flat, FSM) and not has_data(flat)
    assert api.verify_models(api.load(example).model, flat).equivalent
