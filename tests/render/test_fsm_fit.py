"""State-machine pictures read at 100 % (issue 29 item 6): a layout longer than 4 096 pixels
(42.6 in) is laid out again - long names in lines, long chains wrapped into rows, composite
states folded into ``[k states inside]`` boxes - instead of being scaled down; ``--focus`` draws
a composite's inside, and ``--pages`` draws every state on some page."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.cli import main
from fsmbt.model import FSM, State
from fsmbt.render import fsm_to_dot, picture_dot, render_model, render_pages
from fsmbt.render.dot import layout_extent

pytestmark = pytest.mark.skipif(shutil.which("dot") is None, reason="Graphviz dot not installed")

#: 4 096 pixels at 96 dpi: the longest side drawn at 100 %.
FIT_INCHES = 42.6
INNER = 40
_LABEL = re.compile(r'\blabel=(?:"((?:[^"\\]|\\.)*)"|([^\s\]"]+))')


def labels(source: str) -> list[str]:
    """Every node and cluster label of a DOT source, its lines joined by newlines."""
    return [(quoted or bare).replace("\\n", "\n") for quoted, bare in _LABEL.findall(source)]


def names_drawn(source: str) -> set[str]:
    """Each label's first lines joined back into one name (a long name is broken into lines
    after ``_`` with nothing dropped)."""
    return {"".join(text.split("\n")) for text in labels(source)}


def longest_side(source: str) -> float:
    """The layout's longest side in inches before Graphviz would scale it (scale 1: drawn at
    100 %)."""
    scale, width, height = layout_extent(source)
    return max(width, height) / scale


def phase(index: int) -> str:
    return f"phase_{index:02d}_of_the_long_run"


def plant() -> FSM:
    """Start -> Run (a composite of a 40-state chain of long names) -> Stop."""
    inner = FSM(name="Run")
    for index in range(INNER):
        inner.add_state(phase(index))
    for index in range(INNER - 1):
        inner.add_transition(phase(index), "next", phase(index + 1))
    top = FSM(name="plant")
    top.add_state("Start")
    top.add_state(State("Run", action=None, regions=[inner]))
    top.add_state("Stop", final=True)
    top.add_transition("Start", "go", "Run")
    top.add_transition("Run", "halt", "Stop")
    return top


def test_a_composite_too_big_at_100_percent_is_folded_into_a_box_with_its_count() -> None:
    fsm = plant()
    unfitted = fsm_to_dot(fsm)  # every level open: the chain alone is longer than 4096 px
    assert phase(INNER - 1) in names_drawn(unfitted) and longest_side(unfitted) > FIT_INCHES
    notes: list[str] = []
    source = picture_dot(fsm, notes=notes)
    assert f"Run\n[{INNER} states inside]" in labels(source)
    assert not any(name.startswith("phase_") for name in names_drawn(source))
    assert {"Start", "Stop"} <= names_drawn(source)
    scale, width, height = layout_extent(source)
    assert scale == 1.0 and max(width, height) <= FIT_INCHES
    assert any("folded" in note and "Run" in note and "pages=DIR" in note for note in notes)
    # on the web page a trace step inside Run highlights the box (its anchor is Run's)
    boxes = [line for line in picture_dot(fsm, anchors=True).splitlines() if "inside]" in line]
    assert len(boxes) == 1 and 'id="s@Run"' in boxes[0]


def test_a_long_flat_chain_is_wrapped_into_rows_not_scaled_down() -> None:
    fsm = FSM(name="chain")
    for index in range(30):
        fsm.add_state(phase(index))
    for index in range(29):
        fsm.add_transition(phase(index), "next", phase(index + 1))
    assert longest_side(fsm_to_dot(fsm)) > FIT_INCHES
    source = picture_dot(fsm)
    assert longest_side(source) <= FIT_INCHES
    assert {phase(index) for index in range(30)} <= names_drawn(source)  # nothing left out
    assert "constraint=false" in source  # arrows between rows


def test_long_state_names_are_broken_into_lines_and_a_repeated_action_left_out() -> None:
    fsm = FSM(name="oven")
    fsm.add_state("off#cook_time=5;door_closed=true;timer=0", action="off")
    fsm.add_state("on/cooking#cook_time=5;door_closed=true;timer=0", action="cooking")
    fsm.add_state("Heat", action="heater_on")
    fsm.add_transition("off#cook_time=5;door_closed=true;timer=0", "turn_on", "Heat")
    drawn = labels(fsm_to_dot(fsm))
    off = next(text for text in drawn if text.startswith("off#"))
    assert all(len(line) <= 18 for line in off.split("\n")) and "\n" in off
    assert "".join(off.split("\n")) == "off#cook_time=5;door_closed=true;timer=0"
    assert "/ off" not in off  # the name says it already
    assert "Heat\n/ heater_on" in drawn  # an action the name does not show is kept


SCXML = """<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0" initial="Start">
  <state id="Start"><transition event="go" target="Run"/></state>
  <state id="Run" initial="{first}">
{inner}
    <transition event="halt" target="Stop"/>
  </state>
  <final id="Stop"/>
</scxml>
"""


def write_plant(folder: Path) -> Path:
    inner = "\n".join(
        f'    <state id="{phase(i)}"><transition event="next" target="{phase(i + 1)}"/></state>'
        for i in range(INNER - 1)
    )
    inner += f'\n    <state id="{phase(INNER - 1)}"/>'
    path = folder / "plant.scxml"
    path.write_text(SCXML.format(first=phase(0), inner=inner), encoding="utf-8")
    return path


def test_focus_draws_the_inner_states_of_a_folded_composite(tmp_path: Path, capsys) -> None:
    model = write_plant(tmp_path)
    assert main(["render", str(model), "-o", str(tmp_path / "all.dot")]) == 0
    said = capsys.readouterr().err  # the default picture folds Run, and says how to see it ...
    assert "folded" in said and "--focus PATH" in said and "--pages DIR" in said
    out = tmp_path / "run.dot"
    assert main(["render", str(model), "-o", str(out), "--focus", "Run"]) == 0
    source = out.read_text(encoding="utf-8")
    assert {phase(index) for index in range(INNER)} <= names_drawn(source)  # ... focus opens it
    assert "Start" not in names_drawn(source)
    assert longest_side(source) <= FIT_INCHES
    same = render_model(api.load(model).model, tmp_path / "same.dot", composite="Run")
    assert same.read_text(encoding="utf-8") == source  # --focus is --composite for an FSM
    assert (
        main(
            ["render", str(model), "-o", str(tmp_path / "x.dot"), "--focus", "Run"]
            + ["--composite", "Start"]
        )
        == 2
    )


def test_pages_draw_every_state_on_some_page(tmp_path: Path) -> None:
    fsm = plant()
    deep = FSM(name="Check")
    deep.add_state("Probe")
    deep.add_state("Done", final=True)
    deep.add_transition("Probe", "ok", "Done")
    fsm.add_state(State("Check", action=None, regions=[deep]))
    fsm.add_transition("Stop", "again", "Check")
    pages = render_pages(fsm, tmp_path / "pages", fmt="dot")
    assert [p.name for p in pages] == ["top.dot", "Run.dot", "Check.dot"]
    drawn = [names_drawn(p.read_text(encoding="utf-8")) for p in pages]
    every = {"Start", "Stop", "Probe", "Done", *(phase(i) for i in range(INNER))}
    assert every <= set().union(*drawn)
    assert f"Run[{INNER} states inside]" in drawn[0] and "Probe" not in drawn[0]
    assert all(longest_side(p.read_text(encoding="utf-8")) <= FIT_INCHES for p in pages)
