"""``fsmbt verify SOURCE CONVERTED``: is the converted model equivalent to its source?

Exit 0 equivalent, 1 not equivalent, 2 bad input, 3 the two engines disagree (``--engine both``),
4 a verification engine reached its memory or time cap (``--timeout``, ``--nusmv-memory``).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import typer
from rich.console import Console

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
from fsmbt.cli.progress import StageProgress
from fsmbt.cli.render_report import print_report
from fsmbt.verify import EngineDisagreement, certificate

EXIT_EQUIVALENT = 0
EXIT_NOT_EQUIVALENT = 1
EXIT_ENGINES_DISAGREE = 3


def register(app: typer.Typer) -> None:
    @app.command("verify")
    @reads_models
    def verify_command(
        source: Path = typer.Argument(..., help="The source model (FSM or BT)."),
        converted: Path = typer.Argument(..., help="The converted model to check against it."),
        as_json: bool = typer.Option(False, "--json", help="Print the report as JSON."),
        quiet: bool = typer.Option(
            False, "--quiet", "-q", help="No progress display; print only the verdict line."
        ),
        no_progress: bool = typer.Option(
            False, "--no-progress", help="No progress display on stderr (the full report stays)."
        ),
        max_states: int | None = max_states_option(),
        engine: str = typer.Option(
            "native",
            "--verify-engine",
            "--engine",
            help="native, nusmv, or both (both must agree).",
        ),
        loop: bool = typer.Option(
            False, "--loop", help="BT side: tick the root again after it returns."
        ),
        from_format2: str | None = typer.Option(
            None, "--from2", help="Format of CONVERTED (default: detected)."
        ),
        timeout: float | None = timeout_option(),
        nusmv_memory: int | None = nusmv_memory_option(),
        certificate_file: Path | None = certificate_option(),
        *,
        read: ReadOptions,
    ) -> None:
        """Check the five properties (reachability, completeness, no additional behaviour,
        deadlock absence, termination consistency); on failure, show the shortest input
        sequence that tells the two models apart."""
        apply_engine_caps(timeout, nusmv_memory)
        try:
            with StageProgress(
                quiet=quiet or no_progress or as_json, label=f"{source.name} ~ {converted.name}"
            ) as progress:
                request = api.verify_request(
                    engine=engine, loop=loop, max_states=max_states, read=read
                )
                with certificate.collecting_if(certificate_file is not None) as sink:
                    first, second, report = api.verify_files(
                        source,
                        converted,
                        request,
                        converted_format=from_format2,
                        on_stage=progress,
                    )
        except EngineDisagreement as exc:
            print(
                f"error: ENGINES DISAGREE: {exc}; one of the checkers is wrong, please report "
                "this with both files",
                file=sys.stderr,
            )
            raise typer.Exit(EXIT_ENGINES_DISAGREE) from None
        for warning in [*first.warnings, *second.warnings]:
            print(f"warning: {warning}", file=sys.stderr)
        if certificate_file is not None:
            roles = (converted, source) if report.stats.get("swapped") else (source, converted)
            write_certificate(
                certificate_file,
                sink,
                report,
                roles[0].read_bytes(),
                roles[1].read_bytes(),
                to_stderr=as_json,
            )
        if as_json:
            data = report.to_dict()
            data["source_file"] = str(source)
            data["result_file"] = str(converted)
            print(json.dumps(data, indent=2, ensure_ascii=False))
        elif quiet:
            print(f"verdict: {api.verdict_word(report)}")
        else:
            print_report(report, Console())
            for sentence in report.stats.get("abstractions", []):
                print(f"verified under the abstraction: {sentence}")
            if report.stats.get("data_model"):
                print(f"checked through the data model: {report.stats['data_model']}")
            if report.stats.get("swapped"):
                print(
                    f"note: {converted} was read as the source and {source} as its "
                    f"conversion (pairing rule: {report.stats['pairing']}); the verdict does "
                    "not depend on the order"
                )
        raise typer.Exit(EXIT_EQUIVALENT if report.equivalent else EXIT_NOT_EQUIVALENT)
