"""Certificates of per-node proofs for the tests: the bench families' seeded trees and their
per-node conversions, a certificate made through ``verify`` as the CLI makes it (a JSON round
trip), and its check (``fsmbt.verify.certificate``).

``family_pair(family, leaves, seed)``: a ``bench_reactive.family_tree`` and its conversion
written per node. ``certify(doc, model)``: the report and its certificate as plain data.
``recheck(data, doc, model)``: ``certificate.check`` with the digests the certificate names.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.model.bt import BTDocument
from fsmbt.model.fsm import FSM
from fsmbt.verify import certificate, verify
from fsmbt.verify.report import Report

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from bench_reactive import family_tree  # noqa: E402

#: The bench families the per-node proof covers (benchmarks/bench_reactive.py).
FAMILIES = ("mixed", "memory", "reactive-plain", "decorated")
SOURCE, RESULT = "source-digest", "result-digest"


def family_pair(family: str, leaves: int, seed: int) -> tuple[BTDocument, FSM]:
    doc = family_tree(family, leaves, seed)
    return doc, bt_to_hfsm(doc, pernode=True).model


def certify(doc: BTDocument, model: FSM) -> tuple[Report, dict[str, Any]]:
    with certificate.collecting() as sink:
        report = verify(doc, model)
    data = certificate.build(sink, report, source_digest=SOURCE, result_digest=RESULT)
    return report, json.loads(json.dumps(data))


def recheck(data: dict[str, Any], doc: BTDocument, model: FSM) -> certificate.Checked:
    return certificate.check(data, doc, model, source_digest=SOURCE, result_digest=RESULT)
