"""The library's error hints (``fsmbt.model.errors.Hint``) worded as this CLI's flags.

The library names a way past an error in its own terms; the CLI prints it as the flag or command
that does the same, so ``str(error)`` never mentions a flag and a CLI user still reads one.
Every ``Hint`` has an entry (asserted by the tests).
"""

from __future__ import annotations

from collections.abc import Mapping

from fsmbt.model.errors import FsmbtError, Hint

CLI_WORDING: Mapping[Hint, str] = {
    Hint.INPUT_FORMAT: "name it with --from",
    Hint.OUTPUT_FORMAT: "use --to",
    Hint.OVERWRITE: "pass --force to overwrite it",
    Hint.NATIVE_VERIFIER: "use --engine native",
    Hint.RULES_ENGINE: "use --engine rules",
    Hint.LLM_ENGINE: "use --engine llm|nllm|hybrid, or fsmbt llm extract",
    Hint.MAX_NODES: "raise the limit with --max-nodes",
    Hint.MAX_STATES: "raise the limit with --max-states",
    Hint.STATISTICS: "use `fsmbt info` for its structure",
    Hint.NO_EXPANSION: "draw without --expand-subtrees",
    Hint.LLM_BASE_URL: "set --llm-base-url",
    Hint.LLM_MODEL: "set --llm-model",
    Hint.NUSMV_LIMITS: "raise the cap with --timeout SECONDS or --nusmv-memory MIB",
    Hint.CHECKER_TIME: "raise the limit with --timeout SECONDS",
}


def cli_message(error: FsmbtError) -> str:
    """The one-line report of ``error`` with its hints worded as CLI flags.

    Args:
        error: any fsmbt error.

    Returns:
        ``location: element: message; flag hint or flag hint``.
    """
    return error.text(CLI_WORDING)
