"""Folds opened through the API (issue 29, item 6; docs/web.md 'Big models'): a folded BT
subtree's box (``fold@PATH``) and a closed composite state's box (class ``fold``, ``s@PATH``)
are drawn alone by ``POST /api/picture``, with the same anchors the full picture would give
them, and the cache keeps each opened picture under its own key."""

from __future__ import annotations

import re

import pytest
from fastapi.testclient import TestClient

from fsmbt.formats import dumps
from fsmbt.generate.generator import random_bt
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.render.anchor_ids import child_path
from fsmbt.web import WebSettings, create_app
from fsmbt.web.answers import request_key
from support.web_models import hierarchical_scxml, nested_scxml

FOLD_IDS = re.compile(r'<g id="(fold@[^"]*)" class="node fold"')
NODE_IDS = re.compile(r'<g id="n@([^"]*)" class="node')
STATE_IDS = re.compile(r'<g id="s@([^"]*)" class="(node|cluster)')
CLOSED_IDS = re.compile(r'<g id="s@([^"]*)" class="node fold"')


@pytest.fixture(scope="module")
def client():
    with TestClient(create_app(WebSettings.default(workers=1))) as test_client:
        yield test_client


@pytest.fixture(scope="module")
def big_bt() -> tuple[BTDocument, str]:
    doc = random_bt(1, depth=10, breadth=10, max_nodes=1000)
    return doc, dumps(doc, "btcpp")


def _subtree_paths(doc: BTDocument, path: str) -> set[str]:
    """Every child-index path under the node at ``path`` (itself included); a single-tree
    document, so paths are plain child indices."""
    node: BTNode | None = doc.main.root
    assert node is not None
    for part in path.split("/") if path else []:
        node = node.children[int(part)]
    found: set[str] = set()
    stack = [(node, path)]
    while stack:
        current, where = stack.pop()
        found.add(where or "root")
        stack.extend((c, child_path(where, i)) for i, c in enumerate(current.children))
    return found


def test_a_fold_box_opens_to_its_subtree_with_full_paths(client, big_bt):
    doc, text = big_bt
    whole = client.post("/api/picture", json={"text": text}).json()
    folds = FOLD_IDS.findall(whole["svg"])
    assert folds, "the premise: the 1000-node tree is folded"
    # the biggest fold: open it, then open a fold inside it, until a subtree fits whole
    path = max(folds, key=lambda f: len(_subtree_paths(doc, f.removeprefix("fold@"))))
    path = path.removeprefix("fold@")
    for _ in range(6):
        answer = client.post("/api/picture", json={"text": text, "focus": path})
        assert answer.status_code == 200, answer.text
        data = answer.json()
        assert data["focus"] == path and data["kind"] == "bt" and data["error"] is None
        drawn = set(NODE_IDS.findall(data["svg"]))
        under = _subtree_paths(doc, path)
        assert path in drawn  # the opened node is the top of the picture
        assert drawn <= under  # nothing outside the subtree, anchors keep their full paths
        inner = FOLD_IDS.findall(data["svg"])
        if not inner:
            assert drawn == under  # small enough: every node of the subtree drawn
            return
        assert all(f.removeprefix("fold@") in under for f in inner)
        path = inner[0].removeprefix("fold@")
    raise AssertionError("no subtree small enough to draw whole")


def test_a_closed_composite_state_opens_to_its_states(client):
    text = hierarchical_scxml(groups=8, inner=10)
    whole = client.post("/api/picture", json={"text": text, "filename": "h.scxml"}).json()
    closed = CLOSED_IDS.findall(whole["svg"])
    assert closed == [f"G{g}" for g in range(8)]  # too many states: every composite closed
    data = client.post(
        "/api/picture", json={"text": text, "filename": "h.scxml", "composite": "G3"}
    ).json()
    assert data["composite"] == "G3" and data["kind"] == "fsm"
    states = {anchor for anchor, _ in STATE_IDS.findall(data["svg"])}
    assert states == {f"G3/G3_{i}" for i in range(10)}


def test_a_composite_opened_inside_an_opened_composite_keeps_full_paths(client):
    text = nested_scxml(outer=3, groups=8, inner=10)

    def closed(composite: str | None) -> list[str]:
        body = {"text": text, "filename": "n.scxml", "composite": composite}
        return CLOSED_IDS.findall(client.post("/api/picture", json=body).json()["svg"])

    assert closed("O1") == [f"O1/O1G{g}" for g in range(8)]
    data = client.post(
        "/api/picture", json={"text": text, "filename": "n.scxml", "composite": "O1/O1G2"}
    ).json()
    states = {anchor for anchor, _ in STATE_IDS.findall(data["svg"])}
    assert states == {f"O1/O1G2/O1G2_{i}" for i in range(10)}


def test_wrong_openings_are_located_json_errors(client, big_bt):
    _, text = big_bt
    fsm = hierarchical_scxml(groups=2, inner=2)
    for body, word in (
        ({"text": text, "focus": "9/9/9"}, "no node"),
        ({"text": text, "composite": "A"}, "behavior tree"),
        ({"text": fsm, "filename": "h.scxml", "focus": "0"}, "FSM"),
        ({"text": fsm, "filename": "h.scxml", "composite": "Nope"}, "no composite state"),
        ({"text": text, "focus": "0", "composite": "A"}, "one fold at a time"),
    ):
        answer = client.post("/api/picture", json=body)
        assert answer.status_code == 400, (body.get("focus"), answer.text)
        error = answer.json()
        assert set(error) == {"error", "where"} and word in error["error"], error


def test_the_cache_keeps_each_opening_apart(client, big_bt):
    _, text = big_bt
    keys = {
        request_key("picture.json", {"text": text, "focus": focus})
        for focus in (None, "0", "0/1", "1")
    }
    assert len(keys) == 4
    cache = client.app.state.cache
    first = client.post("/api/picture", json={"text": text, "focus": "0"}).json()
    misses = cache.misses
    second = client.post("/api/picture", json={"text": text, "focus": "1"}).json()
    assert cache.misses == misses + 1  # another opening: drawn, not served from the cache
    assert second["svg"] != first["svg"]
    hits = cache.hits
    again = client.post("/api/picture", json={"text": text, "focus": "0"}).json()
    assert cache.hits == hits + 1 and again == first
