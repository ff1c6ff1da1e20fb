"""The GitHub Action's script (scripts/action_diff.sh, run by action.yml) and the pre-commit
hook's command, on a temporary git repository with two commits: the second swaps two children
of a Fallback, adds a model and breaks nothing else."""

from __future__ import annotations

import os
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from fsmbt.cli import main

ROOT = Path(__file__).resolve().parents[2]
ROBOT = ROOT / "examples" / "robot_bt.xml"
SWAP = ("<RobotAtInspection/>\n        <Dock/>", "<Dock/>\n        <RobotAtInspection/>")

pytestmark = pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed")


def _git(repo: Path, *args: str) -> None:
    env = {
        **os.environ,
        "GIT_AUTHOR_NAME": "t",
        "GIT_AUTHOR_EMAIL": "t@example.org",
        "GIT_COMMITTER_NAME": "t",
        "GIT_COMMITTER_EMAIL": "t@example.org",
    }
    subprocess.run(["git", "-C", str(repo), *args], check=True, capture_output=True, env=env)


@pytest.fixture
def repo(tmp_path: Path) -> Path:
    repo = tmp_path / "repo"
    (repo / "models").mkdir(parents=True)
    _git(repo, "init", "-q", "-b", "main")
    shutil.copy(ROBOT, repo / "models" / "robot.xml")
    shutil.copy(ROOT / "examples" / "paper_fsm.xml", repo / "models" / "paper.xml")
    (repo / "README.txt").write_text("not a model\n")
    _git(repo, "add", "-A")
    _git(repo, "commit", "-q", "-m", "first")
    text = ROBOT.read_text(encoding="utf-8")
    (repo / "models" / "robot.xml").write_text(text.replace(*SWAP), encoding="utf-8")
    shutil.copy(ROOT / "examples" / "prey_bt.xml", repo / "models" / "prey.xml")
    (repo / "README.txt").write_text("still not a model\n")
    (repo / "package.xml").write_text('<?xml version="1.0"?>\n<package format="3"/>\n')
    _git(repo, "add", "-A")
    _git(repo, "commit", "-q", "-m", "second: swap two children of a Fallback")
    return repo


def _run_action(repo: Path, tmp_path: Path, **env: str) -> subprocess.CompletedProcess[str]:
    out = tmp_path / "comment.md"
    github_output = tmp_path / "github_output"
    full = {
        **os.environ,
        "FSMBT": f"{shlex.quote(sys.executable)} -m fsmbt.cli",
        "FSMBT_BASE": "HEAD~1",
        "FSMBT_HEAD": "HEAD",
        "FSMBT_OUT": str(out),
        "GITHUB_OUTPUT": str(github_output),
        **env,
    }
    return subprocess.run(
        ["bash", str(ROOT / "scripts" / "action_diff.sh")],
        cwd=repo,
        env=full,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )


def test_action_script_posts_the_markdown(repo: Path, tmp_path: Path) -> None:
    done = _run_action(repo, tmp_path)
    assert done.returncode == 0, done.stderr
    comment = (tmp_path / "comment.md").read_text(encoding="utf-8")
    assert "models/robot.xml" in comment and "behaviour changed" in comment
    assert "**moved** node `Dock`" in comment
    assert "models/prey.xml" in comment and "paper.xml" not in comment  # unchanged: not listed
    assert "README" not in comment
    assert "`package.xml` (not a model)" in comment and "package.xml: not a model" in done.stdout
    assert (tmp_path / "github_output").read_text() == f"markdown={tmp_path / 'comment.md'}\n"
    failing = _run_action(repo, tmp_path, FSMBT_FAIL_ON_CHANGE="true")
    assert failing.returncode == 1
    assert "models/robot.xml: behaviour differs" in failing.stdout


def test_action_script_reports_a_broken_model(repo: Path, tmp_path: Path) -> None:
    (repo / "models" / "robot.xml").write_text("<root BTCPP_format='4'><Behavior", encoding="utf-8")
    _git(repo, "commit", "-q", "-am", "third: broken")
    done = _run_action(repo, tmp_path)
    assert done.returncode == 2
    assert "models/robot.xml: error:" in done.stdout


def test_action_and_hook_definitions() -> None:
    action = yaml.safe_load((ROOT / "action.yml").read_text(encoding="utf-8"))
    assert action["runs"]["using"] == "composite"
    assert any("action_diff.sh" in step.get("run", "") for step in action["runs"]["steps"])
    hooks = yaml.safe_load((ROOT / ".pre-commit-hooks.yaml").read_text(encoding="utf-8"))
    [hook] = hooks
    assert hook["entry"].split()[:2] == ["fsmbt", "review"]


def test_pre_commit_command_on_the_working_tree(
    repo: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    hook = yaml.safe_load((ROOT / ".pre-commit-hooks.yaml").read_text(encoding="utf-8"))[0]
    args = hook["entry"].split()[1:] + ["--repo", str(repo)]
    assert main(args) == 0  # the working tree is HEAD: nothing changed
    capsys.readouterr()
    text = (repo / "models" / "robot.xml").read_text(encoding="utf-8")
    (repo / "models" / "robot.xml").write_text(text.replace(SWAP[1], SWAP[0]), encoding="utf-8")
    assert main(args) == 1
    assert "models/robot.xml: behaviour differs" in capsys.readouterr().out
