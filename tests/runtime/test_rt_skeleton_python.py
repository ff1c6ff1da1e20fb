"""The Python skeleton (``fsmbt runtime python DIR MODEL``) run in py_trees 2.6.

The skeleton of a tree declaring six leaf types gets, in place of the user's classes, classes
returning scripted outcomes by label (tests/support/skeleton_script). 80 seeded random trees
over the controls the Python skeleton runs (Sequence, Fallback, their reactive forms,
Inverter, ForceSuccess, ForceFailure, RetryUntilSuccessful, Repeat, SubTree) get their
generated ``create_tree`` module; one Python process builds and ticks each and prints every
leaf tick, which must be fsmbt's interpreter's trace tick by tick (a py_trees tick is
BehaviorTree.CPP's ``tickExactlyOnce()``). The example's skeleton runs unchanged through its
``main.py``: the default classes print the leaf's label and parameters.
"""

from __future__ import annotations

import os
import random
import re
import subprocess
import sys
from pathlib import Path

from fsmbt import api
from fsmbt.cli import main
from fsmbt.runtime.skeleton.leaves import leaf_kinds
from fsmbt.runtime.skeleton.python import tree_statements
from fsmbt.runtime.skeleton.render import render
from fsmbt.semantics.bt_interpreter import BTLivelock
from support import skeleton_script
from support.random_trees import PYTREES_CONTROLS, PYTREES_DECORATORS, random_tree

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "examples" / "pick_place_bt.xml"
TREES = 80
TICKS = 12
DECORATORS = (*PYTREES_DECORATORS, "Repeat", "RetryUntilSuccessful", "SubTree")

UNION = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence>
      <Act0 name="a0" speed="2"/><Act1 name="a1"/><Act2 name="a2" goal="{goal}"/>
      <Cond0 name="c0"/><Cond1 name="c1"/><Cond2 name="c2"/>
    </Sequence>
  </BehaviorTree>
  <TreeNodesModel>
    <Action ID="Act0"><input_port name="speed" default="1.5"/></Action>
    <Condition ID="Cond0"/><Condition ID="Cond1"/><Condition ID="Cond2"/>
  </TreeNodesModel>
</root>
"""
SCRIPTED = '''"""The test's stand-in for the user's code: outcomes by label from a script file."""

from py_trees.common import Status

PLANS: dict[str, list[str]] = {}
NEXT: dict[str, int] = {}


def load(path: str) -> None:
    PLANS.clear()
    NEXT.clear()
    with open(path, encoding="utf-8") as lines:
        for line in lines:
            label, *outcomes = line.split()
            PLANS[label] = outcomes


def scripted(label: str) -> Status:
    index = NEXT.get(label, 0)
    NEXT[label] = index + 1
    plan = PLANS[label]
    outcome = plan[index % len(plan)]
    print(f"leaf {label} {outcome}")
    return {"success": Status.SUCCESS, "failure": Status.FAILURE}.get(outcome, Status.RUNNING)
'''
ACTION = """from generated.bases import {name}Base
from nodes.scripted import scripted


class {name}({name}Base):
    def on_start(self):
        return scripted(self.label)

    def on_running(self):
        return scripted(self.label)
"""
CONDITION = """from generated.bases import {name}Base
from nodes.scripted import scripted


class {name}({name}Base):
    def on_tick(self):
        return scripted(self.label)
"""
RUNNER = """import importlib
import sys

from py_trees.common import Status

from nodes import scripted

for seed in sys.argv[2:]:
    scripted.load(f"{sys.argv[1]}/script{seed}.txt")
    root = importlib.import_module(f"generated.tree_{seed}").create_tree()
    print(f"=== {seed}")
    for tick in range(1, TICKS + 1):
        root.tick_once()
        print(f"tick {tick}: {root.status.name}")
        if root.status != Status.RUNNING:
            break
"""


def test_generated_python_runs_random_trees_like_the_interpreter(tmp_path: Path) -> None:
    model = tmp_path / "union.xml"
    model.write_text(UNION, encoding="utf-8")
    project = tmp_path / "project"
    assert main(["runtime", "python", str(project), str(model)]) == 0
    (project / "nodes" / "scripted.py").write_text(SCRIPTED, encoding="utf-8")
    for name in ("Act0", "Act1", "Act2", "Cond0", "Cond1", "Cond2"):
        text = (CONDITION if name.startswith("Cond") else ACTION).format(name=name)
        (project / "nodes" / f"{name.lower()}.py").write_text(text, encoding="utf-8")
    (project / "run_all.py").write_text(RUNNER.replace("TICKS", str(TICKS)), encoding="utf-8")
    expected: dict[str, skeleton_script.Trace] = {}
    livelocks = 0
    for seed in range(TREES):
        doc = random_tree(
            random.Random(seed), controls=PYTREES_CONTROLS, decorators=DECORATORS, max_nodes=22
        )
        script = skeleton_script.plans(doc, seed)
        if not script:
            continue
        try:
            expected[str(seed)] = skeleton_script.run_interpreter(
                doc, script, TICKS, exactly_once=True
            )
        except BTLivelock:
            livelocks += 1
            continue
        skeleton_script.write(tmp_path / f"script{seed}.txt", script)
        statements, root = tree_statements(doc, leaf_kinds(doc))
        module = render(
            "py_tree.py.j2",
            source=f"seed {seed}",
            leaves=leaf_kinds(doc),
            statements=statements,
            root=root,
        )
        (project / "generated" / f"tree_{seed}.py").write_text(module, encoding="utf-8")
    run = subprocess.run(
        [sys.executable, "run_all.py", str(tmp_path), *expected],
        cwd=project,
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "PYTHONDONTWRITEBYTECODE": "1"},
    )
    assert run.returncode == 0, run.stderr[-3000:]
    runs = run.stdout.split("=== ")[1:]
    assert len(runs) == len(expected)
    leaf_ticks = 0
    for chunk in runs:
        seed, _, body = chunk.partition("\n")
        got = skeleton_script.parse_run(body)
        assert got == expected[seed], f"seed {seed}"
        leaf_ticks += sum(len(leaves) for leaves, _ in got)
    print(
        f"\n{len(runs)} random trees, {leaf_ticks} leaf ticks in py_trees: the interpreter's "
        f"trace ({livelocks} livelocking trees not run)"
    )
    assert len(runs) >= TREES // 2 and leaf_ticks > 150


def test_example_python_skeleton_runs_with_labels_and_parameters(tmp_path: Path) -> None:
    project = tmp_path / "pick_place"
    assert main(["runtime", "python", str(project), str(EXAMPLE)]) == 0
    run = subprocess.run(
        [sys.executable, "main.py", "--period", "0"],
        cwd=project,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert run.returncode == 0, run.stderr
    lines = run.stdout.splitlines()
    assert lines[0] == "Detect 'DETECT' started timeout=2.0"
    assert "Grasp 'GRASP' started force=10.0 object_pose={pose}" in lines
    assert "Place 'PLACE' started location=bin" in lines
    assert lines[-1] == "tick 4: SUCCESS"
    assert api.load(project / "tree.xml").model
    doc = (REPO / "docs" / "runtime-python.md").read_text(encoding="utf-8")
    section = doc.split("## The migration path", 1)[1]
    blocks = re.findall(r"```(\w+)\n(.*?)```", section, re.S)
    snippet = next(body for lang, body in blocks if lang == "sh")
    assert "fsmbt runtime python out/pick_place_py examples/pick_place_bt.xml" in snippet
    assert "main.py --period 0" in snippet
    assert run.stdout == next(body for lang, body in blocks if lang == "text")
