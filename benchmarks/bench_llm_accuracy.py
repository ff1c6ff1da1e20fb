"""Accuracy of the LLM engines against a REAL OpenAI-compatible endpoint (never in CI).

Converts seeded generated models (FSMs of 2-30 states, BTs of depth/breadth 2-5, the paper's
scenarios) with ``llm`` (four-part prompt with the SCP), ``nllm`` (without it) and, with
``--ablate``, each single-module ablation, and prints per engine: first-pass success, final
success after feedback rounds, mean regenerations, tokens in/out and latency. A success is the
project's checker saying "equivalent"; nothing else counts. Every conversion is also written to
the JSONL log (``--log``).

It refuses to run without a configured endpoint (FSMBT_LLM_BASE_URL / --llm-base-url, a model
and a key: docs/llm.md), on CI (CI=true), and against a loopback address unless
``--allow-local`` (an Ollama or vLLM server on this machine), because the tests' scripted server
lives there and its answers must never become an accuracy figure.

    FSMBT_LLM_BASE_URL=deepseek FSMBT_LLM_API_KEY=... \\
        .venv/bin/python benchmarks/bench_llm_accuracy.py --fsms 20 --bts 20 --ablate
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
from collections import defaultdict
from urllib.parse import urlparse

from fsmbt.generate.generator import random_bt, random_fsm
from fsmbt.llm.client import LLMClient
from fsmbt.llm.config import LLMConfigError, LLMUnavailableError, resolve_settings
from fsmbt.llm.log import ConversionRecord
from fsmbt.llm.pipeline import convert_with_llm
from fsmbt.llm.prompts import MODULES

LOOPBACK = ("127.", "localhost", "::1", "[::1]")


def models(n_fsms: int, n_bts: int, seed: int) -> list[tuple[str, object]]:
    out: list[tuple[str, object]] = []
    scenarios = ("basic", "robot", "game")
    for i in range(n_fsms):
        states = 2 + (i * 7) % 29
        out.append((f"fsm-{i}-{states}", random_fsm(f"{seed}-fsm-{i}", states, scenarios[i % 3])))
    for i in range(n_bts):
        size = 2 + i % 4
        out.append(
            (
                f"bt-{i}-d{size}",
                random_bt(f"{seed}-bt-{i}", size, size, scenarios[i % 3], max_nodes=60),
            )
        )
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fsms", type=int, default=10)
    parser.add_argument("--bts", type=int, default=10)
    parser.add_argument("--seed", type=int, default=2024)
    parser.add_argument("--ablate", action="store_true", help="also run each SCP module ablation")
    parser.add_argument("--max-regenerations", type=int, default=None)
    parser.add_argument("--verify-engine", default="native")
    parser.add_argument("--llm-base-url")
    parser.add_argument("--llm-model")
    parser.add_argument("--log", default="llm-accuracy.jsonl")
    parser.add_argument("--allow-local", action="store_true")
    args = parser.parse_args(argv)
    if os.environ.get("CI"):
        print("refusing to run on CI: accuracy needs a real LLM endpoint", file=sys.stderr)
        return 2
    try:
        settings = resolve_settings(
            base_url=args.llm_base_url,
            model=args.llm_model,
            max_regenerations=args.max_regenerations,
            log_path=args.log,
        )
    except LLMConfigError as exc:
        print(f"refusing to run: {exc}", file=sys.stderr)
        return 2
    host = urlparse(settings.base_url).hostname or ""
    if host.startswith(LOOPBACK) and not args.allow_local:
        print(
            f"refusing to run against {settings.base_url} (loopback): pass --allow-local for a "
            "real local model server",
            file=sys.stderr,
        )
        return 2
    client = LLMClient(settings)
    from fsmbt.llm.pipeline import default_verifier

    verifier = default_verifier(args.verify_engine)
    variants: list[tuple[str, bool, frozenset[str]]] = [
        ("llm", True, frozenset()),
        ("nllm", False, frozenset()),
    ]
    if args.ablate:
        for direction_modules in MODULES.values():
            for module in direction_modules:
                variants.append((f"llm-{module}", True, frozenset({module})))
    results: dict[str, list[ConversionRecord]] = defaultdict(list)
    print(f"model {settings.describe()}; log {settings.log_path}")
    for name, model in models(args.fsms, args.bts, args.seed):
        direction_modules = MODULES["fsm_to_bt" if name.startswith("fsm") else "bt_to_fsm"]
        for label, scp, ablated in variants:
            if ablated and not ablated <= set(direction_modules):
                continue
            try:
                outcome = convert_with_llm(
                    model,
                    client,
                    scp=scp,
                    disabled_modules=ablated,  # type: ignore[arg-type]
                    verifier=verifier,
                    engine_name=label,
                    source_name=name,
                )
            except LLMUnavailableError as exc:
                print(f"stopping: {exc}", file=sys.stderr)
                return 2
            results[label].append(outcome.record)
            print(
                f"{name:<16} {label:<28} {outcome.record.verdict:<16} "
                f"rounds={len(outcome.record.rounds)} tokens={outcome.record.tokens_in}/"
                f"{outcome.record.tokens_out}",
                flush=True,
            )
    print(
        "\nengine                        n  first-pass  final   regen  tokens-in  tokens-out  latency-s"
    )
    for label, records in results.items():
        n = len(records)
        first = sum(r.first_pass_success for r in records) / n
        final = sum(r.verdict == "equivalent" for r in records) / n
        print(
            f"{label:<28} {n:>3}  {first:>9.1%}  {final:>6.1%}  "
            f"{statistics.mean(r.regenerations for r in records):>5.2f}  "
            f"{statistics.mean(r.tokens_in for r in records):>9.0f}  "
            f"{statistics.mean(r.tokens_out for r in records):>10.0f}  "
            f"{statistics.mean(r.latency_s for r in records):>9.2f}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
