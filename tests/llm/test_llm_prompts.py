"""Prompt templates, compact model forms, token budget, answer parsing and LEBT structure checks."""

from __future__ import annotations

from pathlib import Path

import pytest

from fsmbt.formats.registry import dumps
from fsmbt.generate.generator import random_fsm
from fsmbt.llm.client import LLMClient
from fsmbt.llm.config import LLMSettings
from fsmbt.llm.parsing import AnswerError, parse_bt_answer, parse_fsm_answer
from fsmbt.llm.pipeline import convert_with_llm
from fsmbt.llm.prompts import (
    BT_TO_FSM,
    FSM_TO_BT,
    MODULES,
    PromptOptions,
    conversion_messages,
    load_template,
    split_parts,
)
from fsmbt.llm.structural import check_lebt
from fsmbt.llm.tokens import count_messages, count_text, encoding
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM
from support.scripted_server import ScriptedServer

PAPER_BUDGET = 1000  # the paper's upper figure for prompt tokens per conversion


def door() -> FSM:
    fsm = FSM(name="door")
    fsm.add_state("Closed", action="close")
    fsm.add_state("Open", action="open")
    fsm.add_state("Gone", action="leave", final=True)
    fsm.add_transition("Closed", "push", "Open")
    fsm.add_transition("Open", "pull", "Closed")
    fsm.add_transition("Open", "exit", "Gone")
    return fsm


def lebt_xml(fsm: FSM) -> str:
    from fsmbt.convert.engines import converter_for

    return dumps(converter_for("rules", fsm)(fsm, style="lebt").model, "btcpp")


@pytest.mark.parametrize("direction", [FSM_TO_BT, BT_TO_FSM])
def test_templates_have_the_four_parts_and_their_modules(direction: str) -> None:
    parts = split_parts(load_template(direction))
    assert list(parts) == ["Role", "Task", "Stepwise Conversion Procedure", "Constraints"]
    for module in MODULES[direction]:
        assert f"### module: {module}" in parts["Stepwise Conversion Procedure"]
    assert "$model" in parts["Constraints"]


def test_ablation_drops_exactly_one_module() -> None:
    full = conversion_messages(door(), PromptOptions(FSM_TO_BT))[1]["content"]
    ablated = conversion_messages(
        door(), PromptOptions(FSM_TO_BT, disabled_modules=frozenset({"lebt_mapping"}))
    )[1]["content"]
    assert "Entry state:" in ablated and "Entry state:" in full
    assert "Selector subtree of state S" in full and "Selector subtree of state S" not in ablated
    with pytest.raises(InputError, match="unknown SCP module"):
        PromptOptions(FSM_TO_BT, disabled_modules=frozenset({"depth_compression"}))


def test_the_fsm_prompt_spells_out_the_lebt_leaves_and_the_model() -> None:
    text = conversion_messages(door(), PromptOptions(FSM_TO_BT))[1]["content"]
    assert '<LebtGuard target="S" pairs="A/go;B/back"/>' in text
    assert 'LebtState state="S" action="s_act" final="false" exits="go;stop"' in text
    assert "start: __start__ enters Closed with no event" in text
    assert "Closed=close, Open=open, Gone=leave (final)" in text
    assert "Open: pull->Closed, exit->Gone" in text


def test_tiktoken_counts_offline_with_the_real_cl100k_ranks() -> None:
    enc = encoding()
    assert enc.encode("hello world") == [15339, 1917]  # cl100k_base's ids
    assert count_text("") == 0


def test_prompt_tokens_of_30_state_models_stay_within_the_papers_budget() -> None:
    for scenario in ("basic", "robot", "game"):
        for seed in range(3):
            fsm = random_fsm(seed, 30, scenario)
            assert len(fsm.states) == 30
            tokens = count_messages(conversion_messages(fsm, PromptOptions(FSM_TO_BT)))
            assert tokens <= PAPER_BUDGET, (scenario, seed, tokens)


def test_parsing_tolerates_fences_and_chatter_but_not_bad_content() -> None:
    xml = lebt_xml(door())
    assert parse_bt_answer(f"Sure.\n```xml\n{xml}```\nDone!").main.root is not None
    assert parse_bt_answer(f"Here you go: {xml} -- enjoy").main.root is not None
    with pytest.raises(AnswerError, match="no BT.CPP XML"):
        parse_bt_answer("I would need more information.")
    with pytest.raises(AnswerError):
        parse_bt_answer(
            "<root BTCPP_format='4'><BehaviorTree ID='M'><Sequence></BehaviorTree></root>"
        )
    fsm = parse_fsm_answer(
        '```\n{"initial": "a", "states": [{"name": "a"}], "transitions": []}\n```'
    )
    assert fsm.initial == "a"  # a missing "kind" is tolerated in an FSM answer
    with pytest.raises(AnswerError, match="expected an FSM"):
        parse_fsm_answer('{"kind": "bt", "trees": []}')
    with pytest.raises(AnswerError, match="invalid JSON"):
        parse_fsm_answer('{"states": [}')


def test_the_structural_check_names_missing_duplicate_and_dangling_nodes() -> None:
    fsm = door()
    xml = lebt_xml(fsm)
    assert check_lebt(fsm, parse_bt_answer(xml)) == []
    missing = xml.replace('state="Gone"', 'state="Gon"')
    problems = check_lebt(fsm, parse_bt_answer(missing))
    assert "state Gone has no LebtState node" in problems
    assert any("names state 'Gon', which the FSM does not have" in p for p in problems)
    dangling = xml.replace('pairs="Open/exit"', 'pairs="Closed/exit"')
    assert any(
        "no transition Closed --exit--> Gone" in p
        for p in check_lebt(fsm, parse_bt_answer(dangling))
    )
    wrong_port = xml.replace('action="leave"', 'action="stay"')
    assert any(
        "must have action='leave'" in p for p in check_lebt(fsm, parse_bt_answer(wrong_port))
    )
    doubled = xml.replace(
        "</Sequence>\n  </BehaviorTree>",
        '<LebtState state="Open" action="open" final="false" exits="pull;exit"/>'
        "</Sequence>\n  </BehaviorTree>",
        1,
    )
    assert doubled != xml
    assert any("Open has 2 LebtState nodes" in p for p in check_lebt(fsm, parse_bt_answer(doubled)))


def test_fsm_to_bt_round_with_a_scripted_correct_lebt(tmp_path: Path) -> None:
    fsm = door()
    answer = "```xml\n" + lebt_xml(fsm) + "```"
    broken = answer.replace('exits="pull;exit"', 'exits="pull"')
    with ScriptedServer([{"content": broken}, {"content": answer}]) as server:
        client = LLMClient(
            LLMSettings(
                base_url=server.base_url,
                model="m",
                api_key="k",
                backoff_s=0.01,
                timeout_s=5,
                log_path=None,
            )
        )
        outcome = convert_with_llm(fsm, client)
    assert outcome.equivalent and outcome.record.regenerations == 1
    assert "must have exits='pull;exit'" in server.requests[1]["body"]["messages"][-1]["content"]


@pytest.mark.parametrize("extended", [False, True])
def test_the_structural_checks_accept_every_verified_rules_result(extended: bool) -> None:
    """A correct answer must never be rejected before verification: the rules engine's results,
    which the checker proves equivalent, pass both structural checks."""
    from fsmbt.convert.engines import converter_for
    from fsmbt.generate.generator import random_bt
    from fsmbt.llm.structural import check_hfsm
    from fsmbt.model.flatten import flatten
    from fsmbt.verify import verify

    for seed in range(8):
        bt = random_bt(seed, 4, 3, "robot", extended=extended, max_nodes=30)
        hfsm = converter_for("rules", bt)(bt).model
        assert verify(bt, hfsm).equivalent
        assert check_hfsm(bt, hfsm) == [], seed
        fsm = random_fsm(seed, 8 + seed)
        lebt = converter_for("rules", fsm)(fsm, style="lebt").model
        assert verify(fsm, lebt).equivalent
        assert check_lebt(flatten(fsm), lebt) == [], seed
