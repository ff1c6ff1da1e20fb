"""Does python-statemachine load an SCXML document fsmbt wrote? The load check of every written
state machine (docs/semantics.md §5, "Every written tree loads").

Rule: where python-statemachine (a W3C SCXML engine written by others; fsmbt's test oracle,
issue 11) is installed, ``convert`` loads each SCXML result with
``statemachine.io.loader.load(text, format="scxml")`` and makes one instance (which enters the
initial configuration, as a user's first step would); an exception is a refusal - a located
error, never a verdict. Without python-statemachine there is no check (``None``) and the summary
says nothing about it. The text is fsmbt's own writer's: expressions are evaluated by the
engine's safe evaluator, no user code is imported.

Costs: the engine's parse and one start, O(document size).
"""

from __future__ import annotations

import contextlib
import dataclasses
import gc
import io
import json
import os
import sys
from typing import NoReturn

from fsmbt.semantics.engines.btcpp_load import LoadCheck

ENGINE = "python-statemachine"


def engine_name() -> str | None:
    """``python-statemachine 3.2.2`` when it imports, else ``None``."""
    try:
        import statemachine
    except ImportError:
        return None
    return f"{ENGINE} {getattr(statemachine, '__version__', '')}".strip()


def check_scxml_loads(text: str) -> LoadCheck | None:
    """Load ``text`` in python-statemachine and start one instance; ``None`` without it."""
    engine = engine_name()
    if engine is None:
        return None
    from statemachine.io.loader import load

    try:
        with contextlib.redirect_stdout(io.StringIO()):  # the engine prints <log> content
            chart = load(text, format="scxml")
            chart()
    except Exception as exc:  # the engine's own error classes, whatever they are
        message = " ".join(f"{type(exc).__name__}: {exc}".split())[:600]
        return LoadCheck(engine, False, message)
    return LoadCheck(engine, True)


def main() -> NoReturn:
    """``python -m fsmbt.semantics.engines.scxml_load [FILE]``: the check of the SCXML text in
    FILE (else on standard input), answered as one JSON line (the ``LoadCheck``'s fields;
    ``null`` without python-statemachine). ``load_beside`` runs it beside a proof.

    The cyclic garbage collector is off in this process: the engine builds a few hundred
    thousand objects per 10 000 states (states, transitions, callback lists), all alive until
    the process ends, and the collector's passes over them cost more than the load itself
    (the 15 560-node ``mixed`` chart: 8-12 s of CPU with it, 3.6-4.8 s without, at load 3-4;
    the peak memory is the same, 430 MB, as the engine leaves almost no cyclic garbage -
    ``benchmarks/bench_load_check.py`` measures both back to back). The engine's work and answer do not change: the
    collector only frees unreachable cycles, and the process exits after one answer. A
    document whose load would need the collector to stay within the address-space cap
    (``load_beside.LOAD_MAX_MEMORY_MB``) ends as a refusal that says the check gave no answer,
    never as a pass."""
    gc.disable()
    if len(sys.argv) > 1:
        with open(sys.argv[1], encoding="utf-8") as handle:
            text = handle.read()
    else:
        text = sys.stdin.read()
    answer = check_scxml_loads(text)
    # the answer to the parent process (a protocol it reads, not presentation)
    sys.stdout.write(json.dumps(None if answer is None else dataclasses.asdict(answer)) + "\n")
    sys.stdout.flush()
    # the answer is out: skip the interpreter's teardown, which frees the engine's chart object
    # by object (about 3.5 s for a 15 000-state chart, half as long as the check itself)
    os._exit(0)


if __name__ == "__main__":
    main()
