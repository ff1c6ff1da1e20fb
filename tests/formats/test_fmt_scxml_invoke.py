"""``<invoke>`` of SCXML sessions (fsmbt.formats.scxml.invoke): the expected configurations are
worked out by hand from the W3C SCXML 1.0 text (6.4 <invoke>, 6.2.4 send targets, appendix D:
``statesToInvoke``, ``exitStates`` cancelling, the main loop's finalize/autoforward step,
``exitInterpreter`` and ``done.invoke``), with fsmbt's schedule (docs/formats/scxml.md: an
event given to a child is processed by it at once). The differential test against
python-statemachine's SCXML engine is at the end (it runs children in threads and sends
``done.invoke`` when a child has *started*, not when it ends, so it is compared on documents
that do not read ``done.invoke``).
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import time
from pathlib import Path

import pytest

from fsmbt import api, limits
from fsmbt.formats import loads
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.verify.nusmv.binary import find_nusmv
from support.corpus import CORPUS

NS = 'xmlns="http://www.w3.org/2005/07/scxml"'


def doc(body: str, initial: str | None = None) -> str:
    first = f' initial="{initial}"' if initial else ""
    return f'<scxml {NS} version="1.0"{first}>\n{body}\n</scxml>'


def child(body: str, attrs: str = "") -> str:
    """An ``<invoke>`` of an inline child document."""
    return f'<invoke {attrs}><content><scxml version="1.0">{body}</scxml></content></invoke>'


def walk(model: FSM, events: list[str]) -> list[str]:
    """The flat FSM's states along ``events`` (an event with no transition is ignored)."""
    step = {(t.source, t.event): t.target for t in model.transitions}
    state = model.initial or ""
    seen = [state]
    for event in events:
        state = step.get((state, event), state)
        seen.append(state)
    return seen


def read(text: str, **options: object) -> FSM:
    model = loads(text, "scxml", options=options or None)
    assert isinstance(model, FSM)
    return model


TOGGLE = child(
    '<state id="here"><transition event="goThere" target="there"/></state>'
    '<state id="there"><transition event="goHere" target="here"/></state>',
    'type="http://www.w3.org/TR/scxml/" autoforward="true"',
)


def test_autoforwarded_child_is_part_of_the_state_and_restarts_on_reentry() -> None:
    model = read(
        doc(
            '<state id="any"><transition event="goNowhere" target="nowhere"/>'
            '<transition event="goSomewhere" target="somewhere"/>'
            f'<state id="nowhere"/><state id="somewhere">{TOGGLE}</state></state>'
        )
    )
    # the invoke id is <state id>.<n> (W3C: stateid.platformid); an external transition
    # re-entering 'somewhere' cancels the session and starts a new one in its initial state
    assert walk(model, ["goSomewhere", "goThere", "goSomewhere", "goThere", "goHere"]) == [
        "any/nowhere",
        "any/somewhere{somewhere.1=here}",
        "any/somewhere{somewhere.1=there}",
        "any/somewhere{somewhere.1=here}",
        "any/somewhere{somewhere.1=there}",
        "any/somewhere{somewhere.1=here}",
    ]
    assert model.states["any/somewhere{somewhere.1=there}"].action == "somewhere+there"
    # without autoforward the child never hears the environment: goThere is not an input
    silent = TOGGLE.replace(' autoforward="true"', "")
    quiet = read(doc(f'<state id="s">{silent}</state>'))
    assert walk(quiet, ["goThere"]) == ["s{s.1=here}"] * 2
    assert {t.event for t in quiet.transitions} == set()


def test_child_events_reach_the_parent_queue_before_the_environment_speaks() -> None:
    # the child starts at the end of the first macro step, sends 'ready' to #_parent, and the
    # parent takes it before the environment's first event (the environment waits for idle)
    body = child(
        '<state id="idle"><onentry><send event="ready" target="#_parent"/></onentry>'
        '<transition event="ping" target="busy"><send event="pong" target="#_parent"/>'
        "</transition></state>"
        '<state id="busy"><transition event="ping" target="end"/></state>'
        '<final id="end"><onexit><send event="bye" target="#_parent"/></onexit></final>',
        'id="c"',
    )
    model = read(
        doc(
            f'<state id="s">{body}'
            '<state id="s1"><transition event="ready" target="s2"/></state>'
            '<state id="s2"><transition event="poke"><send event="ping" target="#_c"/>'
            '</transition><transition event="pong" target="s3"/></state>'
            '<state id="s3"><transition event="poke"><send event="ping" target="#_c"/>'
            '</transition><transition event="bye" target="s4"/></state>'
            '<state id="s4"><transition event="done.invoke.c" target="t"/>'
            '<transition event="bye" target="wrong"/></state>'
            '</state><state id="t"/><state id="wrong"/>'
        )
    )
    # poke: the parent sends ping; the child moves to busy and sends pong -> s3.
    # poke again: the child ends; its final state's onexit (exitInterpreter) sends bye before
    # done.invoke.c: s3 --bye--> s4 --done.invoke.c--> t
    assert walk(model, ["poke", "poke"]) == ["s/s2{c=idle}", "s/s3{c=busy}", "t"]
    # FSM -> BT of the session system is proved equivalent (native checker and NuSMV)
    result = api.convert_model(model, style="lebt")  # the LEBT: NuSMV checks it too
    assert api.verify_models(model, result.model, "native").equivalent
    if find_nusmv() is not None:
        assert api.verify_models(model, result.model, "nusmv").equivalent


def test_state_exited_in_the_macro_step_that_entered_it_invokes_nothing() -> None:
    started = child(
        '<state id="a"><onentry><send event="started" target="#_parent"/></onentry></state>'
    )
    model = read(
        doc(
            f'<state id="s">{started}<transition target="t"/></state>'
            '<state id="t"><transition event="started" target="wrong"/></state>'
            '<state id="wrong"/>'
        )
    )
    assert model.initial == "t"  # (the environment may still send 'started' itself)
    assert not any("{" in name for name in model.states)


def test_events_of_a_cancelled_session_are_ignored() -> None:
    # 'e' is forwarded first (the child answers 'late'), then the parent leaves s on 'e',
    # cancelling the child: 'late' is from a cancelled session and is not processed
    answer = child(
        '<state id="a"><transition event="e" target="b"><send event="late" target="#_parent"/>'
        '</transition></state><state id="b"/>',
        'id="c" autoforward="true"',
    )
    model = read(
        doc(
            f'<state id="s">{answer}<transition event="e" target="t"/></state>'
            '<state id="t"><transition event="late" target="wrong"/></state><state id="wrong"/>'
        )
    )
    assert walk(model, ["e"]) == ["s{c=a}", "t"]


def test_unreachable_send_targets_raise_error_communication() -> None:
    # onentry of s runs before s's session starts (end of the macro step): #_c is unreachable
    invoked = child('<state id="a"/>', 'id="c"')
    model = read(
        doc(
            f'<state id="s"><onentry><send event="x" target="#_c"/></onentry>{invoked}'
            '<transition event="error.communication" target="err"/></state><state id="err"/>'
        )
    )
    assert model.initial == "err"
    # #_parent of a document nobody invoked
    orphan = read(
        doc(
            '<state id="s"><onentry><send event="x" target="#_parent"/></onentry>'
            '<transition event="error.communication" target="err"/></state><state id="err"/>'
        )
    )
    assert orphan.initial == "err"


def test_finished_child_is_one_state_and_done_invoke_names_the_id() -> None:
    quick = child(
        '<state id="a"><transition event="stop" target="f"/></state><final id="f"/>',
        'id="job" autoforward="true"',
    )
    model = read(
        doc(
            f'<state id="s">{quick}<transition event="done.invoke" target="t"/></state>'
            '<state id="t"/>'
        )
    )
    # 'done.invoke' matches done.invoke.job (prefix); the child's end moves the parent
    assert walk(model, ["stop"]) == ["s{job=a}", "t"]
    stays = read(
        doc(f'<state id="s">{quick}<transition event="go" target="t"/></state><state id="t"/>')
    )
    assert walk(stays, ["stop", "stop", "go"]) == [
        "s{job=a}",
        "s{job=(done)}",
        "s{job=(done)}",
        "t",
    ]


def test_finalize_runs_harmless_content_only() -> None:
    logged = child(
        '<state id="a"><onentry><send event="hi" target="#_parent"/></onentry></state>', 'id="c"'
    ).replace("</invoke>", '<finalize><log expr="1"/></finalize></invoke>')
    model = read(
        doc(f'<state id="s">{logged}<transition event="hi" target="t"/></state><state id="t"/>')
    )
    assert model.initial == "t"
    raising = logged.replace('<log expr="1"/>', '<raise event="boom"/>')
    with pytest.raises(UnsupportedError, match="<finalize> that raises or sends"):
        read(doc(f'<state id="s">{raising}</state>'))


def test_nested_sessions_and_the_state_bound() -> None:
    inner = child(
        '<state id="x"><transition event="flip" target="y"/></state>'
        '<state id="y"><transition event="flip" target="x"/></state>',
        'id="g" autoforward="true"',
    )
    outer = child(f'<state id="m">{inner}</state>', 'id="k" autoforward="true"')
    model = read(doc(f'<state id="s">{outer}</state>'))
    assert walk(model, ["flip", "flip"]) == ["s{k=m{g=x}}", "s{k=m{g=y}}", "s{k=m{g=x}}"]
    with limits.changed(max_states=1):
        with pytest.raises(InputError, match="more than 1 reachable"):
            read(doc(f'<state id="s">{outer}</state>'))
    with limits.changed(max_include_depth=1):
        with pytest.raises(InputError, match="FSMBT_MAX_INCLUDE_DEPTH"):
            read(doc(f'<state id="s">{outer}</state>'))


@pytest.mark.parametrize(
    "invoke, message",
    [
        ('<invoke type="vxml2" src="dialog.vxml#Intro"/>', "(external services) of type 'vxml2'"),
        ('<invoke type="http://www.w3.org/TR/ccxml/" src="x"/>', "(external services)"),
        ('<invoke src="http://example.org/child.scxml"/>', "(external services) at"),
        ('<invoke typeexpr="t" src="x"/>', "typeexpr"),
        ('<invoke srcexpr="s"/>', "srcexpr"),
        (
            '<invoke idlocation="loc"><content><scxml version="1.0"><state id="a"/></scxml>'
            "</content></invoke>",
            "idlocation",
        ),
        ('<invoke><content expr="doc"/></invoke>', "<content expr"),
        (
            '<invoke><content><scxml version="1.0"><state id="a"><transition event="e" '
            'cond="x &gt; 1" target="a"/></state></scxml></content></invoke>',
            "cond guard in an invoked document",
        ),
    ],
)
def test_what_has_no_finite_reading_is_refused_with_its_line(invoke: str, message: str) -> None:
    with pytest.raises(UnsupportedError, match=re.escape(message)) as info:
        read(doc(f'<state id="s">\n{invoke}\n</state>'))
    assert info.value.location is not None and info.value.location.line == 3


@pytest.mark.parametrize(
    "body, message",
    [
        (
            '<state id="s"><invoke src="a.scxml"><content><scxml version="1.0"><state id="a"/>'
            "</scxml></content></invoke></state>",
            "exactly one of src and <content>",
        ),
        ('<state id="s"><invoke><content>text</content></invoke></state>', "one <scxml>"),
        (
            '<state id="s"><invoke autoforward="yes"><content><scxml version="1.0"><state '
            'id="a"/></scxml></content></invoke></state>',
            "autoforward",
        ),
        (
            '<state id="s"><invoke id="c"><content><scxml version="1.0"><state id="a"/></scxml>'
            '</content></invoke><invoke id="c"><content><scxml version="1.0"><state id="a"/>'
            "</scxml></content></invoke></state>",
            "duplicate <invoke> id",
        ),
        (
            '<final id="f"><invoke><content><scxml version="1.0"><state id="a"/></scxml>'
            "</content></invoke></final>",
            "<invoke> in <final>",
        ),
        ('<state id="s"><invoke src="child.scxml"/></state>', "including file's path"),
    ],
)
def test_malformed_invokes_are_input_errors(body: str, message: str) -> None:
    with pytest.raises(InputError, match=re.escape(message)):
        read(doc(body))


def test_send_to_an_unknown_session_id_is_still_refused() -> None:
    with pytest.raises(UnsupportedError, match="no <invoke> of this document"):
        read(doc('<state id="s"><onentry><send event="x" target="#_nobody"/></onentry></state>'))


# -- src files -----------------------------------------------------------------------------------
CHILD_FILE = doc(
    '<state id="c0"><onentry><send event="up" target="#_parent"/></onentry>'
    '<transition event="tick" target="c1"/></state><state id="c1"/>'
)


def test_src_file_next_to_the_document(tmp_path: Path) -> None:
    (tmp_path / "child.scxml").write_text(CHILD_FILE)
    main = tmp_path / "main.scxml"
    main.write_text(
        doc(
            '<state id="wait"><invoke id="kid" src="child.scxml" autoforward="true"/>'
            '<state id="w0"><transition event="up" target="w1"/></state><state id="w1"/>'
            "</state>"
        )
    )
    model = api.load(main).model
    assert isinstance(model, FSM)
    assert walk(model, ["tick"]) == ["wait/w1{kid=c0}", "wait/w1{kid=c1}"]
    outcome = api.convert_file(main, tmp_path / "out.xml")
    assert outcome.equivalent is True, outcome.report


def test_src_files_are_confined_and_cycles_refused(tmp_path: Path) -> None:
    sub = tmp_path / "sub"
    sub.mkdir()
    (tmp_path / "outside.scxml").write_text(CHILD_FILE)
    inner = sub / "main.scxml"
    inner.write_text(doc('<state id="s"><invoke src="../outside.scxml"/></state>'))
    with pytest.raises(InputError, match="outside the folder"):
        api.load(inner)
    (sub / "evil.scxml").symlink_to(tmp_path / "outside.scxml")
    inner.write_text(doc('<state id="s"><invoke src="evil.scxml"/></state>'))
    with pytest.raises(InputError, match="outside the folder"):
        api.load(inner)
    loop = tmp_path / "loop.scxml"
    loop.write_text(doc('<state id="s"><invoke src="loop.scxml"/></state>'))
    with pytest.raises(InputError, match="<invoke src> cycle"):
        api.load(loop)
    missing = tmp_path / "missing.scxml"
    missing.write_text(doc('<state id="s">\n<invoke src="nope.scxml"/></state>'))
    with pytest.raises(InputError, match="does not exist") as info:
        api.load(missing)
    assert info.value.location is not None and info.value.location.line == 3
    fifo = tmp_path / "fifo.scxml"
    os.mkfifo(fifo)
    missing.write_text(doc('<state id="s"><invoke src="fifo.scxml"/></state>'))
    with pytest.raises(InputError, match="not a regular file"):
        api.load(missing)


def test_repeated_invocation_of_files_is_bounded_in_all(tmp_path: Path) -> None:
    for n in range(12):  # each level invokes the next twice: 2**11 documents to read
        body = "".join(f'<state id="s{k}"><invoke src="i{n + 1}.scxml"/></state>' for k in range(2))
        write = body if n < 11 else '<state id="leaf"/>'
        (tmp_path / f"i{n}.scxml").write_text(doc(f'<parallel id="p">{write}</parallel>'))
    with limits.changed(max_input_bytes=50_000):
        with pytest.raises(InputError, match="each <invoke> counted"):
            api.load(tmp_path / "i0.scxml")


def test_error_in_an_invoked_file_names_that_file(tmp_path: Path) -> None:
    (tmp_path / "child.scxml").write_text(
        doc('<state id="a">\n<onentry><foreach array="a" item="i"/></onentry></state>')
    )
    main = tmp_path / "main.scxml"
    main.write_text(doc('<state id="s"><invoke src="child.scxml"/></state>'))
    with pytest.raises(UnsupportedError) as info:
        api.load(main)
    assert "<foreach>" in str(info.value)
    assert info.value.location is not None
    assert info.value.location.file is not None and info.value.location.file.endswith("child.scxml")


def test_corpus_qt_invoke_example_converts_and_verifies(tmp_path: Path) -> None:
    path = CORPUS / "fsm" / "qt_scxml_examples" / "invoke.scxml"
    if not path.is_file():
        pytest.skip(f"corpus not found at {CORPUS} (set FSMBT_CORPUS)")
    outcome = api.convert_file(path, tmp_path / "bt.xml")
    assert outcome.equivalent is True
    model = api.load(path).model
    assert isinstance(model, FSM)
    # the inline child has no autoforward and nobody sends to it: it rests in 'here'
    assert set(model.states) == {"anyplace/nowhere", "anyplace/somewhere{somewhere.1=here}"}


# -- python-statemachine (a W3C engine written by others) ---------------------------------------
PING = doc(
    '<state id="s">'
    + child(
        '<state id="idle"><onentry><send event="ready" target="#_parent"/></onentry>'
        '<transition event="ping" target="busy"><send event="pong" target="#_parent"/>'
        '</transition></state><state id="busy"><transition event="ping" target="idle">'
        '<send event="pang" target="#_parent"/></transition></state>',
        'id="c"',
    )
    + '<state id="s1"><transition event="ready" target="s2"/></state>'
    '<state id="s2"><transition event="poke"><send event="ping" target="#_c"/></transition>'
    '<transition event="pong" target="s3"/></state>'
    '<state id="s3"><transition event="poke"><send event="ping" target="#_c"/></transition>'
    '<transition event="pang" target="s2"/><transition event="out" target="t"/></state>'
    '</state><state id="t"><transition event="back" target="s"/></state>'
)


def _settled(configuration: object, seconds: float = 3.0) -> list[str]:
    """The engine's configuration once it stops changing (children run in threads)."""
    last: list[str] | None = None
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        now = sorted(s.id for s in configuration())  # type: ignore[operator]
        if now == last:
            return now
        last = now
        time.sleep(0.15)
    raise AssertionError("the engine did not settle")


def test_parent_and_child_agree_with_python_statemachine() -> None:
    loader = pytest.importorskip("statemachine.io.loader")
    model = read(PING)
    with contextlib.redirect_stdout(io.StringIO()):
        machine = loader.load(PING, format="scxml")()

    def engine_name() -> str:
        parent = _settled(lambda: machine.configuration)
        # the child machine is reached through the engine's (private) invoke manager
        active = machine._engine._invoke_manager._active
        children = [inv._handler._child for inv in active.values() if inv._handler._child]
        if "t" in parent:
            return "t"
        leaf = [p for p in parent if p != "s"][0]
        running = [c for c in children if not c.is_terminated]
        assert len(running) == 1
        inner = sorted(s.id for s in running[0].configuration)
        return f"s/{leaf}{{c={inner[0]}}}"

    events = ["poke", "poke", "poke", "out", "back", "poke", "poke"]
    expected = walk(model, events)
    seen = [engine_name()]
    for event in events:
        machine.send(event)
        seen.append(engine_name())
    assert seen == expected


def test_departures_of_python_statemachine_from_the_w3c_invoke_rules() -> None:
    """Named so a change of the engine shows (docs/formats/scxml.md, "XInclude and <invoke>"):
    it sends done.invoke when the child has started, and stops autoforwarding then."""
    loader = pytest.importorskip("statemachine.io.loader")
    never_ends = doc(
        '<state id="s">'
        + child(
            '<state id="a"><transition event="never" target="f"/></state><final id="f"/>', 'id="c"'
        )
        + '<transition event="done.invoke.c" target="t"/></state><state id="t"/>'
    )
    assert read(never_ends).initial == "s{c=a}"  # W3C: the child has not ended
    with contextlib.redirect_stdout(io.StringIO()):
        machine = loader.load(never_ends, format="scxml")()
    assert _settled(lambda: machine.configuration) == ["t"]
    toggle = doc(f'<state id="s">{TOGGLE}</state>')
    assert walk(read(toggle), ["goThere"])[-1] == "s{s.1=there}"
    with contextlib.redirect_stdout(io.StringIO()):
        machine = loader.load(toggle, format="scxml")()
    _settled(lambda: machine.configuration)
    machine.send("goThere")
    _settled(lambda: machine.configuration)
    (invocation,) = machine._engine._invoke_manager._active.values()
    assert sorted(s.id for s in invocation._handler._child.configuration) == ["here"]


def test_a_document_that_ends_cancels_its_sessions() -> None:
    model = read(
        doc(
            f'<state id="s">{TOGGLE}<transition event="stop" target="end"/></state>'
            '<final id="end"/>'
        )
    )
    assert walk(model, ["goThere", "stop"]) == ["s{s.1=here}", "s{s.1=there}", "end"]
    assert model.states["end"].final


def test_deep_nesting_is_bounded_without_recursion_errors() -> None:
    from fsmbt.formats.scxml.invoke import MAX_SESSION_DEPTH

    def nested(levels: int) -> str:
        body = (
            '<state id="x"><transition event="flip" target="y"/></state>'
            '<state id="y"><transition event="flip" target="x"/></state>'
        )
        for i in range(levels):
            invoke = child(body, f'id="k{i}" autoforward="true"')
            body = f'<state id="m{i}">{invoke}</state>'
        return doc(body)

    with limits.changed(max_include_depth=10_000):
        deepest = read(nested(MAX_SESSION_DEPTH))
        assert len(deepest.states) == 2  # 'flip' is forwarded down every level
        with pytest.raises(InputError, match=f"bound of {MAX_SESSION_DEPTH} nested sessions"):
            read(nested(MAX_SESSION_DEPTH + 1))
