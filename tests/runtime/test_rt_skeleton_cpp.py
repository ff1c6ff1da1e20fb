"""The C++ skeleton (``fsmbt runtime cpp DIR MODEL``) compiled against BehaviorTree.CPP 4.8.2.

One compile per module (cached by the hash of every source file in the temp folder): the
skeleton of a tree declaring six leaf types, whose user classes are replaced - as a user would
fill them in - by classes returning scripted outcomes by label (tests/support/skeleton_script).
The binary then runs 80 seeded random trees over those types (every BehaviorTree.CPP control
and decorator fsmbt's interpreter has) and prints each leaf tick; the trace must be the one
fsmbt's interpreter gives (``BTRunner``, ``tickOnce``) tick by tick. The same build holds the
example's three leaf types (examples/pick_place_bt.xml) with the default classes fsmbt writes:
the example's tree runs as docs/runtime.md shows, printing each leaf's label and parameters; a
Switch over a generated output port runs the right branch.
"""

from __future__ import annotations

import hashlib
import os
import random
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.cli import main
from fsmbt.formats import dumps
from fsmbt.runtime.cpp import library_built, library_prefix
from fsmbt.semantics.bt_interpreter import BTLivelock
from support import skeleton_script
from support.random_trees import random_tree

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "examples" / "pick_place_bt.xml"
TREES = 80
TICKS = 12

#: A tree that declares the six leaf types the random trees use (random_trees: Act0-2, Cond0-2).
UNION = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence>
      <Act0 name="a0" speed="2"/><Act1 name="a1"/><Act2 name="a2" goal="{goal}"/>
      <Cond0 name="c0"/><Cond1 name="c1"/><Cond2 name="c2"/><Look name="l" result="{seen}"/>
    </Sequence>
  </BehaviorTree>
  <TreeNodesModel>
    <Action ID="Act0"><input_port name="speed" type="double" default="1.5"/></Action>
    <Action ID="Act1"/>
    <Condition ID="Cond0"/>
    <Condition ID="Cond1"/>
    <Condition ID="Cond2"/>
    <Action ID="Look"><output_port name="result"/></Action>
  </TreeNodesModel>
</root>
"""
SCRIPTED = r"""#pragma once
// The test's stand-in for the user's code: outcomes by label from the file $FSMBT_SCRIPT.
#include <behaviortree_cpp/basic_types.h>

#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

inline std::string scriptedWord(const std::string& label)
{
  static std::map<std::string, std::vector<std::string>> plans = [] {
    std::map<std::string, std::vector<std::string>> read;
    std::ifstream in(std::getenv("FSMBT_SCRIPT"));
    std::string line;
    while(std::getline(in, line))
    {
      std::istringstream words(line);
      std::string name, outcome;
      words >> name;
      while(words >> outcome) read[name].push_back(outcome);
    }
    return read;
  }();
  static std::map<std::string, std::size_t> next;
  const std::vector<std::string>& plan = plans.at(label);
  const std::string& outcome = plan[next[label]++ % plan.size()];
  std::cout << "leaf " << label << " " << outcome << std::endl;
  return outcome;
}

inline BT::NodeStatus scripted(const std::string& label)
{
  const std::string outcome = scriptedWord(label);
  return outcome == "success" ? BT::NodeStatus::SUCCESS :
         outcome == "failure" ? BT::NodeStatus::FAILURE : BT::NodeStatus::RUNNING;
}
"""
ACTION = """#pragma once
#include "fsmbt_nodes.hpp"
#include "scripted.hpp"
namespace bt_nodes {{
class {name} : public generated::{name}Base
{{
public:
  using generated::{name}Base::{name}Base;
  BT::NodeStatus onStart() override {{ return scripted(label()); }}
  BT::NodeStatus onRunning() override {{ return scripted(label()); }}
  void onHalted() override {{}}
}};
}}
"""
CONDITION = """#pragma once
#include "fsmbt_nodes.hpp"
#include "scripted.hpp"
namespace bt_nodes {{
class {name} : public generated::{name}Base
{{
public:
  using generated::{name}Base::{name}Base;
  BT::NodeStatus tick() override {{ return scripted(label()); }}
}};
}}
"""


LOOK = """#pragma once
#include "fsmbt_nodes.hpp"
#include "scripted.hpp"
namespace bt_nodes {
// sets its output port to the next word of its script: what a >2-outcome state reports
class Look : public generated::LookBase
{
public:
  using generated::LookBase::LookBase;
  BT::NodeStatus onStart() override
  {
    setOutput("result", scriptedWord(label()));
    return BT::NodeStatus::SUCCESS;
  }
  BT::NodeStatus onRunning() override { return BT::NodeStatus::SUCCESS; }
  void onHalted() override {}
};
}
"""
#: A state with three outcomes as the structured style may dispatch it: an output port read by
#: a Switch (not in fsmbt's interpreter: the blackboard decides; the expected runs are Switch's
#: rule, case_1 -> first child, case_2 -> second, anything else -> the last).
SWITCH = """<root BTCPP_format="4" main_tree_to_execute="T">
  <BehaviorTree ID="T">
    <Sequence>
      <Look name="l" result="{seen}"/>
      <Switch2 variable="{seen}" case_1="cup" case_2="box">
        <Act0 name="on_cup"/><Act1 name="on_box"/><Act2 name="otherwise"/>
      </Switch2>
    </Sequence>
  </BehaviorTree>
</root>
"""


def _union() -> str:
    """UNION plus the example's three leaf types, declared as the example declares them: one
    binary runs the random trees (scripted classes) and the example (its default classes)."""
    example = EXAMPLE.read_text(encoding="utf-8")
    start = example.index("<TreeNodesModel>") + len("<TreeNodesModel>")
    models = example[start : example.index("</TreeNodesModel>")]
    uses = '<Detect name="DETECT"/><Grasp name="GRASP"/><Place name="PLACE"/>'
    text = UNION.replace("</TreeNodesModel>", models + "</TreeNodesModel>")
    return text.replace("    </Sequence>", f"      {uses}\n    </Sequence>", 1)


def _require_build() -> None:
    missing = [tool for tool in ("cmake",) if shutil.which(tool) is None]
    if not any(shutil.which(cxx) for cxx in ("g++", "c++", "clang++")):
        missing.append("a C++ compiler")
    if missing:
        pytest.skip(f"cannot compile C++ here: missing {', '.join(missing)}")
    if not library_built():
        pytest.fail(f"BehaviorTree.CPP is not built at {library_prefix()}: run scripts/setup.sh")


def _build(project: Path) -> tuple[Path, float]:
    """Configure and build ``project`` in a temp folder keyed by its sources' hash (reused; the
    tree is read at run time, so it is not part of the key)."""
    digest = hashlib.sha256()
    for path in sorted(project.rglob("*")):
        compiled = path.suffix in (".hpp", ".cpp") or path.name == "CMakeLists.txt"
        if path.is_file() and compiled and "build" not in path.relative_to(project).parts:
            digest.update(str(path.relative_to(project)).encode() + b"\0" + path.read_bytes())
    build = Path(tempfile.gettempdir()) / f"fsmbt-skeleton-{digest.hexdigest()[:16]}"
    binary = build / "bin"
    if binary.is_file():
        return binary, 0.0
    started = time.perf_counter()
    configure = subprocess.run(
        [
            "cmake",
            "-S",
            str(project),
            "-B",
            str(build / "cmake"),
            f"-DCMAKE_PREFIX_PATH={library_prefix()}",
            "-DCMAKE_BUILD_TYPE=Release",
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert configure.returncode == 0, configure.stderr[-2000:]
    compiled = subprocess.run(
        ["nice", "-n", "10", "cmake", "--build", str(build / "cmake")],
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert compiled.returncode == 0, compiled.stdout[-3000:] + compiled.stderr[-3000:]
    target = next(p for p in (build / "cmake").iterdir() if p.is_file() and os.access(p, os.X_OK))
    target.replace(binary)
    return binary, time.perf_counter() - started


@pytest.fixture(scope="module")
def scripted_binary(tmp_path_factory) -> Path:
    _require_build()
    root = tmp_path_factory.mktemp("skeleton")
    model = root / "union.xml"
    model.write_text(_union(), encoding="utf-8")
    project = root / "project"
    assert main(["runtime", "cpp", str(project), str(model)]) == 0
    (project / "nodes" / "scripted.hpp").write_text(SCRIPTED, encoding="utf-8")
    for name in ("Act0", "Act1", "Act2", "Cond0", "Cond1", "Cond2"):
        text = (CONDITION if name.startswith("Cond") else ACTION).format(name=name)
        (project / "nodes" / f"{name.lower()}.hpp").write_text(text, encoding="utf-8")
    (project / "nodes" / "look.hpp").write_text(LOOK, encoding="utf-8")
    binary, seconds = _build(project)
    print(f"\nscripted skeleton: compiled in {seconds:.1f} s (0.0 = cached)")
    return binary


def test_generated_cpp_runs_random_trees_like_the_interpreter(
    scripted_binary: Path, tmp_path: Path
) -> None:
    compared = leaf_ticks = livelocks = 0
    for seed in range(TREES):
        doc = random_tree(random.Random(seed), max_nodes=22)
        script = skeleton_script.plans(doc, seed)
        if not script:
            continue
        try:
            expected = skeleton_script.run_interpreter(doc, script, TICKS, exactly_once=False)
        except BTLivelock:
            livelocks += 1  # BehaviorTree.CPP's tickOnce() would loop forever: not run
            continue
        tree = tmp_path / f"tree{seed}.xml"
        tree.write_text(dumps(doc, "btcpp"), encoding="utf-8")
        plan = skeleton_script.write(tmp_path / f"script{seed}.txt", script)
        run = subprocess.run(
            [str(scripted_binary), str(tree), "--period-ms", "0", "--max-ticks", str(TICKS)],
            capture_output=True,
            text=True,
            timeout=60,
            env={**os.environ, "FSMBT_SCRIPT": str(plan)},
        )
        assert run.returncode in (0, 1, 3), (seed, run.stderr)
        got = skeleton_script.parse_run(run.stdout)
        assert got == expected, f"seed {seed}: {tree.read_text()}"
        compared += 1
        leaf_ticks += sum(len(leaves) for leaves, _ in got)
    print(
        f"\n{compared} random trees, {leaf_ticks} leaf ticks: same trace as the interpreter "
        f"({livelocks} livelocking trees not run)"
    )
    assert compared >= TREES // 2 and leaf_ticks > 150


def test_example_skeleton_runs_with_labels_and_parameters(
    scripted_binary: Path, tmp_path: Path
) -> None:
    """The example's leaf types are in the module's build with their default classes (as
    ``fsmbt runtime cpp`` writes them): the example's tree runs as docs/runtime.md shows."""
    project = tmp_path / "pick_place"
    assert main(["runtime", "cpp", str(project), str(EXAMPLE)]) == 0
    assert {p.name for p in (project / "nodes").iterdir()} == {
        "detect.hpp",
        "grasp.hpp",
        "place.hpp",
    }
    binary = scripted_binary
    run = subprocess.run(
        [str(binary), str(project / "tree.xml"), "--period-ms", "0"],
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
    snippet, printed = _documented("runtime.md")
    assert "fsmbt runtime cpp out/pick_place_cpp examples/pick_place_bt.xml" in snippet
    assert "pick_place_bt --period-ms 0" in snippet and run.stdout == printed
    # the same tree with a port the classes do not declare: a load error, exit 1, one line
    broken = tmp_path / "broken.xml"
    broken.write_text(
        (project / "tree.xml").read_text().replace('location="bin"', 'place="bin"', 1)
    )
    refused = subprocess.run([str(binary), str(broken)], capture_output=True, text=True, timeout=60)
    assert refused.returncode == 1 and "place" in refused.stderr
    assert api.load(project / "tree.xml").model  # the copied tree reads back


def _documented(page: str) -> tuple[str, str]:
    """The migration section's shell snippet and the output it shows (docs/<page>)."""
    import re

    doc = (REPO / "docs" / page).read_text(encoding="utf-8")
    section = doc.split("## The migration path", 1)[1]
    blocks = re.findall(r"```(\w+)\n(.*?)```", section, re.S)
    return (
        next(body for lang, body in blocks if lang == "sh"),
        next(body for lang, body in blocks if lang == "text"),
    )


@pytest.mark.parametrize(
    ("seen", "branch"), [("cup", "on_cup"), ("box", "on_box"), ("mug", "otherwise")]
)
def test_an_output_port_dispatched_by_switch_runs_the_right_branch(
    scripted_binary: Path, tmp_path: Path, seen: str, branch: str
) -> None:
    tree = tmp_path / "switch.xml"
    tree.write_text(SWITCH, encoding="utf-8")
    plans = {"l": [seen], "on_cup": ["success"], "on_box": ["failure"], "otherwise": ["success"]}
    script = skeleton_script.write(tmp_path / "script.txt", plans)
    run = subprocess.run(
        [str(scripted_binary), str(tree), "--period-ms", "0", "--max-ticks", "3"],
        capture_output=True,
        text=True,
        timeout=60,
        env={**os.environ, "FSMBT_SCRIPT": str(script)},
    )
    result = "FAILURE" if branch == "on_box" else "SUCCESS"
    assert skeleton_script.parse_run(run.stdout) == [
        ([("l", seen), (branch, plans[branch][0])], result)
    ], run.stdout + run.stderr
