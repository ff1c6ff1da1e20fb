"""python-statemachine as an independent oracle for fsmbt's SCXML reader (issue 11, 5b).

For every corpus SCXML file (``FSMBT_CORPUS``/fsm, default ``<repo>/../shared/corpus``; the
``_malformed`` and ``_legacy_draft`` folders excluded) that both fsmbt and python-statemachine
3.2.2 read, ``FSMBT_SCXML_READER_SEQUENCES`` (default 20) seeded random event sequences of up to
``FSMBT_SCXML_LENGTH`` events (default 20) must give the same configuration after every event
in the engine and in ``FSMMachine`` over fsmbt's model of the file. Then hand-written documents
probe the corners of the supported subset where a reader is most easily wrong (parallel
regions, prefix-free event matching, completion of nested and parallel states, transitions
leaving several levels, document order). Counts are printed (``pytest -s``).

Departures of the engine from the W3C algorithm found on the way are documented in
docs/formats/scxml.md ("python-statemachine as oracle") and named by a test here.
"""

from __future__ import annotations

import os
import random
import signal
from pathlib import Path

import pytest
from scxml_oracle import Engine, python_spelled, replay

from fsmbt import api
from fsmbt.formats import loads
from fsmbt.model.errors import FsmbtError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.machine import FSMMachine
from support.corpus import CORPUS

REPO = Path(__file__).resolve().parents[2]
SEQUENCES = int(os.environ.get("FSMBT_SCXML_READER_SEQUENCES", "20"))
LENGTH = int(os.environ.get("FSMBT_SCXML_LENGTH", "20"))
SEED = int(os.environ.get("FSMBT_SCXML_SEED", "11"))
#: Wall seconds the engine may take on one corpus file's sequences. An ECMAScript document read
#: in the engine's Python data model can loop forever: an eventless transition whose cond
#: fails (``true`` is no Python name) raises error.execution, and W3C's algorithm then selects
#: it again; hence the Python spelling (``scxml_oracle.python_spelled``) and this bound.
ENGINE_SECONDS = int(os.environ.get("FSMBT_SCXML_ENGINE_SECONDS", "60"))
NS = 'xmlns="http://www.w3.org/2005/07/scxml"'


def corpus_scxml() -> list[Path]:
    folder = CORPUS / "fsm"
    return sorted(
        p
        for p in folder.rglob("*.scxml")
        if "_malformed" not in p.parts and "_legacy_draft" not in p.parts
    )


def compare(text: str, model: FSM, seed: int, sequences: int) -> tuple[int, list[str]]:
    rng = random.Random(seed)
    machine = FSMMachine(model)
    events = 0
    mismatches = []
    for _ in range(sequences):
        result = replay(text, model, rng, length=LENGTH, machine=machine)
        events += result.sent
        if result.mismatch is not None:
            mismatches.append(str(result.mismatch))
        if result.departure is not None:
            mismatches.append(f"undocumented here: {result.departure}")
    return events, mismatches


class _EngineTooSlow(Exception):
    pass


def _alarm(_signum: int, _frame: object) -> None:
    raise _EngineTooSlow


def test_corpus_files_both_read_agree() -> None:
    paths = corpus_scxml() if (CORPUS / "fsm").exists() else []
    if not paths:
        pytest.skip(f"corpus not found at {CORPUS} (set FSMBT_CORPUS)")
    compared, fsmbt_refuses, engine_refuses, events = [], [], [], 0
    spelled, too_slow = [], []
    disagreements: dict[str, list[str]] = {}
    previous = signal.signal(signal.SIGALRM, _alarm)
    try:
        for index, path in enumerate(paths):
            label = str(path.relative_to(CORPUS))
            try:
                model = api.load(path).model
            except FsmbtError:
                fsmbt_refuses.append(label)
                continue
            text = path.read_text()
            python = python_spelled(text)
            if python is not None:  # the engine's data model is Python: same values, its spelling
                text, model = python, loads(python, "scxml")
                spelled.append(label)
            try:
                Engine(text)
            except Exception as exc:  # the engine's own refusal, whatever its type
                engine_refuses.append(f"{label}: {type(exc).__name__}")
                continue
            signal.alarm(ENGINE_SECONDS)
            try:
                sent, mismatches = compare(text, model, SEED + index, SEQUENCES)
            except _EngineTooSlow:
                too_slow.append(label)
                continue
            finally:
                signal.alarm(0)
            events += sent
            compared.append(label)
            if mismatches:
                disagreements[label] = mismatches[:2]
    finally:
        signal.signal(signal.SIGALRM, previous)
    print(
        f"\n[corpus scxml] {len(paths)} files: {len(compared)} read by both and compared "
        f"({len(compared) * SEQUENCES} sequences, {events} events; {len(spelled)} ECMAScript "
        f"documents given to both in Python spelling), "
        f"{len(compared) - len(disagreements)} agree, {len(disagreements)} disagree; "
        f"refused by fsmbt {len(fsmbt_refuses)}, by the engine (fsmbt reads them) "
        f"{len(engine_refuses)} {engine_refuses}; engine past {ENGINE_SECONDS} s: {too_slow}"
    )
    assert not too_slow, too_slow
    assert len(compared) >= 15
    assert not disagreements, disagreements


# -- probes: the corners of the subset ---------------------------------------------------------
PROBES = {
    "parallel regions both move, parent transition on the same event loses": """
  <parallel id="p">
    <state id="r1"><state id="a1"><transition event="e" target="a2"/></state><state id="a2"/></state>
    <state id="r2"><state id="b1"><transition event="f" target="b2"/></state><state id="b2"/></state>
    <transition event="e" target="out"/><transition event="g" target="out"/>
  </parallel>
  <state id="out"><transition event="back" target="p"/></state>""",
    "completion of a compound whose initial state is final at once": """
  <state id="s"><transition event="go" target="c"/></state>
  <state id="c"><final id="cf"/><transition event="done.state.c" target="t"/></state>
  <state id="t"><transition event="again" target="s"/></state>""",
    "eventless chain into a nested compound": """
  <state id="s"><transition target="c"/></state>
  <state id="c"><state id="c1"><transition target="c2"/></state>
    <state id="c2"><transition event="x" target="cf"/></state><final id="cf"/>
    <transition event="done.state.c" target="end"/></state>
  <final id="end"/>""",
    "an event on a compound whose sub-machine sits in a final state": """
  <state id="c"><state id="c1"><transition event="x" target="cf"/></state><final id="cf"/>
    <transition event="y" target="d"/></state>
  <state id="d"><transition event="y" target="c"/></state>""",
    "self-transition of a compound restarts it": """
  <state id="c"><state id="c1"><transition event="x" target="c2"/></state><state id="c2"/>
    <transition event="r" target="c"/></state>""",
    "transition leaving two levels, and the same event on each level": """
  <state id="a"><state id="a1"><state id="x"><transition event="go" target="b"/>
    <transition event="in" target="y"/></state><state id="y"><transition event="go" target="a"/>
    </state><transition event="up" target="b"/></state>
    <transition event="go" target="a"/><transition event="up" target="a"/></state>
  <state id="b"><transition event="back" target="a"/></state>""",
    "parallel of compound states completes, nested in a compound": """
  <state id="top" initial="p"><parallel id="p">
    <state id="r1"><state id="a1"><transition event="x" target="af"/></state><final id="af"/></state>
    <state id="r2"><state id="b1"><transition event="y" target="bf"/></state><final id="bf"/></state>
    <transition event="done.state.p" target="tf"/></parallel>
    <final id="tf"/><transition event="done.state.top" target="end"/></state>
  <final id="end"/>""",
    "document order between transitions on one event": """
  <state id="s"><transition event="e" target="t"/><transition event="e" target="u"/></state>
  <state id="t"><transition event="e" target="s"/></state><state id="u"/>""",
    "guarded completion transitions (fsmbt's own encoding)": """
  <state id="u"><state id="w"><transition event="ok" target="uS"/>
    <transition event="ko" target="uF"/></state><final id="uS"/><final id="uF"/>
    <transition event="done.state.u" cond="In('uS')" target="won"/>
    <transition event="done.state.u" cond="In('uF')" target="lost"/></state>
  <state id="won"><transition event="again" target="u"/></state><final id="lost"/>""",
    "dotted ids and events that are not prefixes of each other": """
  <state id="a.b"><transition event="x.y" target="a.c"/></state>
  <state id="a.c"><transition event="x.z" target="a.b"/></state>""",
}


#: Documents the structural reader refuses and fsmbt reads by running the W3C algorithm
#: (``fsmbt.formats.scxml.w3c``, docs/formats/scxml.md): one per feature of issue 12 part 4.
W3C_PROBES = {
    "shallow history restores the last child, not its descendants": """
  <state id="a" initial="a1"><history id="h"><transition target="a1"/></history>
    <state id="a1"><transition event="n" target="a2"/></state>
    <state id="a2" initial="x"><state id="x"><transition event="n" target="y"/></state>
      <state id="y"/></state>
    <transition event="out" target="b"/></state>
  <state id="b"><transition event="back" target="h"/><transition event="reset" target="a"/></state>""",
    "deep history restores the leaves": """
  <state id="a" initial="a1"><history id="h" type="deep"><transition target="a1"/></history>
    <state id="a1"><transition event="n" target="a2"/></state>
    <state id="a2" initial="x"><state id="x"><transition event="n" target="y"/></state>
      <state id="y"/></state>
    <transition event="out" target="b"/></state>
  <state id="b"><transition event="back" target="h"/></state>""",
    "raise runs before the next external event, in order": """
  <state id="s"><transition event="go" target="t"><raise event="one"/><raise event="two"/>
    </transition></state>
  <state id="t"><transition event="one" target="u"/><transition event="two" target="s"/></state>
  <state id="u"><transition event="two" target="v"/><transition event="one" target="s"/></state>
  <state id="v"><transition event="go" target="s"/></state>""",
    "send without target: external queue, after the internal events": """
  <state id="s"><onentry><send event="ext"/><raise event="int"/></onentry>
    <transition event="int" target="t"/><transition event="ext" target="w"/></state>
  <state id="t"><transition event="ext" target="u"/><transition event="int" target="w"/></state>
  <state id="u"><transition event="again" target="s"/></state><state id="w"/>""",
    "guards are chosen by the environment; the engine's choice is one of fsmbt's": """
  <datamodel><data id="flag" expr="True"/></datamodel>
  <state id="s"><transition event="e" cond="flag" target="t"/>
    <transition event="e" target="u"/></state>
  <state id="t"><transition event="back" target="s"/></state>
  <state id="u"><transition event="back" target="s"/></state>""",
    "wildcard and prefix descriptors": """
  <state id="s"><transition event="a.b" target="t"/><transition event="a.*" target="u"/>
    <transition event="*" target="w"/></state>
  <state id="t"><transition event="a" target="s"/></state>
  <state id="u"><transition event="x" target="s"/></state>
  <state id="w"><transition event="a.b.c" target="s"/></state>""",
    "done.state of an atomic parent never comes; entry into a non-initial child": """
  <state id="s"><transition event="go" target="c2"/><transition event="done.state.s" target="s"/>
    </state>
  <state id="c" initial="c1"><state id="c1"><transition event="n" target="c2"/></state>
    <state id="c2"><transition event="n" target="cf"/></state><final id="cf"/>
    <transition event="done.state.c" target="s"/></state>""",
    "targetless and internal transitions": """
  <state id="c" initial="c1"><state id="c1"><transition event="n" target="c2"/></state>
    <state id="c2"><transition event="n" target="c1"/></state>
    <transition event="stay"><raise event="n"/></transition>
    <transition event="in" type="internal" target="c1"/>
    <transition event="ext" target="c1"/></state>""",
    "exact data: a counter read by guards, assignments on transitions and on entry": """
  <datamodel><data id="cook" expr="3"/><data id="t" expr="0"/><data id="closed" expr="True"/>
  </datamodel>
  <state id="off"><transition event="on" target="on"/></state>
  <state id="on" initial="idle"><onentry><assign location="t" expr="0"/></onentry>
    <transition event="off" target="off"/><transition cond="t &gt;= cook" target="off"/>
    <state id="idle"><transition cond="closed" target="cooking"/>
      <transition event="close" target="cooking"><assign location="closed" expr="True"/>
      </transition></state>
    <state id="cooking"><transition event="open" target="idle">
      <assign location="closed" expr="False"/></transition>
      <transition event="time"><assign location="t" expr="t + 1"/></transition></state></state>""",
    "exact data: an internal transition keeps the counter, an external one runs exit/entry": """
  <datamodel><data id="x" expr="0"/></datamodel>
  <state id="a" initial="a1"><onentry><assign location="x" expr="x + 1"/></onentry>
    <onexit><assign location="x" expr="x + 1"/></onexit>
    <state id="a1"><transition event="ext" target="a2"/></state>
    <state id="a2"><transition event="go" cond="x == 1" target="b"/>
      <transition event="go" cond="x == 3" target="c"/></state>
    <transition event="t1" type="internal" cond="x == 1" target="a2"/>
    <transition event="t0" cond="x &lt; 5" target="a"/></state>
  <state id="b"><transition event="back" cond="x % 2 == 0" target="a"/></state>
  <state id="c"><transition event="back" target="a"/></state>""",
    "computed event names: eventexpr of a literal and _event.name": """
  <state id="s"><transition event="go stop" target="t">
    <send eventexpr="'did.' + _event.name"/></transition></state>
  <state id="t"><transition event="did.go" target="u"/><transition event="did.stop" target="v"/>
  </state>
  <state id="u"><transition event="back" target="s"/></state>
  <state id="v"><transition event="back" target="s"/></state>""",
    "error.execution: _event read before any event skips the send and the rest": """
  <state id="s"><onentry><send eventexpr="'x.' + _event.name"/><raise event="r"/></onentry>
    <transition event="error.execution" target="failed"/><transition event="r" target="ran"/>
    <transition event="x" target="ran"/></state>
  <state id="failed"><transition event="back" target="t"/></state><state id="ran"/>
  <state id="t"><onentry><send event="y"><param name="p" expr="_event.data"/></send></onentry>
    <transition event="y" target="u"/></state><state id="u"/>""",
    "if branches raise by guard; log and unread assign ignored": """
  <datamodel><data id="flag" expr="False"/><data id="count" expr="0"/></datamodel>
  <state id="s"><transition event="go" target="t"><log expr="'go'"/>
    <assign location="count" expr="count + 1"/>
    <if cond="flag"><raise event="yes"/><else/><raise event="no"/></if></transition></state>
  <state id="t"><transition event="yes" target="y"/><transition event="no" target="n"/></state>
  <state id="y"><transition event="back" target="s"/></state>
  <state id="n"><transition event="back" target="s"/></state>""",
}


@pytest.mark.parametrize("case", sorted(W3C_PROBES))
def test_w3c_probe_agrees(case: str) -> None:
    text = f'<scxml {NS} version="1.0" datamodel="python">{W3C_PROBES[case]}\n</scxml>'
    model = loads(text, "scxml")
    assert not model.is_hierarchical  # read by the W3C algorithm
    _events, mismatches = compare(text, model, SEED, 60)
    assert not mismatches, mismatches[:3]


@pytest.mark.parametrize("case", sorted(PROBES))
def test_probe_agrees(case: str) -> None:
    text = f'<scxml {NS} version="1.0">{PROBES[case]}\n</scxml>'
    model = loads(text, "scxml")
    _events, mismatches = compare(text, model, SEED, 60)
    assert not mismatches, mismatches[:3]


# -- departures of the engine from the W3C algorithm -----------------------------------------------
@pytest.mark.parametrize(
    "body, w3c, engine",
    [
        # W3C 3.3: no initial attribute -> the first child state in document order (here <parallel>)
        (
            '<state id="top"><parallel id="p"><state id="a"/><state id="b"/></parallel>'
            '<state id="t"/></state>',
            "top/p/[a|b]",
            "top/t",
        ),
        # ... and here the <final>
        ('<state id="c"><final id="f"/><state id="s"/></state>', "c/f", "c/s"),
    ],
)
def test_departure_default_initial_of_compound_ignores_document_order(
    body: str, w3c: str, engine: str
) -> None:
    """python-statemachine 3.2.2 collects a compound state's children by tag (<state>, then
    <final>, then <parallel>), so without ``initial`` it starts in the first <state> child, not
    the first child in document order as W3C says. fsmbt keeps W3C's rule; the files fsmbt
    writes always carry ``initial`` on compound states, so they do not meet the case."""
    text = f'<scxml {NS} version="1.0">{body}</scxml>'
    fsmbt_state, _ = FSMMachine(loads(text, "scxml")).start()
    assert fsmbt_state == w3c
    assert Engine(text).configuration() == engine  # the departure, as of 3.2.2


def test_departure_event_list_with_two_blanks_matches_every_event() -> None:
    """python-statemachine 3.2.2 splits an ``event`` list on single blanks: ``"a.x  b.y"`` (a
    list written across lines, as ``qt_scxml_examples/ftpclient.scxml`` does) gets an empty
    descriptor that matches every event, so ``r`` takes the first transition. W3C splits on
    whitespace: ``r`` takes the second. The oracle gives the engine each list's blanks
    collapsed (``scxml_oracle.engine_text``, the same document to W3C)."""
    from statemachine.io.loader import load

    text = f"""<scxml {NS} version="1.0">
  <state id="s"><transition event="a.x
        b.y" target="t"/><transition event="r" target="u"/></state>
  <state id="t"/><state id="u"/></scxml>"""
    machine = load(text, format="scxml")()
    machine.send("r")
    assert sorted(s.id for s in machine.configuration) == ["t"]  # the departure, as of 3.2.2
    fsmbt = FSMMachine(loads(text, "scxml"))
    assert fsmbt.step(fsmbt.start()[0], "r")[0] == "u"
    assert Engine(text).configuration() == "s"
    engine = Engine(text)
    engine.send("r")
    assert engine.configuration() == "u"  # with the blanks collapsed


def test_departure_engine_stops_when_a_top_level_parallel_completes() -> None:
    """python-statemachine 3.2.2 stops (``is_terminated``) once every region of a top-level
    <parallel> rests in a final state; W3C stops only on entering a top-level <final>: the
    parallel raises ``done.state.p`` and the machine runs on, so ``p``'s own transitions still
    fire. fsmbt keeps W3C's rule (``FSMMachine`` is still running and takes ``e``)."""
    text = f"""<scxml {NS} version="1.0">
  <parallel id="p"><transition event="e" target="out"/>
    <state id="a"><state id="a1"><transition event="x" target="af"/></state><final id="af"/></state>
    <state id="b"><state id="b1"><transition event="y" target="bf"/></state><final id="bf"/></state>
  </parallel><state id="out"/></scxml>"""
    machine = FSMMachine(loads(text, "scxml"))
    engine = Engine(text)
    state, _ = machine.start()
    for event in ("x", "y"):
        state, _ = machine.step(state, event)
        engine.send(event)
    assert engine.configuration() == state == "p/[a/af|b/bf]"
    assert machine.status(state) == "running" and engine.terminated  # the departure
    assert engine.top_parallel_completed()
    state, _ = machine.step(state, "e")
    engine.send("e")
    assert state == "out" and engine.configuration() == "p/[a/af|b/bf]"


def test_departure_assign_fails_in_a_second_instance_of_one_loaded_class() -> None:
    """python-statemachine 3.2.2: two instances of one class loaded from a document with
    ``<assign location="count" expr="count + 1"/><raise event="no"/>`` differ: the first runs
    the block (W3C: ``t`` then ``n``), the second skips the raise after the assign and stays in
    ``t``. fsmbt keeps W3C's reading (the assign is ignored, the raise runs); the oracle loads
    a fresh class per instance for such documents (``scxml_oracle.ASSIGN_SHARED_CLASS``)."""
    from statemachine.io.loader import load

    text = f"""<scxml {NS} version="1.0" datamodel="python">
  <datamodel><data id="count" expr="0"/></datamodel>
  <state id="s"><transition event="go" target="t"><assign location="count" expr="count + 1"/>
    <raise event="no"/></transition></state>
  <state id="t"><transition event="no" target="n"/></state><state id="n"/></scxml>"""
    chart = load(text, format="scxml")
    seen = []
    for _ in range(2):
        machine = chart()
        machine.send("go")
        seen.append(sorted(s.id for s in machine.configuration))
    assert seen == [["n"], ["t"]]  # the departure, as of 3.2.2
    fsmbt = FSMMachine(loads(text, "scxml"))
    state, _ = fsmbt.start()
    assert fsmbt.step(state, "go")[0] == "n"
    assert Engine(text).configuration() == "s"


def test_an_invalid_send_target_raises_error_execution_in_both() -> None:
    """``<send target="_internal">`` (an older draft's spelling of ``#_internal``): W3C 6.2.4
    and the engine raise error.execution and skip the rest of the block; so does fsmbt."""
    text = (
        '<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0">'
        '<state id="s"><transition event="go" target="t"/></state>'
        '<state id="t"><onentry><send target="_internal" event="sent"/>'
        '<raise event="after"/></onentry>'
        '<transition event="sent" target="got_it"/><transition event="after" target="went_on"/>'
        '<transition event="error.execution" target="failed"/></state>'
        '<state id="got_it"/><state id="went_on"/><state id="failed"/></scxml>'
    )
    engine = Engine(text)
    engine.send("go")
    machine = FSMMachine(loads(text, "scxml"))
    state, _ = machine.step(machine.start()[0], "go")
    assert engine.configuration() == state == "failed"
