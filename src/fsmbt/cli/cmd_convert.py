"""``fsmbt convert``: convert a model (direction from its kind), verify the result, report.

Option parsing and printing around ``fsmbt.api.convert_file``, which does the work. The
destination is checked before anything else; the result goes to ``-o`` (never overwriting
without ``--force``) or to stdout, and is written only when it is equivalent (or
``--no-verify``), unless ``--keep-failed``. With stdout as the output the verdict and figures
go to stderr, so stdout stays a clean model. Exit 0 when equivalent (or ``--no-verify``), 1 when
not, 2 on bad input.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Literal

import typer

from fsmbt import api
from fsmbt.api_types import ReadOptions
from fsmbt.cli.certificates import certificate_option, write_certificate
from fsmbt.cli.options import (
    apply_engine_caps,
    max_states_option,
    nusmv_memory_option,
    reads_models,
    timeout_option,
)
from fsmbt.cli.progress import StageProgress, format_timings
from fsmbt.cli.wording import checked_counts, conversion_summary
from fsmbt.llm.config import PROVIDERS
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError
from fsmbt.model.undeclared import summary as undeclared_summary
from fsmbt.model.undeclared import undeclared_leaf_types
from fsmbt.verify import certificate
from fsmbt.verify.report import Report

PROVIDER_NAMES = ", ".join(sorted(PROVIDERS))


def register(app: typer.Typer) -> None:
    @app.command("convert")
    @reads_models
    def convert_command(
        source: Path = typer.Argument(..., help="the model to convert (FSM or BT)"),
        output: Path | None = typer.Option(
            None, "-o", "--output", help="write here (default: stdout)"
        ),
        to: str | None = typer.Option(
            None,
            "--to",
            help="output format (default: from -o's "
            "extension, else btcpp for a BT, scxml for an FSM)",
        ),
        engine: str = typer.Option("rules", "--engine", help="rules, or a registered engine"),
        style: str = typer.Option(
            "auto",
            "--style",
            help="FSM->BT: auto (structured for SMACH/FlexBE/YASMIN and machines that declare "
            "outcomes, else dispatch), structured, dispatch, lebt (paper is lebt)",
        ),
        outcomes: str | None = typer.Option(
            None,
            "--outcomes",
            help="structured style: outcome statuses, e.g. arrived=success,lost=failure",
        ),
        loop: bool = typer.Option(
            False,
            "--loop",
            help="BT->FSM: the root is ticked again after it returns (checked in loop mode)",
        ),
        unroll: bool = typer.Option(
            False,
            "--unroll",
            help="BT->FSM: keep the tree's memory (retry counts, running indices) as states "
            "instead of SCXML data (a flat product, for tools without a data model)",
        ),
        no_verify: bool = typer.Option(False, "--no-verify", help="skip the equivalence check"),
        no_load_check: bool = typer.Option(
            False,
            "--no-load-check",
            help="FSM->BT: do not load the written tree in BehaviorTree.CPP 4.8.2 (by default a "
            "tree the engine refuses is an error)",
        ),
        verify_engine: str = typer.Option(
            "native",
            "--verify-engine",
            help="the equivalence check's engine: native, nusmv or both",
        ),
        force: bool = typer.Option(False, "--force", help="overwrite an existing output file"),
        keep_failed: bool = typer.Option(
            False,
            "--keep-failed",
            help="write the result even when it is not equivalent (default: not written)",
        ),
        as_json: bool = typer.Option(False, "--json", help="print a JSON summary on stdout"),
        quiet: bool = typer.Option(
            False,
            "--quiet",
            "-q",
            help="no progress display, and of the summary only warnings and the verdict line",
        ),
        no_progress: bool = typer.Option(
            False, "--no-progress", help="no progress display on stderr (the full summary stays)"
        ),
        max_states: int | None = max_states_option(),
        hierarchy: Literal["subtrees", "flatten"] = typer.Option(
            "subtrees",
            "--hierarchy",
            help="FSM->BT of a "
            "hierarchical FSM: subtrees (one SubTree per composite "
            "state, LEBT or dispatch form) or flatten (the machine flattened first)",
        ),
        llm_base_url: str | None = typer.Option(
            None, "--llm-base-url", help=f"LLM engines: endpoint URL or provider ({PROVIDER_NAMES})"
        ),
        llm_model: str | None = typer.Option(None, "--llm-model", help="LLM engines: model name"),
        timeout: float | None = timeout_option(),
        nusmv_memory: int | None = nusmv_memory_option(),
        certificate_file: Path | None = certificate_option(),
        *,
        read: ReadOptions,
    ) -> None:
        """Convert an FSM into a behavior tree or a behavior tree into a hierarchical FSM, and
        prove the result equivalent."""
        apply_engine_caps(timeout, nusmv_memory)
        engine_options: dict[str, object] = {}
        if engine in api.LLM_ENGINES:
            engine_options.update(llm_base_url=llm_base_url, llm_model=llm_model)
        if unroll:
            engine_options["unroll"] = True
        request = api.convert_request(
            to=to,
            engine=engine,
            style=style,
            loop=loop,
            hierarchy=hierarchy,
            verify=not no_verify,
            verify_engine=verify_engine,
            load_check=not no_load_check,
            overwrite=force,
            max_states=max_states,
            keep_not_equivalent=keep_failed,
            outcomes=outcomes,
            read=read,
            engine_options=engine_options,
        )
        if certificate_file is not None and no_verify:
            raise InputError("--certificate needs the equivalence check (drop --no-verify)")
        with StageProgress(quiet=quiet or no_progress, label=source.name) as progress:
            with certificate.collecting_if(certificate_file is not None) as sink:
                outcome = api.convert_file(source, output, request, on_stage=progress)
        if certificate_file is not None and outcome.report is not None:
            write_certificate(
                certificate_file,
                sink,
                outcome.report,
                source.read_bytes(),
                outcome.text.encode("utf-8"),
                to_stderr=output is None or as_json,
            )
        summary = outcome.to_dict()
        if as_json:
            if output is None:
                summary["model"] = outcome.text
            print(json.dumps(summary, indent=2, default=str))
        else:
            if output is None:
                sys.stdout.write(outcome.text)
            _print_summary(outcome, to_stderr=output is None, brief=quiet)
        if outcome.equivalent is False:
            raise typer.Exit(1)


def _print_summary(outcome: api.Outcome, *, to_stderr: bool, brief: bool = False) -> None:
    stream = sys.stderr if to_stderr else sys.stdout
    for warning in outcome.warnings:
        print(f"warning: {warning}", file=stream)
    source = outcome.source.model
    if isinstance(source, BTDocument):
        undeclared = undeclared_leaf_types(source)
        if undeclared:
            print(
                f"warning: {undeclared_summary(undeclared)}; declare them with --node-models FILE",
                file=stream,
            )
    if brief:
        written = "" if outcome.output is None or outcome.written else " (not written)"
        print(f"verdict: {outcome.verdict}{written}", file=stream)
        return
    figures = conversion_summary(
        outcome.conversion.direction, outcome.conversion.stats, outcome.conversion.engine
    )
    where = str(outcome.output) if outcome.output is not None else "stdout"
    print(
        f"converted {outcome.conversion.direction} with {outcome.conversion.engine} -> "
        f"{where} ({outcome.output_format}): {figures}",
        file=stream,
    )
    print(f"time: {format_timings(outcome.timings)}", file=stream)
    if outcome.load is not None:
        print(outcome.load.summary(), file=stream)
    report: Report | None = outcome.report
    if report is None:
        print("verification skipped (--no-verify)", file=stream)
        return
    print(f"verdict: {outcome.verdict}", file=stream)
    if report.method:
        engines = ", ".join(f"{name} {version}" for name, version in report.engines.items())
        print(f"  proven by: {report.method} ({engines})", file=stream)
        for sentence in report.abstractions:
            print(f"  under the abstraction: {sentence}", file=stream)
    if report.stats.get("compositional"):
        print(
            f"  compositional check: {report.stats['compositional']}; the whole product decided",
            file=stream,
        )
    if report.stats.get("nusmv_limit"):  # --verify-engine both: NuSMV did not confirm it
        print(f"  NuSMV gave up (native verdict only): {report.stats['nusmv_limit']}", file=stream)
    counts = checked_counts(report.stats)
    if counts:
        print(f"  checked {counts}", file=stream)
    for sentence in report.stats.get("abstractions", []):
        print(f"verified under the abstraction: {sentence}", file=stream)
    if report.stats.get("data_model"):
        print(f"checked through the data model: {report.stats['data_model']}", file=stream)
    for name, prop in report.properties.items():
        mark = "ok  " if prop.holds else "FAIL"
        print(f"  {mark} {name}: {prop.detail}", file=stream)
    if outcome.output is not None and not outcome.written:
        print(
            f"not written: {outcome.output} (the result is not equivalent; --keep-failed "
            "writes it anyway)",
            file=stream,
        )
