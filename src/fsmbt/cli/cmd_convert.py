"""``fsmbt convert``: convert a model (direction from its kind), verify the result, report.

The converted model goes to ``-o`` (never overwriting without ``--force``) or to stdout; the
verdict and the conversion's figures go to stderr then, so stdout stays a clean model. Exit 0
when equivalent (or ``--no-verify``), 1 when not, 2 on bad input.

The LLM engines (``llm``, ``nllm``, ``hybrid``) read the input through
``fsmbt.llm.extract.read_input``, so prose, unknown notations and diagrams reach the model's
extraction step (``hybrid`` asks the LLM only when no parser reads the file);
``--llm-base-url`` / ``--llm-model`` go to the engine as ``llm_base_url`` / ``llm_model``.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import typer

from fsmbt.convert import convert
from fsmbt.formats import dumps, read_model, write_model
from fsmbt.formats.registry import format_for_path
from fsmbt.model.fsm import FSM

DEFAULT_FSM_FORMAT = "scxml"  # BT -> FSM: nested states survive
DEFAULT_BT_FORMAT = "btcpp"   # FSM -> BT: BehaviorTree.CPP v4 XML with TreeNodesModel
LLM_ENGINES = ("llm", "nllm", "hybrid")


def _read_source(source: Path, source_format: str | None, engine: str,
                 options: dict[str, object]):
    """The source model; for the LLM engines through ``read_input`` (LLM extraction when no
    parser reads it), recording the client and provenance in ``options`` for the engine."""
    if engine not in LLM_ENGINES:
        return read_model(source, source_format)
    from fsmbt.llm.engine import client_from_options
    from fsmbt.llm.extract import needs_llm, read_input

    client = None
    if engine != "hybrid" or needs_llm(source, source_format):
        client = client_from_options(options)  # LLMConfigError (exit 2) when none is set up
    loaded = read_input(source, source_format, client=client)
    options.update(client=client, source_name=str(source), extracted_by_llm=loaded.extracted)
    return loaded.model


def register(app: typer.Typer) -> None:
    @app.command("convert")
    def convert_command(
        source: Path = typer.Argument(..., help="the model to convert (FSM or BT)"),
        output: Path | None = typer.Option(None, "-o", "--output",
                                           help="write here (default: stdout)"),
        to: str | None = typer.Option(None, "--to", help="output format (default: from -o's "
                                      "extension, else btcpp for a BT, scxml for an FSM)"),
        source_format: str | None = typer.Option(None, "--from", help="input format"),
        engine: str = typer.Option("rules", "--engine", help="rules, or a registered engine"),
        style: str = typer.Option("paper", "--style", help="output structure style"),
        loop: bool = typer.Option(False, "--loop", help="BT->FSM: the root is ticked again "
                                  "after it returns (checked in loop mode)"),
        no_verify: bool = typer.Option(False, "--no-verify", help="skip the equivalence check"),
        force: bool = typer.Option(False, "--force", help="overwrite an existing output file"),
        as_json: bool = typer.Option(False, "--json", help="print a JSON summary on stdout"),
        hierarchy: str = typer.Option("subtrees", "--hierarchy", help="FSM->BT of a "
                                      "hierarchical FSM: subtrees (one SubTree per composite "
                                      "state) or flatten (one flat LEBT)"),
        llm_base_url: str | None = typer.Option(None, "--llm-base-url", help="LLM engines: "
                                                "endpoint URL or provider (openai, deepseek, "
                                                "qwen, ollama, vllm)"),
        llm_model: str | None = typer.Option(None, "--llm-model", help="LLM engines: model "
                                             "name"),
    ) -> None:
        """Convert an FSM into a behavior tree or a behavior tree into a hierarchical FSM, and
        prove the result equivalent."""
        options: dict[str, object] = {}
        if engine in LLM_ENGINES:
            options.update(llm_base_url=llm_base_url, llm_model=llm_model)
        model = _read_source(source, source_format, engine, options)
        if loop:
            options["loop"] = True
        if engine == "rules" and isinstance(model, FSM):
            options["hierarchy"] = hierarchy
        result = convert(model, engine=engine, style=style, **options)
        kind = "fsm" if isinstance(result.model, FSM) else "bt"
        fmt = to
        if fmt is None and output is not None:
            guessed = format_for_path(output, writing=True, kind=kind)
            fmt = guessed.name if guessed is not None else None
        if fmt is None:
            fmt = DEFAULT_FSM_FORMAT if kind == "fsm" else DEFAULT_BT_FORMAT
        text: str | None = None
        if output is not None:
            write_model(result.model, output, fmt, overwrite=force)
        else:
            text = dumps(result.model, fmt)

        report = None
        if not no_verify:
            from fsmbt.verify import verify

            report = verify(model, result.model, loop=loop)
        summary = {
            "source": str(source),
            "output": str(output) if output is not None else None,
            "format": fmt,
            "engine": result.engine,
            "direction": result.direction,
            "stats": result.stats,
            "warnings": result.warnings,
            "equivalent": report.equivalent if report is not None else None,
            "properties": report.verdicts() if report is not None else None,
        }
        if as_json:
            if text is not None:
                summary["model"] = text
            print(json.dumps(summary, indent=2, default=str))
        else:
            if text is not None:
                sys.stdout.write(text)
            _print_summary(summary, report, to_stderr=text is not None)
        if report is not None and not report.equivalent:
            raise typer.Exit(1)


def _print_summary(summary: dict, report, *, to_stderr: bool) -> None:
    stream = sys.stderr if to_stderr else sys.stdout
    for warning in summary["warnings"]:
        print(f"warning: {warning}", file=stream)
    figures = ", ".join(f"{k}={v}" for k, v in summary["stats"].items())
    where = summary["output"] or "stdout"
    print(f"converted {summary['direction']} with {summary['engine']} -> {where} "
          f"({summary['format']}): {figures}", file=stream)
    if report is None:
        print("verification skipped (--no-verify)", file=stream)
        return
    verdict = "EQUIVALENT" if report.equivalent else "NOT EQUIVALENT"
    print(f"verdict: {verdict}", file=stream)
    for name, prop in report.properties.items():
        mark = "ok  " if prop.holds else "FAIL"
        print(f"  {mark} {name}: {prop.detail}", file=stream)
