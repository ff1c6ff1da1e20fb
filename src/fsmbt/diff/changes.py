"""Diff every model file that changed between two git revisions (docs/diff.md, 'Pull requests
and pre-commit'): what the GitHub Action (``action.yml``) and the pre-commit hook
(``.pre-commit-hooks.yaml``) run through ``fsmbt review``.

Rules: the changed files are ``git diff --name-status BASE [HEAD]`` (without HEAD: the working
tree, which is what pre-commit checks), kept when their name matches one of ``patterns``
(``fnmatch``, default ``DEFAULT_PATTERNS``). A modified or renamed file is diffed against its
BASE version (read with ``git show``, written into a temporary folder under the same name so the
format is detected as usual); an added file is only read (a model that does not load is a bad
input); a deleted file is listed; a matching file no reader recognises by its content (a ROS
``package.xml``, a launch file) is listed as "not a model". git is run without a shell, with a fixed argument list; paths
come from git itself. SubTree files that a tree names are read from the same revision only when
they sit beside it in the temporary folder (a limitation stated in docs/diff.md).

Costs: one ``git`` process per changed file plus one diff each.
"""

from __future__ import annotations

import fnmatch
import subprocess
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from fsmbt import api
from fsmbt.diff.behaviour import DEFAULT_MAX_GROUPS
from fsmbt.diff.compare import diff_models
from fsmbt.diff.report import DiffReport, to_markdown
from fsmbt.formats.registry import formats
from fsmbt.model.errors import FsmbtError, InputError

#: Files treated as models when no pattern is given.
DEFAULT_PATTERNS = ("*.xml", "*.scxml")
#: Seconds one git command may take.
GIT_TIMEOUT_S = 60


@dataclass
class ChangedModel:
    """One changed model file and what became of it.

    Attributes:
        path: its path in the repository (the NEW name when renamed).
        status: ``modified``, ``added``, ``deleted`` or ``renamed``.
        report: the diff (modified and renamed files whose two versions load).
        error: the one-line error when a version does not load or cannot be compared.
    """

    path: str
    status: str
    report: DiffReport | None = None
    error: str | None = None


@dataclass
class Changes:
    """Every changed model file between two revisions."""

    base: str
    head: str | None
    files: list[ChangedModel] = field(default_factory=list)

    @property
    def changed_behaviour(self) -> bool:
        return any(f.report is not None and not f.report.same for f in self.files)

    @property
    def bad(self) -> bool:
        return any(f.error is not None for f in self.files)

    def markdown(self) -> str:
        """One review comment for all the files."""
        head = self.head or "the working tree"
        lines = [
            f"## fsmbt: behaviour of the models changed between `{self.base}` and `{head}`",
            "",
        ]
        if not self.files:
            lines.append("No model file changed.")
        for f in self.files:
            if f.error is not None:
                lines += [f"### `{f.path}` ({f.status})", "", f"⚠️ {f.error}", ""]
            elif f.report is not None:
                lines += [to_markdown(f.report), ""]
            else:
                lines += [f"### `{f.path}` ({f.status})", ""]
        return "\n".join(lines)


def _git(repo: Path, *args: str) -> str:
    try:
        done = subprocess.run(
            ["git", "-C", str(repo), *args],
            capture_output=True,
            text=True,
            timeout=GIT_TIMEOUT_S,
            check=False,
        )
    except (OSError, subprocess.TimeoutExpired) as exc:
        raise InputError(f"cannot run git: {exc}") from None
    if done.returncode != 0:
        message = done.stderr.strip().splitlines()
        raise InputError(f"git {' '.join(args)}: {message[-1] if message else 'failed'}")
    return done.stdout


def changed_files(
    repo: Path, base: str, head: str | None, patterns: tuple[str, ...]
) -> list[tuple[str, str, str]]:
    """``(status, old path, new path)`` of the changed files matching ``patterns``."""
    args = ["diff", "--name-status", "-M", base] + ([head] if head else [])
    out: list[tuple[str, str, str]] = []
    names = {"M": "modified", "A": "added", "D": "deleted", "R": "renamed", "T": "modified"}
    for line in _git(repo, *args).splitlines():
        parts = line.split("\t")
        if len(parts) < 2:
            continue
        code = parts[0][:1]
        old_path, new_path = parts[1], parts[-1]
        if code not in names:
            continue
        if not any(
            fnmatch.fnmatch(new_path, p) or fnmatch.fnmatch(Path(new_path).name, p)
            for p in patterns
        ):
            continue
        out.append((names[code], old_path, new_path))
    return out


def diff_changes(
    repo: str | Path,
    base: str,
    head: str | None = None,
    *,
    patterns: tuple[str, ...] = DEFAULT_PATTERNS,
    max_groups: int = DEFAULT_MAX_GROUPS,
) -> Changes:
    """Diff every changed model file between ``base`` and ``head`` (``None``: working tree).

    Raises:
        InputError: git fails (not a repository, an unknown revision).
    """
    root = Path(repo)
    changes = Changes(base, head)
    with tempfile.TemporaryDirectory(prefix="fsmbt-diff-") as tmp:
        for status, old_path, new_path in changed_files(root, base, head, patterns):
            item = ChangedModel(new_path, status)
            changes.files.append(item)
            if status == "deleted":
                continue
            try:
                new_file = _version(root, head, new_path, Path(tmp) / "new")
                if not looks_like_a_model(new_file):
                    item.status = "not a model"
                    continue
                if status == "added":
                    api.load(new_file)
                    continue
                old_file = _version(root, base, old_path, Path(tmp) / "old")
                old = api.load(old_file)
                new = api.load(new_file)
                item.report = diff_models(
                    old.model,
                    new.model,
                    old_name=f"{old_path}@{base}",
                    new_name=f"{new_path}@{head or 'worktree'}",
                    max_groups=max_groups,
                )
            except FsmbtError as exc:
                message = str(exc).replace(f"{tmp}/old/", f"{base}:")
                item.error = message.replace(f"{tmp}/new/", f"{head}:")
    return changes


def looks_like_a_model(path: Path) -> bool:
    """Whether some reader recognises the file's content (a ROS ``package.xml`` or a launch
    file matches ``*.xml`` but is no model: it is listed, not refused)."""
    try:
        text = path.read_bytes()[:65536].decode("utf-8", errors="replace")
    except OSError:
        return True  # the reader will say why it cannot be read
    return any(f.read is not None and f.sniff is not None and f.sniff(text) for f in formats())


def _version(repo: Path, rev: str | None, path: str, folder: Path) -> Path:
    """The file at ``rev`` (``None``: the working tree) as a local path."""
    if rev is None:
        return repo / path
    target = folder / path
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_text(_git(repo, "show", f"{rev}:{path}"), encoding="utf-8")
    return target
