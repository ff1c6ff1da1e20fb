"""The C++ LEBT runtime (fsmbt/lebt.hpp) through its driver, its bad-input errors, the files
``fsmbt runtime cpp|python`` writes, the CMake example, the build script and the cache lookup."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.cli import main
from fsmbt.convert import convert
from fsmbt.formats import dumps
from fsmbt.runtime import cpp as cpp_runtime
from fsmbt.runtime.cpp import DriverSession, library_prefix
from support import hand_lebt

REPO = Path(__file__).resolve().parents[2]
DOOR = REPO / "examples" / "door_hfsm.scxml"

MINIMAL = """<root BTCPP_format="4" main_tree_to_execute="MainTree">
  <BehaviorTree ID="MainTree">
    <Sequence name="LEBT">
      <Fallback name="A_selector">
        <LebtGuard name="Enter_A" target="A" pairs="__start__/"/>
        <Sequence name="A_chain">
          <LebtState name="A" state="A" action="do_A" final="false" exits="go"/>
          <Fallback name="B_selector">
            <LebtGuard name="Enter_B" target="B" pairs="A/go"/>
            {leaf}
          </Fallback>
        </Sequence>
      </Fallback>
    </Sequence>
  </BehaviorTree>
</root>
"""
GOOD_LEAF = '<LebtState name="B" state="B" action="do_B" final="true" exits=""/>'


def _driver_call(
    driver: Path, tree: Path, *args: str, stdin: str = ""
) -> subprocess.CompletedProcess:
    return subprocess.run(
        [str(driver), str(tree), *args], input=stdin, capture_output=True, text=True, timeout=60
    )


def _tree(tmp_path: Path, leaf: str = GOOD_LEAF, name: str = "tree.xml") -> Path:
    path = tmp_path / name
    path.write_text(MINIMAL.replace("{leaf}", leaf), encoding="utf-8")
    return path


def _door_tree(tmp_path: Path) -> Path:
    path = tmp_path / "door_bt.xml"
    path.write_text(
        dumps(convert(api.load(DOOR).model, style="lebt").model, "btcpp"), encoding="utf-8"
    )
    return path


# -- the runtime on known trees ------------------------------------------------------------------
def test_minimal_tree_runs_enters_once_and_terminates(driver: Path, tmp_path: Path) -> None:
    tree = _tree(tmp_path)
    [run] = DriverSession(tree, driver=driver).run([["nothing", "go", "go"]])
    assert [(s.event, s.actions, s.terminated, s.state) for s in run] == [
        (None, ("do_A",), False, "A"),  # no initial event: A is entered at start
        ("nothing", (), False, "A"),  # no transition: ignored, A not re-entered
        ("go", ("do_B",), True, "B"),  # final state: terminated
        ("go", (), True, "B"),  # a final state ignores every event
    ]


def test_hierarchical_door_runs_its_subtree_unchanged(driver: Path, tmp_path: Path) -> None:
    tree = _door_tree(tmp_path)
    text = tree.read_text(encoding="utf-8")
    assert '<SubTree name="Operating" ID="Operating"/>' in text  # one tree per composite
    [run] = DriverSession(tree, driver=driver).run(
        [["open_cmd", "fully_open", "fire_alarm", "open_cmd", "reset", "fire_alarm", "shutdown"]]
    )
    assert [s.actions for s in run] == [
        ("Closed",),
        ("Opening",),
        ("Open",),
        ("Emergency",),
        (),
        ("Closed",),
        ("Emergency",),
        ("Off",),
    ]
    assert [s.terminated for s in run][-2:] == [False, True]
    assert run[2].state == "Operating/Open"


def test_reset_between_sequences_starts_afresh(driver: Path, tmp_path: Path) -> None:
    runs = DriverSession(_tree(tmp_path), driver=driver).run([["go"], ["nothing"], []])
    assert [[s.actions for s in run] for run in runs] == [
        [("do_A",), ("do_B",)],
        [("do_A",), ()],
        [("do_A",)],
    ]


# -- bad input: clear, located errors at load time -------------------------------------------
def test_unknown_leaf_names_the_node_and_its_line(driver: Path, tmp_path: Path) -> None:
    tree = _tree(tmp_path, '<MoveBase name="go_somewhere" goal="kitchen"/>')
    proc = _driver_call(driver, tree)
    assert proc.returncode == 1 and proc.stdout == ""
    [line] = proc.stderr.strip().splitlines()
    assert "MoveBase" in line and "line 10" in line, line


def test_builtin_leaf_that_is_not_lebt_is_refused_with_its_line(
    driver: Path, tmp_path: Path
) -> None:
    tree = _tree(tmp_path, '<Sleep name="nap" msec="10"/>')
    proc = _driver_call(driver, tree)
    assert proc.returncode == 1
    assert '<Sleep name="nap">' in proc.stderr and "line 10" in proc.stderr
    assert "not an LEBT leaf" in proc.stderr


def test_refused_leaf_line_is_the_named_element(driver: Path, tmp_path: Path) -> None:
    leaf = (
        '<Sequence name="s">\n  <SleepLonger/>\n  <Sleep name="first" msec="1"/>\n'
        '  <Sleep name="nap" msec="1"/>\n</Sequence>'
    )
    path = tmp_path / "two_sleeps.xml"
    path.write_text(
        MINIMAL.replace("{leaf}", leaf).replace(
            '<LebtGuard name="Enter_B" target="B" pairs="A/go"/>', ""
        ),
        encoding="utf-8",
    )
    proc = _driver_call(driver, path)
    assert proc.returncode == 1
    # BehaviorTree.CPP refuses the unknown <SleepLonger> first, with the line tinyxml2 gives
    # (for a first child, the line its preceding whitespace starts on)
    assert "Error at line 10: -> Node not recognized: SleepLonger" in proc.stderr
    path.write_text(
        path.read_text(encoding="utf-8").replace("  <SleepLonger/>\n", ""), encoding="utf-8"
    )
    proc = _driver_call(driver, path)
    assert '<Sleep name="first">' in proc.stderr and "line 11" in proc.stderr, proc.stderr


def test_missing_action_callback_is_a_load_error(driver: Path, tmp_path: Path) -> None:
    tree = _tree(tmp_path)
    proc = _driver_call(driver, tree, "--register", "do_A", stdin="go\n")
    assert proc.returncode == 1 and proc.stdout == ""  # nothing ran
    assert "no callback registered for action(s): 'do_B' (state B)" in proc.stderr
    ok = _driver_call(driver, tree, "--register", "do_A,do_B", stdin="go\n")
    assert ok.returncode == 0 and '"actions":["do_B"]' in ok.stdout


@pytest.mark.parametrize(
    ("leaf", "message"),
    [
        ('<LebtGuard name="bad" target="B" pairs="A-go"/>', "malformed pair 'A-go'"),
        (
            '<LebtState name="B" state="{bb_state}" action="x" final="true" exits=""/>',
            "blackboard reference",
        ),
        ('<LebtState name="B" state="B" action="x" final="maybe" exits=""/>', "port 'final'"),
    ],
)
def test_malformed_lebt_ports_are_load_errors(
    driver: Path, tmp_path: Path, leaf: str, message: str
) -> None:
    proc = _driver_call(driver, _tree(tmp_path, leaf))
    assert proc.returncode == 1 and message in proc.stderr, proc.stderr
    assert 'name="' in proc.stderr  # names the node


def test_malformed_xml_and_missing_file_are_one_line_errors(driver: Path, tmp_path: Path) -> None:
    broken = tmp_path / "broken.xml"
    broken.write_text("<root BTCPP_format='4'><BehaviorTree ID='M'>", encoding="utf-8")
    for path in (broken, tmp_path / "absent.xml"):
        proc = _driver_call(driver, path)
        assert proc.returncode == 1
        assert len(proc.stderr.strip().splitlines()) == 1 and "error:" in proc.stderr


def test_table_mode_matches_the_tree_on_the_door(driver: Path, tmp_path: Path) -> None:
    tree = _door_tree(tmp_path)
    events = [
        [
            "open_cmd",
            "obstacle",
            "fully_open",
            "close_cmd",
            "fully_closed",
            "fire_alarm",
            "bogus",
            "reset",
            "fire_alarm",
            "shutdown",
            "reset",
        ]
    ]
    bt = DriverSession(tree, driver=driver).run(events)
    table = DriverSession(tree, driver=driver, table=True).run(events)
    assert bt == table


# -- files written out, the CMake example ------------------------------------------------------
def test_runtime_cpp_writes_files_and_refuses_to_overwrite(tmp_path: Path, capsys) -> None:
    target = tmp_path / "out"
    assert main(["runtime", "cpp", str(target)]) == 0
    written = sorted(p.relative_to(target).as_posix() for p in target.rglob("*") if p.is_file())
    assert written == ["CMakeLists.txt", "include/fsmbt/lebt.hpp", "main.cpp"]
    assert (target / "include/fsmbt/lebt.hpp").read_bytes() == cpp_runtime.HEADER.read_bytes()
    (target / "main.cpp").write_text("// mine\n", encoding="utf-8")
    capsys.readouterr()
    assert main(["runtime", "cpp", str(target)]) == 2
    assert "not overwriting" in capsys.readouterr().err
    assert (target / "main.cpp").read_text(encoding="utf-8") == "// mine\n"  # untouched
    assert main(["runtime", "cpp", str(target), "--force"]) == 0
    assert (target / "main.cpp").read_bytes() == (cpp_runtime.EXAMPLE_DIR / "main.cpp").read_bytes()


def test_runtime_python_writes_the_example_and_never_overwrites(tmp_path: Path, capsys) -> None:
    target = tmp_path / "py"
    assert main(["runtime", "python", str(target)]) == 0
    written = sorted(p.name for p in target.iterdir())
    assert written == ["lebt_tree.xml", "run_lebt.py"]
    (target / "run_lebt.py").write_text("# mine\n", encoding="utf-8")
    capsys.readouterr()
    assert main(["runtime", "python", str(target)]) == 2
    err = capsys.readouterr().err
    assert "already exist" in err and err.count("\n") == 1
    assert (target / "run_lebt.py").read_text(encoding="utf-8") == "# mine\n"  # untouched
    assert main(["runtime", "python", str(target), "--force"]) == 0
    assert (target / "run_lebt.py").read_text(encoding="utf-8") != "# mine\n"


def test_cmake_example_builds_and_runs_the_door(driver: Path, tmp_path: Path) -> None:
    """The documented example (docs/runtime.md): written out, configured against the cached
    BehaviorTree.CPP, built, run on the converted door."""
    project = tmp_path / "lebt_example"
    assert main(["runtime", "cpp", str(project)]) == 0
    build = project / "build"
    configure = subprocess.run(
        [
            "cmake",
            "-S",
            str(project),
            "-B",
            str(build),
            f"-DCMAKE_PREFIX_PATH={library_prefix()}",
            "-DCMAKE_BUILD_TYPE=Release",
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert configure.returncode == 0, configure.stderr[-2000:]
    compiled = subprocess.run(
        ["nice", "-n", "10", "cmake", "--build", str(build)],
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert compiled.returncode == 0, compiled.stdout[-2000:] + compiled.stderr[-2000:]
    tree = _door_tree(tmp_path)
    snippet, printed = _documented_example()
    documented_args = snippet.strip().splitlines()[-1].split()[2:]  # after binary and tree
    run = subprocess.run(
        [str(build / "lebt_example"), str(tree), *documented_args],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert run.returncode == 0, run.stderr
    assert run.stdout == printed  # docs/runtime.md shows what it prints
    # the same program on the door's dispatch form (the default style): the same run
    door = api.load(REPO / "examples" / "door_hfsm.scxml").model
    dispatch = tmp_path / "door_dispatch.xml"
    dispatch.write_text(dumps(convert(door).model, "btcpp"), encoding="utf-8")
    assert "<DispatchEntry" in dispatch.read_text(encoding="utf-8")
    run = subprocess.run(
        [str(build / "lebt_example"), str(dispatch), *documented_args],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert run.returncode == 0, run.stderr
    assert run.stdout == printed
    run = subprocess.run(
        [
            str(build / "lebt_example"),
            str(tree),
            "open_cmd",
            "fully_open",
            "fire_alarm",
            "shutdown",
        ],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert run.returncode == 0, run.stderr
    assert run.stdout.splitlines() == [
        "  action Closed (entered Operating/Closed)",
        "start: state Operating/Closed",
        "  action Opening (entered Operating/Opening)",
        "event open_cmd: state Operating/Opening",
        "  action Open (entered Operating/Open)",
        "event fully_open: state Operating/Open",
        "  action Emergency (entered Emergency)",
        "event fire_alarm: state Emergency",
        "  action Off (entered Off)",
        "event shutdown: state Off, terminated",
    ]
    other = _tree(tmp_path)  # actions do_A/do_B have no callbacks in main.cpp
    refused = subprocess.run(
        [str(build / "lebt_example"), str(other)], capture_output=True, text=True, timeout=60
    )
    assert refused.returncode == 1 and "'do_A' (state A)" in refused.stderr


def _documented_example() -> tuple[str, str]:
    """docs/runtime.md's example: the shell snippet and the text it says is printed."""
    import re

    doc = (REPO / "docs" / "runtime.md").read_text(encoding="utf-8")
    section = doc.split("## The example, run as written", 1)[1]
    blocks = re.findall(r"```(\w+)\n(.*?)```", section, re.S)
    snippet = next(body for lang, body in blocks if lang == "sh")
    printed = next(body for lang, body in blocks if lang == "text")
    return snippet, printed


def test_docs_show_the_shipped_example_files() -> None:
    import re

    doc = (REPO / "docs" / "runtime.md").read_text(encoding="utf-8")
    blocks = dict(
        (lang, body)
        for lang, body in re.findall(r"```(\w+)\n(.*?)```", doc, re.S)
        if lang in ("cpp", "cmake")
    )
    assert blocks["cpp"] == (cpp_runtime.EXAMPLE_DIR / "main.cpp").read_text(encoding="utf-8")
    assert blocks["cmake"] == (cpp_runtime.EXAMPLE_DIR / "CMakeLists.txt").read_text(
        encoding="utf-8"
    )
    snippet, _ = _documented_example()
    assert "fsmbt runtime cpp out/lebt_example" in snippet


# -- cache lookup, doctor, the build script without a compiler ----------------------------------
def test_find_driver_ignores_a_stale_driver(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setenv("FSMBT_CACHE", str(tmp_path))
    bin_dir = cpp_runtime.library_prefix() / "bin"
    bin_dir.mkdir(parents=True)
    fake = bin_dir / cpp_runtime.DRIVER_NAME
    fake.write_text("#!/bin/sh\n", encoding="utf-8")
    fake.chmod(0o755)
    stamp = bin_dir / (cpp_runtime.DRIVER_NAME + ".sources")
    stamp.write_text("0" * 64 + "\n", encoding="utf-8")
    assert cpp_runtime.find_driver() is None
    assert "not built" in cpp_runtime.status().problem  # no library in this cache
    stamp.write_text(cpp_runtime.sources_hash() + "\n", encoding="utf-8")
    assert cpp_runtime.find_driver() == fake


def test_doctor_reports_the_cpp_runtime(tmp_path: Path, monkeypatch) -> None:
    from fsmbt.cli.cmd_doctor import checks

    names = {c.name: c for c in checks()}
    assert names["C++ LEBT driver"].ok == (cpp_runtime.find_driver() is not None)
    monkeypatch.setenv("FSMBT_CACHE", str(tmp_path))
    names = {c.name: c for c in checks()}
    assert not names["C++ LEBT driver"].ok
    assert not names[f"BehaviorTree.CPP {cpp_runtime.BTCPP_VERSION} (C++)"].ok
    assert "fsmbt doctor --install btcpp" in names["C++ LEBT driver"].hint
    assert main(["doctor"]) == 1


def test_build_script_without_compiler_says_what_is_missing(tmp_path: Path) -> None:
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    for tool in ("dirname", "sed", "bash"):  # what the script needs before its tool check
        found = shutil.which(tool)
        assert found is not None
        (bin_dir / tool).symlink_to(found)
    script = REPO / "scripts" / "build_btcpp.sh"
    proc = subprocess.run(
        [str(bin_dir / "bash"), str(script)],
        capture_output=True,
        text=True,
        timeout=60,
        env={"PATH": str(bin_dir), "HOME": str(tmp_path)},
    )
    assert proc.returncode == 2
    [line] = proc.stderr.strip().splitlines()
    assert "missing cmake, a C++17 compiler" in line, line
    assert proc.stdout == ""
    assert not (tmp_path / ".cache").exists()  # nothing was started


def test_build_script_is_executable_in_git() -> None:
    script = REPO / "scripts" / "build_btcpp.sh"
    mode = subprocess.run(
        ["git", "ls-files", "-s", str(script)], capture_output=True, text=True, cwd=REPO
    ).stdout.split()
    assert mode and mode[0] == "100755" and os.access(script, os.X_OK)


def test_nusmv_cache_is_per_machine_and_keyed_by_version(tmp_path: Path, monkeypatch) -> None:
    from fsmbt.verify.nusmv import binary

    monkeypatch.delenv(binary.ENV_VAR, raising=False)
    monkeypatch.setenv("FSMBT_CACHE", str(tmp_path))
    assert binary.cached_binary() == tmp_path / "nusmv-2.5.4" / "bin" / "NuSMV"
    listed = binary.candidates()
    assert listed.index(binary.cached_binary()) < listed.index(binary.LEGACY_BINARY)
    assert listed[-1] == binary.LEGACY_BINARY  # the old per-checkout place, last


def test_nusmv_build_script_reuses_the_old_checkout_binary(tmp_path: Path) -> None:
    """A NuSMV the old script built in <repo>/.cache is copied into the machine cache (no
    rebuild); the next run finds it there."""
    repo = tmp_path / "repo"
    (repo / "scripts").mkdir(parents=True)
    shutil.copy2(REPO / "scripts" / "build_nusmv.sh", repo / "scripts" / "build_nusmv.sh")
    # the checkout's script runs the one the package ships (src/fsmbt/install)
    (repo / "src" / "fsmbt" / "install").mkdir(parents=True)
    shutil.copy2(
        REPO / "src" / "fsmbt" / "install" / "build_nusmv.sh",
        repo / "src" / "fsmbt" / "install" / "build_nusmv.sh",
    )
    legacy = repo / ".cache" / "nusmv" / "bin" / "NuSMV"
    legacy.parent.mkdir(parents=True)
    legacy.write_text("#!/bin/sh\necho 'usage: NuSMV -dcx ...'\n", encoding="utf-8")
    legacy.chmod(0o755)
    env = {**os.environ, "FSMBT_CACHE": str(tmp_path / "cache")}
    env.pop("FSMBT_NUSMV_PREFIX", None)
    first = subprocess.run(
        [str(repo / "scripts" / "build_nusmv.sh")],
        capture_output=True,
        text=True,
        timeout=60,
        env=env,
    )
    assert first.returncode == 0, first.stderr
    cached = tmp_path / "cache" / "nusmv-2.5.4" / "bin" / "NuSMV"
    assert "copied from the old per-checkout cache" in first.stdout
    assert cached.read_bytes() == legacy.read_bytes()
    legacy.unlink()
    second = subprocess.run(
        [str(repo / "scripts" / "build_nusmv.sh")],
        capture_output=True,
        text=True,
        timeout=60,
        env=env,
    )
    assert second.returncode == 0 and f"already built: {cached}" in second.stdout


# -- callbacks get label and parameters; hand-broken annotations are load errors ---------------
def test_callbacks_get_the_state_label_and_its_parameters(driver: Path, tmp_path: Path) -> None:
    import json

    tree = tmp_path / "hand.xml"
    tree.write_text(hand_lebt.TREE, encoding="utf-8")
    run = _driver_call(driver, tree, "--entries", stdin="go\nstop\n")
    assert run.returncode == 0, run.stderr
    records = [json.loads(line) for line in run.stdout.splitlines()]
    entered = [(r["entered"], r["params"]) for r in records if "entered" in r]
    assert entered == [(state, params) for _, state, params in hand_lebt.ENTRIES]
    steps = [r for r in records if "step" in r]
    assert [s["actions"] for s in steps] == [[action] for action, _, _ in hand_lebt.ENTRIES]
    assert steps[-1]["terminated"] is True


@pytest.mark.parametrize("case", [c[0] for c in hand_lebt.BROKEN])
def test_hand_broken_annotations_are_load_errors_naming_the_node(
    driver: Path, tmp_path: Path, case: str
) -> None:
    _, replaced, replacement, node, line = next(c for c in hand_lebt.BROKEN if c[0] == case)
    tree = tmp_path / "broken.xml"
    tree.write_text(hand_lebt.broken(replaced, replacement), encoding="utf-8")
    run = _driver_call(driver, tree, stdin="go\n")
    assert run.returncode == 1 and run.stdout == ""
    error = run.stderr.strip()
    assert len(error.splitlines()) == 1 and f'name="{node}"' in error, error
    if "params" not in case:  # BehaviorTree.CPP builds the node before the runner sees the XML
        assert f"line {line}" in error, error
