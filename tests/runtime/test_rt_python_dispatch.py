"""The Python runtime runs dispatch trees (issue 23: docs/semantics.md section 12, the form
``--style auto`` writes for an event-driven machine), through the checker's own macro steps.

- differential: random event-driven FSMs (and HFSMs: the hierarchical form, §12a) converted with
  ``--style auto`` (asserted to be the dispatch form), written as XML and loaded from the text,
  run by ``load_tree`` with one recording callable per action: after the start and every event
  of seeded random walks the callables really called (action, state label, params), the
  runner's state and its termination equal the FSM's;
- a ``params`` port reaches the callable as a dict; entries without action call nothing;
- load-time errors (one located ``InputError``): an engine that cannot run the form, a leaf
  other than ``DispatchEntry``, a ``DispatchEntry`` without ``state``, a malformed ``params``,
  an action without callable.
"""

from __future__ import annotations

import random
import re

import pytest
from lxml import etree

from fsmbt.convert import convert
from fsmbt.formats import dumps, loads
from fsmbt.generate import random_fsm
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.runtime.python_runtime import DISPATCH_ENGINES, ENGINES, load_tree
from fsmbt.semantics.execution import Flavour, flavour_of
from fsmbt.semantics.machine import FINAL, FSMMachine

FSMS = 40
HFSMS = 12
SEQUENCES = 4
LENGTH = 25


def dispatch_text(fsm: FSM) -> str:
    model = convert(fsm, style="auto").model
    assert flavour_of(model) is Flavour.DISPATCH, "auto writes the dispatch form"
    return dumps(model, "btcpp")


class Recorder:
    """One callable per action; ``calls`` holds (action, state label, params) as called."""

    def __init__(self, names: set[str]) -> None:
        self.calls: list[tuple[str, str, dict[str, str]]] = []
        self.actions = {name: self._make(name) for name in names}

    def _make(self, name: str):
        return lambda state, params: self.calls.append((name, state, params))


def differences(fsm: FSM, text: str, rng: random.Random) -> list[str]:
    machine = FSMMachine(fsm)
    actions = {s.action for s in machine.fsm.states.values() if s.action is not None}
    alphabet = [*machine.alphabet, "__not_an_event__"]
    problems: list[str] = []
    for _ in range(SEQUENCES):
        recorder = Recorder(actions)
        runner = load_tree(text, recorder.actions, allow_unused=True)
        assert runner.engine == "fsmbt"
        state, outputs = machine.start()
        ran = runner.start()
        events: list[str] = []
        for k in range(LENGTH + 1):
            # the callables' states are the states entered, in order, with their actions
            want_calls = [(a, state, {}) for a in outputs]
            want_state = runner.start_state if state == machine.start_state else state
            got = (recorder.calls, ran, runner.state, runner.terminated)
            want = (want_calls, outputs, want_state, machine.status(state) == FINAL)
            if got != want:
                problems.append(f"after {events}: runtime {got}, FSM {want}")
                break
            if k == LENGTH:
                break
            active = list(machine.active_inputs(state))
            event = rng.choice(active) if active and rng.random() < 0.8 else rng.choice(alphabet)
            events.append(event)
            recorder.calls.clear()
            state, outputs = machine.step(state, event)
            ran = runner.post(event)
    return problems


def test_generated_event_driven_machines_run_like_the_fsm() -> None:
    from support.conv_hfsm_gen import random_hfsm

    rng = random.Random(23)
    models: list[tuple[str, FSM]] = []
    for i in range(FSMS):
        shape = ("tree", "chain", "loop", "mixed")[i % 4]
        models.append((f"fsm{i}", random_fsm(seed=2300 + i, max_states=25, shape=shape)))
    models += [(f"hfsm{i}", random_hfsm(2300 + i)) for i in range(HFSMS)]
    compared, problems = 0, {}
    for name, fsm in models:
        try:
            text = dispatch_text(fsm)
        except (AssertionError, UnsupportedError):
            continue  # auto wrote the LEBT (a reason it names); not this test's subject
        compared += 1
        if found := differences(fsm, text, rng):
            problems[name] = found[:2]
    assert not problems, problems
    assert compared >= FSMS  # most generated machines get the dispatch form


def door_text() -> str:
    fsm = random_fsm(seed=7, n_states=6, shape="chain", start_event=False)
    return dispatch_text(fsm)


def test_an_entry_without_action_enters_its_state_silently() -> None:
    fsm = random_fsm(seed=12, n_states=4, shape="chain", start_event=False)
    root = etree.fromstring(dispatch_text(fsm).encode())
    initial = next(e for e in root.iter("DispatchEntry") if e.get("state") == fsm.initial)
    initial.set("action", "")
    recorder = Recorder({e.get("action") for e in root.iter("DispatchEntry") if e.get("action")})
    runner = load_tree(etree.tostring(root, encoding="unicode"), recorder.actions)
    assert runner.start() == () and recorder.calls == []
    assert runner.state == fsm.initial


def test_params_of_the_initial_state() -> None:
    fsm = random_fsm(seed=11, n_states=4, shape="chain", start_event=False)
    root = etree.fromstring(dispatch_text(fsm).encode())
    assert fsm.initial is not None
    initial = next(e for e in root.iter("DispatchEntry") if e.get("state") == fsm.initial)
    initial.set("params", "text=hello \\; world;n=1")
    recorder = Recorder({e.get("action") for e in root.iter("DispatchEntry") if e.get("action")})
    runner = load_tree(etree.tostring(root, encoding="unicode"), recorder.actions)
    runner.start()
    assert recorder.calls == [
        (initial.get("action"), fsm.initial, {"text": "hello ; world", "n": "1"})
    ]
    assert runner.state == fsm.initial


def located(text: str, needle: str) -> int:
    return next(i for i, t in enumerate(text.splitlines(), 1) if needle in t)


def test_load_errors_are_located() -> None:
    text = door_text()
    doc = loads(text, "btcpp")
    actions = {n.attrs["action"] for _t, n in doc.nodes() if n.type == "DispatchEntry"}
    for engine in ENGINES:
        with pytest.raises(InputError, match=f"runs on fsmbt, not on '{engine}'"):
            load_tree(text, {}, engine=engine, allow_unused=True)
    assert DISPATCH_ENGINES == ("fsmbt",)
    with pytest.raises(InputError, match="unknown engine 'ros'"):
        load_tree(text, {}, engine="ros")
    missing = sorted(actions)[0]
    with pytest.raises(InputError, match=f"no callable for the action.*'{missing}'"):
        load_tree(text, {a: print for a in actions if a != missing})
    for attribute, value, message in [
        ("state", "", "no 'state' port"),
        ("params", "novalue", "port 'params'"),
    ]:
        root = etree.fromstring(text.encode())
        root.find(".//DispatchEntry").set(attribute, value)
        bad = etree.tostring(root, pretty_print=True, encoding="unicode")
        with pytest.raises(InputError, match=message) as info:
            load_tree(bad, {a: print for a in actions})
        assert info.value.location is not None
        assert info.value.location.line == located(bad, "<DispatchEntry")
    root = etree.fromstring(text.encode())
    entry = root.find(".//DispatchEntry")
    entry.tag = "MoveBase"
    bad = etree.tostring(root, pretty_print=True, encoding="unicode")
    with pytest.raises(InputError, match="DispatchEntry") as info:
        load_tree(bad, {a: print for a in actions}, allow_unused=True)
    assert info.value.location is not None
    assert info.value.location.line == located(bad, "<MoveBase")


#: Hand edits of a dispatch tree the load check refuses (docs/semantics.md section 12, "Checked
#: at load time"): (what, a function of the text giving the broken text and the line of the
#: edited element, the message).
def _retarget(text: str, old: str, new: str) -> tuple[str, str]:
    """Replace the first ``_onSuccess="old"`` whose leaf is not the start transition."""
    at = text.index(f'_onSuccess="{old}"', text.index("_events"))
    line_start = text.rindex("\n", 0, at) + 1
    fragment = text[line_start : text.index("\n", at)].strip()
    broken = text[:at] + f'_onSuccess="{new}"' + text[at + len(f'_onSuccess="{old}"') :]
    return broken, fragment.replace(old, new)


def test_broken_index_annotations_are_located_load_errors() -> None:
    fsm = random_fsm(seed=3, n_states=60, shape="tree", start_event=False)
    text = dispatch_text(fsm)
    doc = loads(text, "btcpp")
    actions = {n.attrs["action"]: print for _t, n in doc.nodes() if n.type == "DispatchEntry"}
    load_tree(text, actions)  # as written: accepted
    first = re.search(r"_onSuccess=\"(fsm_d0:='([a-g])')\"", text[text.index("_events") :])
    assert first is not None
    old, digit = first.group(1), first.group(2)
    unused = next(d for d in "abcdefg" if d != digit)
    cases = [
        ("fsm_d2:='g'", "which no state has"),  # 60 states: d2 is 'a' or 'b'
        (f"fsm_d0:='{unused}'; fsm_d1:='g'", "but writes the state index .* of "),
        ("fsm_d0:='h'", "malformed index digit 'h'"),
        ("fsm_d7:='a'", "no Switch reads that digit"),
        ("fsm_dx:='a'", "no state index digit"),
    ]
    for new, message in cases:
        broken, fragment = _retarget(text, old, new)
        with pytest.raises(InputError, match=message) as info:
            load_tree(broken, actions)
        assert info.value.location is not None
        line = located(broken, fragment)
        # the edited leaf is the one named (or, for one index two states, one of the two)
        assert info.value.location.line == line or f"line {line})" in str(info.value), new
    # the start transition writes one digit of two
    start = re.search(r"name=\"start\">\s*<DispatchEntry [^>]*_onSuccess=\"([^\"]*)\"", text)
    assert start is not None and ";" in start.group(1)
    broken = text.replace(start.group(1), start.group(1).split(";")[0], 1)
    with pytest.raises(InputError, match="from the start, _onSuccess leaves fsm_d1 unset"):
        load_tree(broken, actions)
    # an index switch case that is no digit
    broken = re.sub(r'(<Switch\d name="dispatch"[^>]*case_1=)"a"', r'\1"q"', text, count=1)
    assert broken != text
    with pytest.raises(InputError, match="case_1 is the malformed index digit 'q'") as info:
        load_tree(broken, actions)
    assert info.value.location is not None and info.value.location.line == located(
        broken, 'name="dispatch"'
    )


def test_dispatch_leaves_without_an_index_are_refused() -> None:
    tree = (
        '<root BTCPP_format="4"><BehaviorTree ID="M">\n<KeepRunningUntilFailure>\n'
        '<DispatchEntry name="A" state="A" action="a"/>\n</KeepRunningUntilFailure>\n'
        "</BehaviorTree></root>"
    )
    with pytest.raises(InputError, match="no Switch reads a state index digit") as info:
        load_tree(tree, {"a": print})
    assert info.value.location is not None and info.value.location.line == 3
