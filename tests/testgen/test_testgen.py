"""fsmbt testgen: the generated suite passes on the tree that behaves like the specification (a
conversion, a refactoring), and fails - failed tests, not errors - on a mutant; the mutation
score counts mutants the cases really tell apart."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from fsmbt import api, testgen
from fsmbt.cli import main
from fsmbt.verify import verify

pytest.importorskip("behaviortreepy")
pytest.importorskip("py_trees")
ROOT = Path(__file__).resolve().parents[2]
ROBOT = ROOT / "examples" / "robot_bt.xml"
SWAP = ("<RobotAtInspection/>\n        <Dock/>", "<Dock/>\n        <RobotAtInspection/>")


def _pytest(folder: Path) -> tuple[int, str]:
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "pytest",
            "-q",
            "-p",
            "no:xdist",
            "-p",
            "no:cacheprovider",
            str(folder),
        ],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
        cwd=folder,
    )
    return done.returncode, done.stdout.strip().splitlines()[-1]


@pytest.fixture(scope="module")
def fsm_spec(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The HFSM fsmbt converts the robot tree into: the specification the tree implements."""
    path = tmp_path_factory.mktemp("spec") / "robot.scxml"
    assert main(["convert", str(ROBOT), "-o", str(path)]) == 0
    return path


def test_suite_passes_on_the_conversion_and_fails_on_a_mutant(
    fsm_spec: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "suite"
    assert main(["testgen", str(fsm_spec), "--tree", str(ROBOT), "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    cases = int(re.search(r"suite: (\d+) cases", printed).group(1))  # type: ignore[union-attr]
    assert re.search(r"covers (\d+)/\1 transitions", printed)
    assert len(list((out / "cases.json").read_text().split('"name"'))) == cases + 1
    # passing on the tree itself: tests/testgen/test_testgen_docs.py runs such a suite
    (out / "tree.xml").write_text(ROBOT.read_text(encoding="utf-8").replace(*SWAP), "utf-8")
    code, summary = _pytest(out)
    assert code == 1 and "failed" in summary and "error" not in summary, summary


def test_suite_passes_on_a_refactored_tree(fsm_spec: Path, tmp_path: Path) -> None:
    refactored = tmp_path / "refactored.xml"
    text = ROBOT.read_text(encoding="utf-8")
    refactored.write_text(text.replace("<Recharge/>", "<Sequence><Recharge/></Sequence>"), "utf-8")
    suite = testgen.generate(api.load(fsm_spec).model)
    doc = api.load(refactored).model
    from fsmbt.semantics.engines.btcpp_engine import BTCppRunner
    from fsmbt.semantics.engines.pytrees_engine import PyTreesRunner

    for case in suite.cases:
        for engine in (PyTreesRunner, BTCppRunner):
            assert testgen.run_case(lambda env, e=engine: e(doc, env), case.to_dict()) is None


def test_mutation_score_is_sound(fsm_spec: Path) -> None:
    tree = api.load(ROBOT).model
    suite = testgen.generate(api.load(fsm_spec).model)
    killed, mutants = testgen.mutation_score(tree, suite)
    assert mutants and killed > 0
    for mutant in mutants:
        if testgen.kills(mutant.model, suite):
            assert not verify(tree, mutant.model).equivalent, mutant.description


def test_bad_input(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    broken = tmp_path / "broken.xml"
    broken.write_text("<root BTCPP_format='4'><BehaviorTree", encoding="utf-8")
    assert main(["testgen", str(ROBOT), "--tree", str(broken), "-o", str(tmp_path / "s")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "broken.xml" in err[0]
    full = tmp_path / "full"
    full.mkdir()
    shutil.copy(ROBOT, full / "x.xml")
    assert main(["testgen", str(ROBOT), "--tree", str(ROBOT), "-o", str(full)]) == 2
    assert "not empty" in capsys.readouterr().err


def test_generated_gtest_file_builds_and_tells_trees_apart(
    fsm_spec: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The GoogleTest file, built with the CMakeLists.txt written beside it against the
    BehaviorTree.CPP 4.8.2 scripts/setup.sh built: every case passes on the tree, some fail on
    the tree with two children of a Fallback swapped (given as the program's argument)."""
    from fsmbt.cache import btcpp_prefix

    prefix = btcpp_prefix()
    if shutil.which("cmake") is None or not Path("/usr/include/gtest/gtest.h").exists():
        pytest.fail("cmake and libgtest-dev are installed by scripts/setup.sh")
    assert (prefix / "lib").is_dir(), "scripts/setup.sh builds BehaviorTree.CPP into the cache"
    out = tmp_path / "suite"
    assert main(["testgen", str(fsm_spec), "--tree", str(ROBOT), "-o", str(out), "--no-score"]) == 0
    cases = int(re.search(r"suite: (\d+) cases", capsys.readouterr().out).group(1))  # type: ignore[union-attr]
    build = tmp_path / "build"
    for command in (
        [
            "cmake",
            "-S",
            str(out),
            "-B",
            str(build),
            f"-DCMAKE_PREFIX_PATH={prefix}",
            "-DCMAKE_BUILD_TYPE=Debug",
        ],
        ["cmake", "--build", str(build)],
    ):
        done = subprocess.run(command, capture_output=True, text=True, timeout=600, check=False)
        assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    program = build / "test_behaviour_btcpp"
    passed = subprocess.run([program], capture_output=True, text=True, timeout=120, check=False)
    assert passed.returncode == 0 and f"[  PASSED  ] {cases} tests." in passed.stdout
    swapped = tmp_path / "swapped.xml"
    swapped.write_text(ROBOT.read_text(encoding="utf-8").replace(*SWAP), encoding="utf-8")
    failed = subprocess.run(
        [program, str(swapped)], capture_output=True, text=True, timeout=120, check=False
    )
    assert failed.returncode == 1 and "FAILED TEST" in failed.stdout
    assert "the tree ticks Dock, expected RobotAtInspection" in failed.stdout
