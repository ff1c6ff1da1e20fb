"""XInclude in SCXML (fsmbt.formats.scxml.include): the included document reads like the same
document written inline by hand (the model is compared, and the hand-inlined text is run by
python-statemachine's SCXML engine, a W3C engine written by others), and every way out of the
confinement rule of docs/security.md is refused with the include's line.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
from pathlib import Path

import pytest

from fsmbt import api, limits
from fsmbt.formats import loads
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.flatten import flatten
from fsmbt.model.fsm import FSM

XI = 'xmlns:xi="http://www.w3.org/2001/XInclude"'
NS = 'xmlns="http://www.w3.org/2005/07/scxml"'

# Main.scxml of the W3C examples, in small: a compound state whose first child comes from a
# fragment file whose root is <state> (written without xmlns, as that example's fragment is)
FRAGMENT = """<state id="Sub1">
  <onentry><log expr="'in Sub1'"/></onentry>
  <transition event="Event2" target="Sub2"/>
</state>"""
MAIN = f"""<scxml {NS} {XI} version="1.0" initial="Test2">
  <state id="Test2">
    <initial><transition target="Sub1"/></initial>
    <xi:include href="{{href}}"/>
    <final id="Sub2"/>
    <transition event="done.state.Test2" target="Test3"/>
  </state>
  <state id="Test3"><transition event="again" target="Test2"/></state>
</scxml>"""
INLINE = MAIN.replace('<xi:include href="{href}"/>', FRAGMENT.replace("<state ", f"<state {NS} "))


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def model_of(path: Path) -> FSM:
    model = api.load(path).model
    assert isinstance(model, FSM)
    return model


def configurations(model: FSM, events: list[str]) -> list[str]:
    flat = flatten(model)
    step = {(t.source, t.event): t.target for t in flat.transitions}
    state = flat.initial or ""
    seen = [state]
    for event in events:
        state = step.get((state, event), state)
        seen.append(state)
    return seen


EVENTS = ["Event2", "again", "Event2", "nothing", "again"]


def test_included_fragment_reads_as_the_hand_inlined_document(tmp_path: Path) -> None:
    write(tmp_path, "Test2Sub1.scxml", FRAGMENT)
    main = write(tmp_path, "Main.scxml", MAIN.format(href="Test2Sub1.scxml"))
    inline = write(tmp_path, "inline.scxml", INLINE)
    loaded = api.load(main)
    assert isinstance(loaded.model, FSM)
    assert configurations(loaded.model, EVENTS) == configurations(model_of(inline), EVENTS)
    assert configurations(loaded.model, EVENTS) == [
        "Test2/Sub1",
        "Test3",
        "Test2/Sub1",
        "Test3",
        "Test3",
        "Test2/Sub1",
    ]
    assert any("without a namespace are read in the SCXML namespace" in w for w in loaded.warnings)
    # an independent reading of the hand-inlined text: python-statemachine's engine
    loader = pytest.importorskip("statemachine.io.loader")
    with contextlib.redirect_stdout(io.StringIO()):
        machine = loader.load(INLINE, format="scxml")()
    engine = [sorted(s.id for s in machine.configuration)]
    for event in EVENTS:
        with contextlib.redirect_stdout(io.StringIO()):
            machine.send(event)
        engine.append(sorted(s.id for s in machine.configuration))
    ours = [sorted(c.split("/")) for c in configurations(loaded.model, EVENTS)]
    assert engine == ours


def test_nested_includes_resolve_relative_to_the_including_file(tmp_path: Path) -> None:
    write(
        tmp_path,
        "parts/outer.scxml",
        f'<state {NS} {XI} id="Sub1"><xi:include href="deeper/inner.scxml"/>'
        '<transition event="Event2" target="Sub2"/></state>',
    )
    write(tmp_path, "parts/deeper/inner.scxml", f'<state {NS} id="leaf"/>')
    main = write(tmp_path, "Main.scxml", MAIN.format(href="parts/outer.scxml"))
    assert configurations(model_of(main), ["Event2"]) == ["Test2/Sub1/leaf", "Test3"]


def test_fallback_is_used_when_the_file_is_missing(tmp_path: Path) -> None:
    text = MAIN.format(href="gone.scxml").replace(
        '<xi:include href="gone.scxml"/>',
        '<xi:include href="gone.scxml"><xi:fallback><state id="Sub1">'
        '<transition event="Event2" target="Sub2"/></state></xi:fallback></xi:include>',
    )
    loaded = api.load(write(tmp_path, "Main.scxml", text))
    assert isinstance(loaded.model, FSM)
    assert configurations(loaded.model, ["Event2"]) == ["Test2/Sub1", "Test3"]
    assert any("<xi:fallback> is used" in w for w in loaded.warnings)


def line_of_include(text: str) -> int:
    return next(n for n, line in enumerate(text.splitlines(), 1) if "xi:include" in line)


@pytest.mark.parametrize(
    "href, message",
    [
        ("../outside.scxml", "outside the folder"),
        ("/etc/passwd", "outside the folder"),
        ("missing.scxml", "does not exist"),
        ("http://example.org/x.scxml", "a URL"),
        ("part.scxml#frag", "fragment identifier"),
        ("self.scxml", "include cycle"),
    ],
)
def test_bad_includes_are_refused_with_the_include_line(
    tmp_path: Path, href: str, message: str
) -> None:
    folder = tmp_path / "models"
    write(tmp_path, "outside.scxml", FRAGMENT)
    text = MAIN.format(href=href)
    main = write(folder, "self.scxml" if href == "self.scxml" else "Main.scxml", text)
    with pytest.raises(InputError, match=re.escape(message)) as info:
        api.load(main)
    assert info.value.location is not None
    assert info.value.location.line == line_of_include(text)


def test_symlink_out_of_the_folder_fifo_and_cycles_through_two_files(tmp_path: Path) -> None:
    folder = tmp_path / "models"
    write(tmp_path, "secret.scxml", FRAGMENT)
    folder.mkdir()
    (folder / "link.scxml").symlink_to(tmp_path / "secret.scxml")
    with pytest.raises(InputError, match="outside the folder"):
        api.load(write(folder, "Main.scxml", MAIN.format(href="link.scxml")))
    os.mkfifo(folder / "pipe.scxml")
    with pytest.raises(InputError, match="not a regular file"):
        api.load(write(folder, "Main.scxml", MAIN.format(href="pipe.scxml")))
    write(folder, "a.scxml", f'<state {NS} {XI} id="Sub1"><xi:include href="b.scxml"/></state>')
    write(folder, "b.scxml", f'<state {NS} {XI} id="x"><xi:include href="a.scxml"/></state>')
    with pytest.raises(InputError, match=r"include cycle: .*a\.scxml -> .*b\.scxml -> .*a\.scxml"):
        api.load(write(folder, "Main.scxml", MAIN.format(href="a.scxml")))
    # the include_root option widens the folder, as for BehaviorTree.CPP includes
    sub = write(folder / "sub", "Main.scxml", MAIN.format(href="../../secret.scxml"))
    loaded = api.load(sub, options={"include_root": str(tmp_path)})
    assert isinstance(loaded.model, FSM)


def test_limits_and_hostile_xml_hold_for_included_files(tmp_path: Path) -> None:
    for n in range(4):  # chain0 includes chain1 includes ... chain3
        inner = f'<xi:include href="chain{n + 1}.scxml"/>' if n < 3 else ""
        write(tmp_path, f"chain{n}.scxml", f'<state {NS} {XI} id="c{n}">{inner}</state>')
    main = write(tmp_path, "Main.scxml", MAIN.format(href="chain0.scxml").replace("Sub1", "c0", 1))
    with limits.changed(max_include_depth=3):
        with pytest.raises(InputError, match="FSMBT_MAX_INCLUDE_DEPTH"):
            api.load(main)
    write(tmp_path, "big.scxml", FRAGMENT + " " * 5000)
    big = write(tmp_path, "Main.scxml", MAIN.format(href="big.scxml"))
    with limits.changed(max_input_bytes=len(big.read_text()) + 10):
        with pytest.raises(InputError, match="FSMBT_MAX_INPUT_BYTES"):
            api.load(big)
    # repeated inclusion doubles per level: the expanded total is bounded, not only each file
    for n in range(12):
        inner = f'<xi:include href="d{n + 1}.scxml"/>' * 2 if n < 11 else ""
        write(tmp_path, f"d{n}.scxml", f'<state {NS} {XI} id="d{n}">{inner}</state>')
    double = write(tmp_path, "Main.scxml", MAIN.format(href="d0.scxml").replace("Sub1", "d0", 1))
    with limits.changed(max_input_bytes=100_000):
        with pytest.raises(InputError, match="each inclusion counted"):
            api.load(double)
    write(
        tmp_path,
        "evil.scxml",
        '<!DOCTYPE s [<!ENTITY a "aaaa"><!ENTITY b "&a;&a;&a;">]><state id="Sub1">&b;</state>',
    )
    with pytest.raises(InputError, match="DOCTYPE declares entities"):
        api.load(write(tmp_path, "Main.scxml", MAIN.format(href="evil.scxml")))
    write(tmp_path, "broken.scxml", "<state id='Sub1'>")
    with pytest.raises(InputError, match=r"malformed XML") as info:
        api.load(write(tmp_path, "Main.scxml", MAIN.format(href="broken.scxml")))
    assert info.value.location is not None and str(info.value.location.file).endswith(
        "broken.scxml"
    )


def test_unsupported_forms_and_errors_in_included_content(tmp_path: Path) -> None:
    text = MAIN.format(href="Test2Sub1.scxml")
    write(tmp_path, "Test2Sub1.scxml", FRAGMENT)
    for change, message in [
        ('parse="text"', 'parse="text"'),
        ('xpointer="x"', "xpointer"),
        ('parse="html"', 'parse="html"'),
    ]:
        variant = text.replace("<xi:include ", f"<xi:include {change} ")
        with pytest.raises(InputError, match=re.escape(message)):
            api.load(write(tmp_path, "Main.scxml", variant))
    with pytest.raises(UnsupportedError, match="XInclude"):
        api.load(
            write(tmp_path, "Main.scxml", text.replace("<xi:include ", '<xi:include parse="text" '))
        )
    # a mistake inside the included content is located at the include and names the file
    write(tmp_path, "dup.scxml", '<state id="Test3"/>')
    with pytest.raises(InputError, match=r"duplicate state id.*included from '.*dup\.scxml'"):
        api.load(write(tmp_path, "Main.scxml", MAIN.format(href="dup.scxml")))
    with pytest.raises(InputError, match="needs the including file's path"):
        loads(text, "scxml")
    with pytest.raises(InputError, match="outside an <xi:include>"):
        loads(f'<scxml {NS} {XI} version="1.0"><state id="a"/><xi:fallback/></scxml>', "scxml")


def test_invoke_src_in_included_content_resolves_against_the_fragment(tmp_path: Path) -> None:
    kid = f'<scxml {NS} version="1.0"><state id="k0"><transition event="go" target="k1"/>'
    write(tmp_path, "parts/kid.scxml", kid + '</state><state id="k1"/></scxml>')
    write(
        tmp_path,
        "parts/frag.scxml",
        f'<state {NS} id="Sub1"><invoke id="kid" src="kid.scxml" autoforward="true"/>'
        '<transition event="Event2" target="Sub2"/></state>',
    )
    main = write(tmp_path, "Main.scxml", MAIN.format(href="parts/frag.scxml"))
    assert configurations(model_of(main), ["go", "Event2"]) == [
        "Test2/Sub1{kid=k0}",
        "Test2/Sub1{kid=k1}",
        "Test3",
    ]
    # an error in the invoked file is located there, not at the include
    write(
        tmp_path,
        "parts/kid.scxml",
        kid.replace("<state", "\n<state")
        + '<onentry><foreach array="a" item="i"/></onentry></state><state id="k1"/></scxml>',
    )
    with pytest.raises(UnsupportedError, match="<foreach>") as info:
        api.load(main)
    assert info.value.location is not None
    assert str(info.value.location.file).endswith("kid.scxml")
    assert "included from" not in str(info.value)
