"""``validate`` and ``convert`` agree on every well-formed corpus BT (issue 12 part 5, issue 25):
a file ``validate`` finds no error and no "cannot convert" warning in is not refused by
``convert``, and a file ``convert`` refuses has an error or a ``cannot-convert`` /
``unknown-semantics`` finding at the place convert names (an error with ``--strict``); ``info`` lists what would be refused.
Skips only when the corpus folder is absent (FSMBT_CORPUS)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.cli import main
from fsmbt.model.errors import InputError
from support.corpus import CORPUS


def _bt_files() -> list[Path]:
    root = CORPUS / "bt"
    if not root.is_dir():
        return []
    return sorted(
        p for p in root.rglob("*.xml") if "_malformed" not in p.parts and "models" not in p.parts
    )


def _refusal(issue: dict[str, object]) -> bool:
    """An error, or a warning that conversion would refuse the model there."""
    return issue["severity"] == "error" or issue["code"] in ("cannot-convert", "unknown-semantics")


def test_validate_and_convert_agree_on_the_corpus(capsys: pytest.CaptureFixture[str]) -> None:
    files = _bt_files()
    if not files:
        pytest.skip(f"corpus not found at {CORPUS} (set FSMBT_CORPUS)")
    disagreements: list[str] = []
    refused = 0
    for path in files:
        code = main(["validate", str(path), "--json"])
        captured = capsys.readouterr()
        if not captured.out:  # the file itself cannot be read: validate says why, on stderr
            assert code == 2 and captured.err.startswith("error:"), path
            with pytest.raises(InputError):
                api.convert_file(path, verify=False)  # and convert refuses it as well
            refused += 1
            continue
        report = json.loads(captured.out)
        try:
            api.convert_file(path, verify=False)
            converts = True
        except InputError as exc:
            converts = False
            refused += 1
            error_lines = {i["line"] for i in report["issues"] if _refusal(i)}
            if exc.location is not None and exc.location.line not in error_lines:
                disagreements.append(
                    f"{path.name}: convert refuses at {exc.location}, "
                    f"validate names no error there ({sorted(error_lines)})"
                )
        clean = code == 0 and not any(_refusal(i) for i in report["issues"])
        if clean != converts:
            disagreements.append(
                f"{path.name}: validate exit {code}, convert "
                f"{'converts' if converts else 'refuses'}"
            )
        if not converts:  # --strict makes the refusal an error
            assert main(["validate", str(path), "--strict", "--json"]) == 2, path
            capsys.readouterr()
    assert disagreements == []
    assert refused > 0  # the corpus has files conversion refuses: the check is not vacuous


def test_info_lists_every_blocker(capsys: pytest.CaptureFixture[str]) -> None:
    path = CORPUS / "bt" / "bt_in_action" / "julienbayle_stardust_r2_bt.xml"
    if not path.is_file():
        pytest.skip(f"corpus not found at {CORPUS} (set FSMBT_CORPUS)")
    assert main(["info", str(path), "--json"]) == 0
    blockers = json.loads(capsys.readouterr().out)["conversion_blockers"]
    assert len(blockers) >= 2  # every one, not only the first
    assert any("BlackboardCheckString" in b and "--abstract blackboard" in b for b in blockers)
    # with the abstraction only the project's own custom control remains
    # the bundled library found by itself gives the project's RealParallel its semantics
    assert not any("RealParallel" in b for b in blockers)
    # with the abstraction and without profiles only the project's own custom control remains
    assert main(["info", str(path), "--json", "--abstract", "blackboard", "--no-profiles"]) == 0
    left = json.loads(capsys.readouterr().out)["conversion_blockers"]
    assert left and all("RealParallel" in b for b in left)
    assert main(["info", str(path), "--json", "--abstract", "blackboard"]) == 0
    assert json.loads(capsys.readouterr().out)["conversion_blockers"] == []
