"""Bad input through the real CLI: every case exits 2 with a one-line cause, fast, no traceback.

Each case writes a file (or a directory, or nothing) under tmp_path and runs
``python -m fsmbt.cli validate FILE`` as a subprocess, as a user would.
"""

from __future__ import annotations

import json
import os
import re
import resource
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pytest

#: A guard against hangs and blow-ups (a 100 000-deep file parsed recursively, a billion-laughs
#: expansion), not a speed target: those take minutes or never end. A normal refusal takes about
#: 1 s, most of it the interpreter's start; speed figures belong in benchmarks/, which print them.
TIME_LIMIT_S = 10.0
DEEP = 100_000
BT_HEAD = '<root BTCPP_format="4" main_tree_to_execute="T"><BehaviorTree ID="T">'
BT_TAIL = "</BehaviorTree></root>"


@dataclass(frozen=True)
class Case:
    name: str
    filename: str
    make: Callable[[Path], None]  # writes the input at the given path
    cause: str  # regex the one-line error must contain (case-insensitive)


def text(content: str) -> Callable[[Path], None]:
    return lambda path: path.write_text(content, encoding="utf-8")


def raw(content: bytes) -> Callable[[Path], None]:
    return lambda path: path.write_bytes(content)


def sparse(size: int) -> Callable[[Path], None]:
    def make(path: Path) -> None:
        with path.open("wb") as stream:
            stream.truncate(size)  # a hole: claims the size without using the disk

    return make


BILLION_LAUGHS = """<?xml version="1.0"?>
<!DOCTYPE lolz [
 <!ENTITY lol "lol">
 <!ENTITY lol2 "&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;">
 <!ENTITY lol3 "&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;">
 <!ENTITY lol4 "&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;">
 <!ENTITY lol5 "&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;">
 <!ENTITY lol6 "&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;">
 <!ENTITY lol7 "&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;">
 <!ENTITY lol8 "&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;">
 <!ENTITY lol9 "&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;">
]>
<root BTCPP_format="4"><BehaviorTree ID="T"><Action ID="&lol9;"/></BehaviorTree></root>
"""

XXE = """<?xml version="1.0"?>
<!DOCTYPE root [<!ENTITY xxe SYSTEM "file:///etc/passwd">]>
<root BTCPP_format="4"><BehaviorTree ID="T"><Action ID="&xxe;"/></BehaviorTree></root>
"""

HUGE_DOCTYPE = """<?xml version="1.0"?>
<!DOCTYPE root [<!ENTITY huge SYSTEM "file:///dev/zero">]>
<root BTCPP_format="4"><BehaviorTree ID="T"><Action ID="&huge;"/></BehaviorTree></root>
"""

YAML_ALIAS_BOMB = (
    "\n".join(
        ["kind: bt", "a0: &a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol]"]
        + [f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 9) + "]" for i in range(1, 10)]
        + ["trees: [{id: T, root: {type: A, attrs: {x: *a9}}}]"]
    )
    + "\n"
)

FSM_JSON_UNKNOWN_TARGET = json.dumps(
    {
        "kind": "fsm",
        "name": "m",
        "initial": "A",
        "states": [{"name": "A"}, {"name": "B"}],
        "transitions": [{"source": "A", "event": "go", "target": "Nowhere"}],
    }
)


def deep_json() -> str:
    node = '{"type": "A", "kind": "Action"}'
    opening = '{"type": "Inverter", "kind": "Decorator", "children": ['
    return (
        '{"kind": "bt", "main_tree": "T", "trees": [{"id": "T", "root": '
        + opening * DEEP
        + node
        + "]}" * DEEP
        + "}]}"
    )


def deep_yaml() -> str:
    opening = "{type: Inverter, kind: Decorator, children: ["
    return "kind: bt\ntrees:\n- id: T\n  root: " + opening * DEEP + "{type: A}" + "]}" * DEEP + "\n"


CASES = [
    Case(
        "broken_xml",
        "broken.xml",
        text(BT_HEAD + "<Sequence><AlwaysSuccess/></BehaviorTree></root>"),
        r"xml|mismatch|well-formed|tag",
    ),
    Case("entity_bomb", "bomb.xml", text(BILLION_LAUGHS), r"entit|DTD|DOCTYPE"),
    Case("external_entity", "xxe.xml", text(XXE), r"entit|DTD|DOCTYPE"),
    Case(
        "doctype_claims_huge_content", "huge_doctype.xml", text(HUGE_DOCTYPE), r"entit|DTD|DOCTYPE"
    ),
    Case(
        "deep_xml",
        "deep.xml",
        text(BT_HEAD + "<Inverter>" * DEEP + "<AlwaysSuccess/>" + "</Inverter>" * DEEP + BT_TAIL),
        r"deep|depth|nest",
    ),
    Case("deep_json", "deep.json", text(deep_json()), r"deep|depth|nest"),
    Case("deep_yaml", "deep.yaml", text(deep_yaml()), r"deep|depth|nest"),
    Case(
        "unknown_node_with_children",
        "unknown.xml",
        text(BT_HEAD + "<Frobnicate><AlwaysSuccess/></Frobnicate>" + BT_TAIL),
        r"Frobnicate",
    ),
    Case(
        "nondeterministic_fsm",
        "nd.csv",
        text("source,event,target\nA,go,B\nA,go,C\nB,back,A\n"),
        r"nondeterministic",
    ),
    Case(
        "transition_to_unknown_state",
        "unknown_target.json",
        text(FSM_JSON_UNKNOWN_TARGET),
        r"Nowhere",
    ),
    Case("empty_file", "empty.json", text(""), r"empty"),
    Case("whitespace_only", "blank.xml", text("  \n\t\n   \n"), r"empty"),
    Case(
        "binary_garbage",
        "garbage.json",
        raw(b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR" + bytes(range(256)) * 4),
        r"binary",
    ),
    Case(
        "random_bytes_with_nul",
        "random.xml",
        raw(bytes((i * 7919 + 13) % 256 for i in range(4096)) + b"\x00"),
        r"binary",
    ),
    Case(
        "latin1_bytes",
        "latin1.csv",
        raw("source,event,target\nA,café,B\n".encode("latin-1")),
        r"UTF-8",
    ),
    Case(
        "utf16_without_bom",
        "utf16.csv",
        raw("source,event,target\nA,go,B\n".encode("utf-16-le")),
        r"UTF-16",
    ),
    Case("sparse_2GB_file", "huge.json", sparse(2 * 1024**3), r"limit|bytes|too large"),
    Case("yaml_alias_bomb", "bomb.yaml", text(YAML_ALIAS_BOMB), r"alias"),
    Case(
        "json_wrong_types",
        "types.json",
        text('{"kind": "fsm", "states": "A", "transitions": 5}'),
        r"expected a list",
    ),
    Case("json_syntax_error", "syntax.json", text('{"kind": "fsm", "states": [}'), r"invalid JSON"),
    Case("directory_instead_of_file", "adir", lambda path: path.mkdir(), r"directory"),
    Case("missing_file", "does_not_exist.xml", lambda path: None, r"no such file|cannot read"),
    Case(
        "subtree_to_missing_tree",
        "subtree.xml",
        text(BT_HEAD + '<Sequence><SubTree ID="Nowhere"/></Sequence>' + BT_TAIL),
        r"Nowhere",
    ),
    Case(
        "decorator_with_two_children",
        "decorator.xml",
        text(BT_HEAD + "<Inverter><AlwaysSuccess/><AlwaysFailure/></Inverter>" + BT_TAIL),
        r"one child",
    ),
    Case(
        "control_without_children",
        "control.xml",
        text(BT_HEAD + "<Sequence/>" + BT_TAIL),
        r"no children|child",
    ),
    Case("csv_missing_columns", "cols.csv", text("source,event\nA,go\n"), r"column"),
    Case(
        "mermaid_garbage",
        "garbage.mmd",
        text("stateDiagram-v2\n  A ==> B ??? !!\n"),
        r"cannot read",
    ),
    Case(
        "mermaid_fork",
        "fork.mmd",
        text("stateDiagram-v2\n  state F <<fork>>\n"),
        r"unsupported.*fork",
    ),
    Case("dot_undirected", "graph.dot", text("graph G { a -- b }\n"), r"undirected"),
    Case("unknown_format", "notes.dat", text("just some words, not a model\n"), r"format|cannot"),
]


def run_validate(target: Path) -> tuple[subprocess.CompletedProcess[str], float, float]:
    """Run the CLI; returns the result, wall-clock seconds and the child's CPU seconds."""
    env = dict(os.environ)
    env.pop("FSMBT_DEBUG", None)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.monotonic()
    result = subprocess.run(
        [sys.executable, "-m", "fsmbt.cli", "validate", str(target)],
        capture_output=True,
        text=True,
        timeout=10,
        env=env,
        cwd=target.parent,
    )
    elapsed = time.monotonic() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return result, elapsed, cpu


def wall_limit() -> float:
    """The hang guard in wall time, stretched only when the machine is oversubscribed (CI shares
    cores with other jobs): a run that got a fraction of a core takes longer in wall time. The
    CPU time the process used is held to the plain limit in every case."""
    cores = os.cpu_count() or 1
    load = os.getloadavg()[0]
    return TIME_LIMIT_S * max(1.0, load / cores)


def test_there_are_at_least_twenty_kinds() -> None:
    assert len({c.name for c in CASES}) >= 20


@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_bad_input_fails_cleanly(case: Case, tmp_path: Path) -> None:
    target = tmp_path / case.filename
    case.make(target)
    result, elapsed, cpu = run_validate(target)
    stderr_lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert result.returncode == 2, (result.returncode, result.stderr[-2000:])
    assert "Traceback" not in result.stderr
    assert len(stderr_lines) == 1, result.stderr[-2000:]
    assert re.search(case.cause, stderr_lines[0], re.IGNORECASE), stderr_lines[0]
    assert cpu < TIME_LIMIT_S, f"used {cpu:.2f} s of CPU"
    limit = wall_limit()
    assert elapsed < limit, f"took {elapsed:.2f} s (limit {limit:.1f} s at this load)"


def test_valid_input_passes(tmp_path: Path) -> None:
    """The same command accepts a good model, so the failures above are about the input."""
    target = tmp_path / "good.csv"
    target.write_text("source,event,target\nA,go,B\nB,back,A\nB,stop,C\n", encoding="utf-8")
    result, _, _ = run_validate(target)
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""
