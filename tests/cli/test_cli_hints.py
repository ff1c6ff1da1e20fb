"""Library errors name no CLI flag; the CLI words their hints as its flags (fsmbt.cli.hints)."""

from __future__ import annotations

from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.cli import main
from fsmbt.cli.hints import CLI_WORDING
from fsmbt.formats import loads
from fsmbt.llm.config import LLMConfigError, resolve_settings
from fsmbt.model import FSM, InputError, State
from fsmbt.model.errors import HINT_TEXT, Hint
from fsmbt.render import TooLargeError, fsm_to_dot

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def small_fsm() -> FSM:
    fsm = FSM(name="m")
    for name in ("a", "b", "c"):
        fsm.add_state(State(name))
    fsm.add_transition("a", "go", "b")
    fsm.add_transition("b", "go", "c")
    return fsm


def test_every_hint_has_library_and_cli_words() -> None:
    assert set(HINT_TEXT) == set(Hint) == set(CLI_WORDING)
    assert not any("--" in text for text in HINT_TEXT.values())
    assert all("--" in text or "fsmbt " in text for text in CLI_WORDING.values())


def test_library_errors_carry_hints_and_name_no_flag(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    target = tmp_path / "m.json"
    api.write(small_fsm(), target)
    with pytest.raises(InputError) as exists:
        api.write(small_fsm(), target)
    with pytest.raises(InputError) as unknown:
        loads("no reader knows this\n")
    with pytest.raises(InputError) as no_suffix:
        api.write(small_fsm(), tmp_path / "m.unknown-suffix")
    with pytest.raises(TooLargeError) as too_large:
        fsm_to_dot(small_fsm(), max_nodes=2)
    for name in ("FSMBT_LLM_BASE_URL", "FSMBT_LLM_MODEL", "FSMBT_LLM_CONFIG"):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("HOME", str(tmp_path))
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "config"))
    monkeypatch.chdir(tmp_path)
    with pytest.raises(LLMConfigError) as no_llm:
        resolve_settings()
    cases = [
        (exists, (Hint.OVERWRITE,)),
        (unknown, (Hint.INPUT_FORMAT,)),
        (no_suffix, (Hint.OUTPUT_FORMAT,)),
        (too_large, (Hint.MAX_NODES, Hint.STATISTICS)),
        (no_llm, (Hint.LLM_BASE_URL, Hint.RULES_ENGINE)),
    ]
    for caught, hints in cases:
        assert caught.value.hints == hints
        text = str(caught.value)
        assert "--" not in text, text
        assert all(HINT_TEXT[h] in text for h in hints), text
        cli = caught.value.text(CLI_WORDING)
        assert all(CLI_WORDING[h] in cli for h in hints), cli


def test_cli_prints_the_flag(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "bt.xml"
    out.write_text("taken", encoding="utf-8")
    assert main(["convert", str(EXAMPLES / "paper_fsm.json"), "-o", str(out)]) == 2
    assert "exists; pass --force to overwrite it" in capsys.readouterr().err
    assert out.read_text(encoding="utf-8") == "taken"
    odd = tmp_path / "odd.model"
    odd.write_text("no reader knows this\n", encoding="utf-8")
    assert main(["info", str(odd)]) == 2
    err = capsys.readouterr().err
    assert "cannot tell the format of this input" in err and "name it with --from" in err
    assert (
        main(
            [
                "render",
                str(EXAMPLES / "paper_fsm.json"),
                "-o",
                str(tmp_path / "p.svg"),
                "--max-nodes",
                "2",
            ]
        )
        == 2
    )
    err = capsys.readouterr().err
    assert "too large to draw" in err and "--max-nodes" in err and "fsmbt info" in err
    assert len(err.strip().splitlines()) == 1


def test_wrapped_errors_keep_their_hints() -> None:
    fsm = api.load(EXAMPLES / "paper_fsm.json").model
    try:
        fsm_to_dot(fsm, max_nodes=1)
    except TooLargeError as exc:
        again = InputError(exc.message, location=exc.location, hints=exc.hints)
        assert again.text(CLI_WORDING).endswith(
            "raise the limit with --max-nodes or use `fsmbt info` for its structure"
        )
    else:  # pragma: no cover - the example has more than one state
        pytest.fail("not refused")
