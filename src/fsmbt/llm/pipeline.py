"""The paper's LLM conversion loop: generate -> parse -> structural check -> verify -> feedback.

Each round asks the model, reads its answer strictly (``parsing``), checks its structure
(``structural``) and then its behavior with the project's checker (``fsmbt.verify``, native by
default, NuSMV when asked). A failing round sends back the concrete problems and the shortest
counterexample, rendered step by step, together with the model's own previous answer, and asks
again, at most ``max_regenerations`` times. The conversation is kept to the original prompt plus
the latest answer and feedback, so its size does not grow with the number of rounds.

Every conversion is recorded (first-pass success, regenerations, tokens, latency, verdict) in
the JSONL log. Correctness never rests on the model: a result is only called equivalent when
the checker says so.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass

from fsmbt.llm.client import LLMClient, Message
from fsmbt.llm.config import LLMUnavailableError
from fsmbt.llm.log import (
    EQUIVALENT,
    INVALID_ANSWER,
    NOT_EQUIVALENT,
    UNAVAILABLE,
    ConversionRecord,
    RoundRecord,
    append_record,
)
from fsmbt.llm.parsing import AnswerError, parse_bt_answer, parse_fsm_answer
from fsmbt.llm.prompts import (
    BT_TO_FSM,
    FSM_TO_BT,
    PromptOptions,
    conversion_messages,
    feedback_message,
)
from fsmbt.llm.structural import check_hfsm, check_lebt
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import FsmbtError
from fsmbt.model.flatten import flatten
from fsmbt.model.fsm import FSM
from fsmbt.verify.report import Report

Model = FSM | BTDocument
Verifier = Callable[[Model, Model], Report]

OUTPUT_FORMAT = {FSM_TO_BT: "BT.CPP XML", BT_TO_FSM: "fsmbt JSON"}
MAX_TRACE_STEPS = 20


@dataclass
class LLMOutcome:
    """What a conversion produced: the last usable result, its report, and the record."""

    result: Model | None
    report: Report | None
    record: ConversionRecord

    @property
    def equivalent(self) -> bool:
        return self.report is not None and self.report.equivalent


def direction_for(model: Model) -> str:
    return FSM_TO_BT if isinstance(model, FSM) else BT_TO_FSM


def default_verifier(engine: str = "native") -> Verifier:
    """The project's checker through its public API (imported late: it is optional here)."""

    def run(source: Model, result: Model) -> Report:
        from fsmbt.verify import verify

        return verify(source, result, engine=engine)

    return run


def convert_with_llm(
    source: Model,
    client: LLMClient,
    *,
    scp: bool = True,
    disabled_modules: Iterable[str] = (),
    max_regenerations: int | None = None,
    verifier: Verifier | None = None,
    engine_name: str | None = None,
    source_name: str = "<input>",
) -> LLMOutcome:
    """Convert ``source`` (FSM -> LEBT, BT -> HFSM) with the model behind ``client``.

    Raises ``LLMUnavailableError`` when the endpoint fails (after logging the attempt). Returns
    an ``LLMOutcome`` otherwise, equivalent or not.
    """
    direction = direction_for(source)
    options = PromptOptions(direction, scp=scp, disabled_modules=frozenset(disabled_modules))
    settings = client.settings
    rounds_allowed = 1 + (
        settings.max_regenerations if max_regenerations is None else max_regenerations
    )
    verify = verifier or default_verifier()
    flat_source = flatten(source) if isinstance(source, FSM) else None
    record = ConversionRecord(
        engine=engine_name or ("llm" if scp else "nllm"),
        task=direction,
        prompt=options.label,
        model=settings.model,
        source=source_name,
    )
    prompt = conversion_messages(flat_source if flat_source is not None else source, options)
    conversation: list[Message] = list(prompt)
    result: Model | None = None
    report: Report | None = None
    try:
        for round_no in range(rounds_allowed):
            completion = client.complete(conversation)
            stage, problems, counterexample, candidate, candidate_report = _judge(
                source, flat_source, completion.text, verify
            )
            if candidate is not None:
                result, report = candidate, candidate_report
            record.add_round(
                RoundRecord(
                    round_no,
                    stage,
                    problems,
                    completion.tokens_in,
                    completion.tokens_out,
                    round(completion.latency_s, 4),
                    completion.attempts,
                    list(completion.failures),
                )
            )
            if stage == "ok":
                break
            conversation = prompt + [
                {"role": "assistant", "content": completion.text},
                feedback_message(problems, counterexample, OUTPUT_FORMAT[direction]),
            ]
    except LLMUnavailableError as exc:
        # the round that could not be completed is recorded with each attempt's cause; the
        # rounds before it and their best result stay in the record and on the exception
        record.add_round(
            RoundRecord(
                len(record.rounds),
                "unavailable",
                [str(exc)],
                0,
                0,
                0.0,
                len(exc.failures),
                list(exc.failures),
            )
        )
        record.verdict = UNAVAILABLE
        record.extra["error"] = str(exc)
        append_record(settings.log_path, record)
        exc.outcome = LLMOutcome(result, report, record)
        raise
    if report is not None:
        record.verdict = EQUIVALENT if report.equivalent else NOT_EQUIVALENT
    else:
        record.verdict = INVALID_ANSWER
    append_record(settings.log_path, record)
    return LLMOutcome(result, report, record)


def _judge(
    source: Model, flat_source: FSM | None, answer: str, verify: Verifier
) -> tuple[str, list[str], str | None, Model | None, Report | None]:
    """(stage, problems, counterexample text, parsed result, report) of one answer."""
    try:
        result: Model = (
            parse_bt_answer(answer) if flat_source is not None else parse_fsm_answer(answer)
        )
    except AnswerError as exc:
        return "parse", [str(exc)], None, None, None
    if flat_source is not None:
        assert isinstance(result, BTDocument)
        problems = check_lebt(flat_source, result)
    else:
        assert isinstance(source, BTDocument) and isinstance(result, FSM)
        problems = check_hfsm(source, result)
    if problems:
        return "structure", problems, None, None, None
    try:
        report = verify(source, result)
    except FsmbtError as exc:
        return "verify", [f"the checker rejected the answer: {exc}"], None, None, None
    if report.equivalent:
        return "ok", [], None, result, report
    failing = [p for p in report.properties.values() if not p.holds]
    problems = [f"{p.name} fails: {p.detail}".rstrip(": ") for p in failing] or [
        "the checker found the result not equivalent"
    ]
    return "verify", problems, render_counterexample(report), result, report


def render_counterexample(report: Report) -> str | None:
    """The shortest failing trace, one step a line, in words the model can act on."""
    traces = [
        (p.name, p.counterexample)
        for p in report.properties.values()
        if not p.holds and p.counterexample
    ]
    if not traces:
        return None
    name, steps = min(traces, key=lambda item: len(item[1]))
    leaf_mode = "leaf" in report.mode
    what = "leaf outcome" if leaf_mode else "event"
    lines = [f"(property {name}; source = the given model, yours = your answer)"]
    for step in steps[:MAX_TRACE_STEPS]:
        given = "start" if step.input is None else f"{what} {step.input}"
        lines.append(
            f"{step.step}. {given}: source ran [{', '.join(step.source_outputs)}] and is in "
            f"{step.source_state} ({step.source_status}); yours ran [{', '.join(step.result_outputs)}] "
            f"and is in {step.result_state} ({step.result_status})"
        )
    if len(steps) > MAX_TRACE_STEPS:
        lines.append(f"... {len(steps) - MAX_TRACE_STEPS} more step(s)")
    return "\n".join(lines)
