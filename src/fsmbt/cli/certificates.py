"""The ``--certificate FILE`` option of ``verify`` and ``convert``: write the verdict's witness.

Why: a verdict a CI or a reviewer can re-check with ``fsmbt check-certificate`` without
trusting the search (``fsmbt.verify.certificate``; docs/verification.md, "Certificates").
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import typer

from fsmbt.verify import certificate
from fsmbt.verify.report import Report


def certificate_option() -> Any:
    """The ``--certificate FILE`` option (default: none written)."""
    return typer.Option(
        None,
        "--certificate",
        help="write a certificate of the verdict to FILE (re-check it with "
        "fsmbt check-certificate SOURCE RESULT FILE)",
    )


def write_certificate(
    path: Path,
    sink: certificate.WitnessSink,
    report: Report,
    source_bytes: bytes,
    result_bytes: bytes,
    *,
    to_stderr: bool,
) -> None:
    """Build and write the certificate; say where on stdout (stderr when stdout is a model or
    JSON)."""
    data = certificate.build(
        sink,
        report,
        source_digest=certificate.digest(source_bytes),
        result_digest=certificate.digest(result_bytes),
    )
    certificate.write(data, path)
    units = data.get("units")
    what = (
        f"{certificate.relation_pairs(data)} related state pairs in {len(units)} "
        f"unit{'s' if len(units) != 1 else ''}"
        if units
        else "counterexamples"
    )
    print(
        f"certificate: {path} ({what}; method {report.method})",
        file=sys.stderr if to_stderr else sys.stdout,
    )
