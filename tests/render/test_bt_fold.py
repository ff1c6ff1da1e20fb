"""Big behavior trees drawn to be read at 100 % (issue 29): folded subtrees say how many nodes
they hide and how to draw them, wide levels wrap into rows, ``depth`` / ``focus`` choose what to
show, and the default PNG of a 1 000-node tree fits 4 096 x 4 096 pixels with aspect <= 4 without
being scaled down."""

from __future__ import annotations

import re
import shutil
import struct
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.cli import main
from fsmbt.formats import dumps
from fsmbt.generate import random_bt
from fsmbt.model import BTDocument, BTNode, NodeKind
from fsmbt.model.errors import InputError
from fsmbt.render import bt_to_dot, model_to_dot, picture_dot, render_model
from fsmbt.render.bt_fold import TOP_CHILDREN, walk
from fsmbt.render.dot import layout_extent

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
needs_dot = pytest.mark.skipif(shutil.which("dot") is None, reason="Graphviz dot not installed")
FOLD_BOX = re.compile(r"\[(\d+) nodes?\]<BR/><FONT[^>]*>focus ([^<]+)</FONT>")


def png_size(path: Path) -> tuple[int, int]:
    """(width, height) from the PNG's IHDR chunk."""
    head = path.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = struct.unpack(">II", head[16:24])
    return width, height


def big_tree() -> BTDocument:
    doc = random_bt(1, depth=10, breadth=10, max_nodes=1000)
    assert sum(1 for _ in doc.nodes()) > 1000
    return doc


def drawn_nodes(source: str) -> list[str]:
    """The BT nodes a picture's DOT draws (ids ``n<k>``; fold boxes are ``f<k>``)."""
    return re.findall(r"^\s*(n\d+) \[", source, flags=re.M)


def test_folded_subtrees_account_for_every_node_and_name_their_path() -> None:
    doc = big_tree()
    notes: list[str] = []
    source = model_to_dot(doc, notes=notes)
    boxes = FOLD_BOX.findall(source)
    shown = len(drawn_nodes(source))
    assert boxes and shown < 300
    assert shown + sum(int(count) for count, _ in boxes) == sum(1 for _ in doc.nodes())
    main = doc.main
    items = walk(doc, main.root, (main.id,), "", expanding=False, max_nodes=None)
    size_at = {item.where: item.size for item in items}
    for count, path in boxes:  # each box hides exactly the descendants of the node it names
        assert size_at[path] - 1 == int(count)
    assert len(notes) == 1
    assert f"folded {len(boxes)} subtrees" in notes[0]
    assert f"drew {shown} of {sum(1 for _ in doc.nodes())} nodes" in notes[0]
    assert "focus=PATH" in notes[0] and "depth=N" in notes[0]


def test_with_anchors_each_fold_box_names_its_folded_node_for_a_page_to_open() -> None:
    doc = big_tree()
    source = model_to_dot(doc, expand_subtrees=True, anchors=True)
    boxes = FOLD_BOX.findall(source)
    ids = re.findall(r'id="fold@([^"]+)"', source)
    assert boxes and sorted(ids) == sorted(path for _, path in boxes)
    assert source.count("class=fold") == len(ids)
    # the box's id opens exactly that subtree: focus on it draws the folded node on top
    opened = model_to_dot(doc, expand_subtrees=True, anchors=True, focus=ids[0])
    assert f'id="n@{ids[0]}"' in opened
    assert "fold@" not in model_to_dot(doc, expand_subtrees=True)  # no anchors: no ids


def test_small_trees_and_the_dot_file_format_are_not_folded() -> None:
    doc = api.load(EXAMPLES / "robot_bt.xml").model
    notes: list[str] = []
    source = model_to_dot(doc, notes=notes)
    assert len(drawn_nodes(source)) == sum(1 for _ in doc.nodes())
    assert not FOLD_BOX.search(source) and notes == []
    big = big_tree()
    assert len(drawn_nodes(bt_to_dot(big, max_nodes=None))) == sum(1 for _ in big.nodes())


def test_depth_folds_exactly_the_deeper_levels() -> None:
    doc = big_tree()
    root = doc.main.root
    assert root is not None
    source = model_to_dot(doc, level=1)
    assert len(drawn_nodes(source)) == 1 + len(root.children)
    folded = {path for _, path in FOLD_BOX.findall(source)}
    assert folded == {str(i) for i, child in enumerate(root.children) if child.children}
    only_root = model_to_dot(doc, level=0)
    assert len(drawn_nodes(only_root)) == 1
    assert [path for _, path in FOLD_BOX.findall(only_root)] == ["root"]


def test_focus_draws_the_subtree_under_a_path_or_a_unique_name() -> None:
    doc = big_tree()
    main = doc.main
    items = walk(doc, main.root, (main.id,), "", expanding=False, max_nodes=None)
    target = next(item for item in items if item.level >= 1 and 5 < item.size < 60)
    source = model_to_dot(doc, focus=target.where)
    assert len(drawn_nodes(source)) == target.size  # small enough: nothing folded
    robot = api.load(EXAMPLES / "robot_bt.xml").model
    named = model_to_dot(robot, focus="Recharge")
    assert len(drawn_nodes(named)) == 1 and "Recharge" in named
    with pytest.raises(InputError, match="no node 'nowhere'"):
        model_to_dot(robot, focus="nowhere")
    twice = BTDocument.single(
        BTNode(
            "Sequence",
            NodeKind.CONTROL,
            children=[BTNode("Go", NodeKind.ACTION), BTNode("Go", NodeKind.ACTION)],
        )
    )
    with pytest.raises(InputError, match=r"2 nodes are named 'Go'.*\(0, 1\)"):
        model_to_dot(twice, focus="Go")


def test_a_very_wide_composite_wraps_its_children_into_rows() -> None:
    leaves = [BTNode(f"Step{i:02d}", NodeKind.ACTION) for i in range(60)]
    doc = BTDocument.single(BTNode("Sequence", NodeKind.CONTROL, children=leaves))
    source = model_to_dot(doc)
    assert len(drawn_nodes(source)) == 61  # every child drawn, none folded
    junctions = re.findall(r"^\s*(j\d+) \[", source, flags=re.M)
    assert len(junctions) >= 2  # at least three rows
    # children keep their order: row after row, left to right
    labels = re.findall(r"label=<(Step\d\d)>", source)
    assert labels == [f"Step{i:02d}" for i in range(60)]


@needs_dot
def test_a_1000_node_tree_fits_4096_pixels_with_aspect_at_most_4_at_full_size(
    tmp_path: Path,
) -> None:
    doc = big_tree()
    notes: list[str] = []
    png = render_model(doc, tmp_path / "big.png", notes=notes)
    width, height = png_size(png)
    assert width <= 4096 and height <= 4096
    assert max(width, height) <= 4 * min(width, height)
    assert notes and notes[0].startswith("folded ")
    scale, _, _ = layout_extent(picture_dot(doc))
    assert scale == 1.0  # drawn at 100 %: folding, not shrinking, made it fit


@needs_dot
def test_a_wide_strip_is_laid_out_within_aspect_4(tmp_path: Path) -> None:
    leaves = [BTNode(f"Action{i}", NodeKind.ACTION) for i in range(6)]
    doc = BTDocument.single(BTNode("Sequence", NodeKind.CONTROL, children=leaves))
    width, height = png_size(render_model(doc, tmp_path / "strip.png"))
    assert width > 4 * 100 and max(width, height) <= 4 * min(width, height)


@needs_dot
def test_cli_says_what_was_folded_and_focus_draws_a_fold(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    model = tmp_path / "big.xml"
    model.write_text(dumps(big_tree(), "btcpp"))
    assert main(["render", str(model), "-o", str(tmp_path / "big.dot")]) == 0
    err = capsys.readouterr().err
    assert "note: folded" in err and "--focus PATH" in err and "--depth N" in err
    path = FOLD_BOX.findall((tmp_path / "big.dot").read_text())[0][1]
    assert main(["render", str(model), "-o", str(tmp_path / "part.png"), "--focus", path]) == 0
    width, height = png_size(tmp_path / "part.png")
    assert width <= 4096 and height <= 4096
    assert main(["render", str(model), "-o", str(tmp_path / "x.png"), "--focus", "9/9/9/9"]) == 2
    assert "no node '9/9/9/9'" in capsys.readouterr().err


def test_a_top_node_with_hundreds_of_children_shows_the_first_and_sums_up_the_rest() -> None:
    leaves = [BTNode(f"Step{i:03d}", NodeKind.ACTION) for i in range(300)]
    doc = BTDocument.single(BTNode("Sequence", NodeKind.CONTROL, children=leaves))
    notes: list[str] = []
    source = model_to_dot(doc, notes=notes)
    assert len(drawn_nodes(source)) == 1 + TOP_CHILDREN
    assert re.findall(r"label=<(Step\d+)>", source) == [f"Step{i:03d}" for i in range(TOP_CHILDREN)]
    rest = 300 - TOP_CHILDREN
    assert f"[{rest} more children, {rest} nodes]" in source
    assert f"focus {TOP_CHILDREN} … 299" in source
    assert notes == [
        f"drew the first {TOP_CHILDREN} of 300 children of root (the others, {rest} nodes, in "
        "one box; draw one with focus=PATH)"
    ]
    assert len(drawn_nodes(model_to_dot(doc, level=1))) == 301  # asked for: all of them


PAGES_BT = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Helper"><Sequence><Action ID="Fetch"/><Action ID="Carry"/></Sequence></BehaviorTree>
  <BehaviorTree ID="Main"><Fallback><SubTree ID="Helper"/><Action ID="Recover"/></Fallback></BehaviorTree>
  <BehaviorTree ID="main"><Action ID="Other"/></BehaviorTree>
</root>
"""


@needs_dot
def test_pages_draw_one_picture_per_tree_main_first(tmp_path: Path, capsys) -> None:
    """``render --pages DIR`` on a BT: one SVG per <BehaviorTree>, the main tree first, names
    made unique (``Main`` and ``main`` on a case-insensitive disk); an existing page without
    --force is refused before any file is written."""
    source = tmp_path / "three.xml"
    source.write_text(PAGES_BT, encoding="utf-8")
    pages = tmp_path / "pages"
    assert main(["render", str(source), "--pages", str(pages)]) == 0
    listed = capsys.readouterr().out
    assert "wrote 3 pictures" in listed and listed.index("Main.svg") < listed.index("Helper.svg")
    assert sorted(p.name for p in pages.iterdir()) == ["Helper.svg", "Main.svg", "main-2.svg"]
    helper = (pages / "Helper.svg").read_text(encoding="utf-8")
    assert "Fetch" in helper and "Recover" not in helper
    assert "Recover" in (pages / "Main.svg").read_text(encoding="utf-8")
    (pages / "Main.svg").unlink()
    before = {p.name: p.stat().st_mtime_ns for p in pages.iterdir()}
    assert main(["render", str(source), "--pages", str(pages)]) != 0  # Helper.svg exists
    assert not (pages / "Main.svg").exists()
    assert {p.name: p.stat().st_mtime_ns for p in pages.iterdir()} == before


def _open_by_full_extent(items, top, estimate, target):  # type: ignore[no-untyped-def]
    """``bt_fold._open`` as it was before the incremental profiles: the whole estimate
    (``_Estimate.extent``) recomputed for every node tried."""
    from fsmbt.render.bt_fold import NODE_BUDGET

    opened: set[int] = set()
    if len(items[top].children) > TOP_CHILDREN:
        estimate.limit[top] = TOP_CHILDREN
    shown, queue, head = 1, [top], 0
    while head < len(queue):
        index = queue[head]
        head += 1
        kids = estimate.kids(index)
        if not kids:
            continue
        cost = len(kids) + sum(1 for c in kids if items[c].children) - (1 if index != top else 0)
        if index != top and shown + cost > NODE_BUDGET:
            continue
        opened.add(index)
        width, height, _ = estimate.extent(top, opened)
        if index != top and (width > target or height > target):
            opened.discard(index)
            continue
        shown += cost
        queue.extend(kids)
    return opened


def test_the_incremental_estimate_opens_what_the_full_estimate_opens() -> None:
    """``_open`` updates only the profiles of the node it tries and its ancestors
    (``bt_fold._Profiles``); it must open exactly the nodes the whole-tree estimate opens, for
    every row width and size tried: FSM dispatch and LEBT trees, random BTs, a wide root."""
    from fsmbt.generate.generator import random_fsm
    from fsmbt.render.bt_fold import ROW_WIDTHS, _Estimate, _open
    from fsmbt.render.bt_graph import measure

    docs: list[BTDocument] = []
    for seed in range(4):
        fsm = random_fsm(seed=f"fold-{seed}", n_states=12 + 8 * seed, max_states=12 + 8 * seed)
        docs += [api.convert_model(fsm, "rules", style=s).model for s in ("dispatch", "lebt")]
    docs += [random_bt(seed=seed, depth=8, max_nodes=400) for seed in range(6)]
    wide = BTNode(
        "Sequence",
        NodeKind.CONTROL,
        children=[BTNode(f"A{i}", NodeKind.ACTION) for i in range(130)],
    )
    docs.append(BTDocument.single(wide))
    tried = 0
    for doc in docs:
        tree = doc.main
        assert tree.root is not None
        items = walk(doc, tree.root, (tree.id,), "", expanding=True, max_nodes=None)
        sizes = [measure(item.node) for item in items]
        for row in ROW_WIDTHS:
            for target in (36.0, 18.0, 6.0):
                expected = _open_by_full_extent(items, 0, _Estimate(items, sizes, row), target)
                assert _open(items, 0, _Estimate(items, sizes, row), None, target) == expected
                tried += 1
    assert tried == len(docs) * len(ROW_WIDTHS) * 3
