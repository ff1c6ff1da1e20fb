"""One tree, one scripted environment, two engines: fsmbt's interpreter and BehaviorTree.CPP
(``BTCppRunner``) tick the same tree ``tickOnce`` by ``tickOnce`` and must record the same
ticks, and raise an error at the same tick or not at all (the differential tests of
tests/semantics)."""

from __future__ import annotations

from fsmbt.model.bt import BTDocument
from fsmbt.semantics.bt_interpreter import BTLivelock, BTRunner, BTRuntimeError
from support.random_trees import OutcomeScript

TICKS = 8


def interpreter_trace(
    doc: BTDocument, script: OutcomeScript, exactly_once: bool, ticks: int = TICKS
) -> tuple[list | None, BTRuntimeError | None]:
    """fsmbt's records of ``ticks`` ticks and the error that stopped them, or ``(None, None)``
    when a tick would not return (a livelock: BehaviorTree.CPP would not return either)."""
    runner = BTRunner(doc, script, exactly_once=exactly_once, max_leaf_ticks_per_tick=200)
    records, error = [], None
    try:
        for _ in range(ticks):
            records.append(runner.tick_once())
    except BTLivelock:
        return None, None
    except BTRuntimeError as exc:
        if "does not end" in str(exc):
            return None, None
        error = exc
    return records, error


def matches_btcpp(
    doc: BTDocument, script: OutcomeScript, exactly_once: bool, label: object
) -> bool:
    """Assert that BehaviorTree.CPP ticks ``doc`` as fsmbt does (``label`` names the case in a
    failure); ``False`` when there is nothing to compare (a tick would not return)."""
    from fsmbt.semantics.engines.btcpp_engine import BTCppRunner

    ours, error = interpreter_trace(doc, script, exactly_once)
    if ours is None:
        return False
    engine = BTCppRunner(doc, script.fresh(), exactly_once=exactly_once)
    theirs, engine_error = [], None
    try:
        for _ in range(len(ours) + (1 if error else 0)):
            theirs.append(engine.tick_once())
    except Exception as exc:  # noqa: BLE001 - BehaviorTree.CPP's logic_error
        engine_error = exc
    assert (error is None) == (engine_error is None), (label, error, engine_error, engine.xml)
    assert theirs[: len(ours)] == ours, (label, engine.xml)
    return True
