"""``fsmbt llm ...``: the LLM path's own commands (docs/llm.md).

- ``fsmbt llm convert INPUT``: convert with ``llm`` / ``nllm`` / ``hybrid``, taking any input a
  person has (a file any reader knows, prose, a table, an unseen notation, a PNG/JPEG diagram),
  with every ``--llm-*`` setting as a flag; writes the result only when verified equivalent.
- ``fsmbt llm extract INPUT``: only the extraction, as fsmbt JSON.
- ``fsmbt llm prompt INPUT``: print the exact messages a conversion would send (no LLM needed).
- ``fsmbt llm tokens INPUT...``: prompt tokens per conversion, counted with tiktoken offline.
"""

from __future__ import annotations

import json
from pathlib import Path

import typer

from fsmbt.cli import sub_app
from fsmbt.llm.config import PROVIDERS

LLM_ENGINES = ("llm", "nllm", "hybrid")


def _llm_options(
    base_url: str | None,
    model: str | None,
    timeout: float | None,
    regenerations: int | None,
    log: str | None,
) -> dict[str, object]:
    return {
        "llm_base_url": base_url,
        "llm_model": model,
        "llm_timeout": timeout,
        "max_regenerations": regenerations,
        "llm_log": log,
    }


def register(app: typer.Typer) -> None:
    llm_app = sub_app("The LLM conversion path: convert, extract, show prompts, count tokens.")
    app.add_typer(llm_app, name="llm")

    base_url_opt = typer.Option(
        None, "--llm-base-url", help=f"Endpoint URL or provider ({', '.join(sorted(PROVIDERS))})."
    )
    model_opt = typer.Option(None, "--llm-model", help="Model name at the endpoint.")
    timeout_opt = typer.Option(
        None, "--llm-timeout", help="Seconds per request, retries included (180)."
    )
    regen_opt = typer.Option(
        None, "--max-regenerations", help="Feedback rounds after the first answer (3)."
    )
    log_opt = typer.Option(None, "--llm-log", help="JSONL log file ('off' disables).")

    @llm_app.command("convert")
    def convert_command(
        input_path: Path = typer.Argument(
            ..., help="The source: any model file, text, table or image."
        ),
        output: Path | None = typer.Option(None, "-o", "--output", help="Write the result here."),
        to_format: str | None = typer.Option(
            None, "--to", help="Output format (default: from -o, else printed as btcpp/json)."
        ),
        from_format: str | None = typer.Option(
            None, "--from", help="Input format; 'llm' forces LLM extraction."
        ),
        engine: str = typer.Option("llm", "--engine", help="llm, nllm or hybrid."),
        ablate: str | None = typer.Option(
            None, "--ablate", help="SCP modules to drop, comma-separated."
        ),
        verify_engine: str = typer.Option(
            "native", "--verify-engine", help="native, nusmv or both."
        ),
        force: bool = typer.Option(False, "--force", help="Overwrite OUTPUT."),
        llm_base_url: str | None = base_url_opt,
        llm_model: str | None = model_opt,
        llm_timeout: float | None = timeout_opt,
        max_regenerations: int | None = regen_opt,
        llm_log: str | None = log_opt,
    ) -> None:
        """Convert INPUT with an LLM engine; the result is verified before it is written."""
        from fsmbt import api
        from fsmbt.formats import dumps
        from fsmbt.model.errors import InputError

        if engine not in LLM_ENGINES:
            raise InputError(
                f"fsmbt llm convert takes --engine {', '.join(LLM_ENGINES)}; "
                "for rules use fsmbt convert"
            )
        options = _llm_options(llm_base_url, llm_model, llm_timeout, max_regenerations, llm_log)
        options.update(ablate=ablate, verify_engine=verify_engine)
        # the engine verified its answer with verify_engine (it refuses one that is not
        # equivalent); the pipeline's own check is the cheap native one
        outcome = api.convert_file(
            input_path,
            output,
            to=to_format,
            source_format=from_format,
            engine=engine,
            overwrite=force,
            options=options,
        )
        if output is None:  # printed FSMs default to fsmbt JSON here (what the LLM speaks)
            text = outcome.text
            if to_format is None and api.model_kind(outcome.result) == "fsm":
                text = dumps(outcome.result, "json")
            print(text, end="")
        typer.echo(
            f"{engine}: verified equivalent; "
            + ", ".join(
                f"{k}={v}"
                for k, v in outcome.conversion.stats.items()
                if k
                in (
                    "first_pass_success",
                    "regenerations",
                    "tokens_in",
                    "tokens_out",
                    "latency_s",
                    "extracted_by_llm",
                    "verify_engine",
                )
            ),
            err=True,
        )

    @llm_app.command("extract")
    def extract_command(
        input_path: Path = typer.Argument(
            ..., help="Text, table, unseen notation or PNG/JPEG diagram."
        ),
        output: Path | None = typer.Option(None, "-o", "--output", help="Write the JSON here."),
        kind: str | None = typer.Option(None, "--kind", help="fsm or bt, when known."),
        force: bool = typer.Option(False, "--force", help="Overwrite OUTPUT."),
        llm_base_url: str | None = base_url_opt,
        llm_model: str | None = model_opt,
        llm_timeout: float | None = timeout_opt,
        max_regenerations: int | None = regen_opt,
        llm_log: str | None = log_opt,
    ) -> None:
        """Let the LLM write the model in INPUT as fsmbt JSON (validated like any input)."""
        from fsmbt import api
        from fsmbt.formats import dumps
        from fsmbt.llm.engine import client_from_options
        from fsmbt.llm.extract import read_input

        client = client_from_options(
            _llm_options(llm_base_url, llm_model, llm_timeout, max_regenerations, llm_log)
        )
        loaded = read_input(
            input_path, "llm", client=client, kind=kind, max_regenerations=max_regenerations
        )
        if output is not None:
            api.write(loaded.model, output, "json", overwrite=force)
        else:
            print(dumps(loaded.model, "json"), end="")

    @llm_app.command("prompt")
    def prompt_command(
        input_path: Path = typer.Argument(..., help="A model file (FSM or BT)."),
        from_format: str | None = typer.Option(
            None, "--from", help="Input format (default: detected)."
        ),
        nllm: bool = typer.Option(False, "--nllm", help="The baseline prompt: no SCP."),
        ablate: str | None = typer.Option(
            None, "--ablate", help="SCP modules to drop, comma-separated."
        ),
        as_json: bool = typer.Option(False, "--json", help="Print the messages as JSON."),
    ) -> None:
        """Print the messages a conversion of INPUT would send, and their token count."""
        from fsmbt import api
        from fsmbt.llm.prompts import messages_for
        from fsmbt.llm.tokens import count_messages

        model = api.load(input_path, from_format).model
        modules = frozenset(m.strip() for m in (ablate or "").split(",") if m.strip())
        options, messages = messages_for(model, scp=not nllm, disabled_modules=modules)
        if as_json:
            print(json.dumps(messages, indent=2, ensure_ascii=False))
        else:
            for message in messages:
                print(f"=== {message['role']} ===\n{message['content']}\n")
        typer.echo(
            f"{options.label}: {count_messages(messages)} prompt tokens (cl100k_base)", err=True
        )

    @llm_app.command("tokens")
    def tokens_command(
        inputs: list[Path] = typer.Argument(..., help="Model files (FSM or BT)."),
        from_format: str | None = typer.Option(
            None, "--from", help="Input format (default: detected)."
        ),
    ) -> None:
        """Prompt tokens of the llm and nllm requests for each model (tiktoken cl100k_base)."""
        from fsmbt import api
        from fsmbt.llm.prompts import messages_for
        from fsmbt.llm.tokens import count_messages

        print("input\tdirection\tllm_prompt_tokens\tnllm_prompt_tokens")
        for path in inputs:
            model = api.load(path, from_format).model
            prompts = [messages_for(model, scp=scp) for scp in (True, False)]
            counts = [count_messages(messages) for _options, messages in prompts]
            print(f"{path}\t{prompts[0][0].direction}\t{counts[0]}\t{counts[1]}")
