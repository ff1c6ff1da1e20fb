"""``fsmbt check-certificate SOURCE RESULT FILE``: re-validate a verdict without re-running the
search (``fsmbt.verify.certificate``; docs/verification.md, "Certificates").

Exit 0 the certificate proves its verdict for these two files, 1 it is refused (tampered, for
other files, or not a proof), 2 bad input (unreadable models or certificate file).
"""

from __future__ import annotations

import sys
from pathlib import Path

import typer

from fsmbt import api
from fsmbt.api_types import ReadOptions
from fsmbt.cli.options import reads_models
from fsmbt.verify import certificate
from fsmbt.verify.orient import orient

EXIT_VALID = 0
EXIT_REFUSED = 1


def register(app: typer.Typer) -> None:
    @app.command("check-certificate")
    @reads_models
    def check_certificate_command(
        source: Path = typer.Argument(..., help="the source model the certificate names"),
        result: Path = typer.Argument(..., help="the converted model"),
        certificate_file: Path = typer.Argument(..., help="the certificate (from --certificate)"),
        *,
        read: ReadOptions,
    ) -> None:
        """Check a certificate written by ``verify``/``convert --certificate``: the relation is
        closed under both machines' steps from their starts and related states agree (one
        machine step per certified edge), or a counterexample replays to a difference."""
        data = certificate.load(certificate_file)
        options = read.reader_options()
        first = api.load(source, read.format, options=options)
        second = api.load(result, None, options=options)
        oriented = orient(first.model, second.model)
        roles = (result, source) if oriented.swapped else (source, result)
        try:
            checked = certificate.check(
                data,
                oriented.source,
                oriented.result,
                source_digest=certificate.digest(roles[0].read_bytes()),
                result_digest=certificate.digest(roles[1].read_bytes()),
            )
        except certificate.CertificateError as exc:
            print(f"certificate REFUSED: {certificate_file}: {exc.message}", file=sys.stderr)
            raise typer.Exit(EXIT_REFUSED) from None
        verdict = "EQUIVALENT" if checked.equivalent else "NOT EQUIVALENT"
        print(f"certificate valid: {verdict} ({checked.mode}, method {checked.method})")
        if checked.equivalent:
            parts = ", ".join(f"{n} {kind}" for kind, n in checked.units.items())
            print(
                f"  checked relations of {checked.pairs} state pairs over "
                f"{checked.states['source']} source and {checked.states['result']} result "
                f"states in {parts} unit(s) ({checked.steps} machine steps, no search)"
            )
        else:
            print(f"  a counterexample replays to a difference ({checked.steps} steps)")
        for name, version in checked.engines.items():
            print(f"  engine: {name} {version}")
        for sentence in checked.abstractions:
            print(f"  under the abstraction: {sentence}")
        raise typer.Exit(EXIT_VALID)
