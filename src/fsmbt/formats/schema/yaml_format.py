"""fsmbt's YAML form: the same schema as the JSON form (``model.serialize``; docs/formats/yaml.md).

Read through ``fsmbt.model.yaml_guarded`` (aliases refused, depth bounded: PyYAML's
``safe_load`` leaves both hazards open).
"""

from __future__ import annotations

from typing import Any

import yaml

from fsmbt.formats.registry import Format, ReadContext, register
from fsmbt.model import Model
from fsmbt.model.errors import InputError
from fsmbt.model.serialize import model_from_dict, model_to_dict
from fsmbt.model.yaml_guarded import load_guarded_yaml


def load_yaml(text: str, ctx: ReadContext) -> Any:
    """Plain data from YAML text (one document), with fsmbt's guards (``model.yaml_guarded``:
    no aliases, bounded depth); errors name the line."""
    return load_guarded_yaml(text, lambda line, column: ctx.location(line, column))


def read_yaml(text: str, ctx: ReadContext) -> Model:
    data = load_yaml(text, ctx)
    try:
        return model_from_dict(data, where="$")
    except InputError as exc:
        exc.location = exc.location or ctx.location()
        raise
    except RecursionError:
        raise InputError("model nested too deeply", location=ctx.location()) from None


class _BlockDumper(yaml.SafeDumper):
    """Block style, keys in schema order, and never an anchor (our own reader refuses aliases)."""

    def ignore_aliases(self, data: Any) -> bool:
        return True


def write_yaml(model: Model) -> str:
    """Block-style YAML; PyYAML's emitter recurses per level, so very deep trees are refused."""
    try:
        return yaml.dump(
            model_to_dict(model),
            Dumper=_BlockDumper,
            sort_keys=False,
            allow_unicode=True,
            default_flow_style=False,
            width=100,
        )
    except RecursionError:
        raise InputError("model nested too deeply to write as YAML; use JSON or XML") from None


def _sniff(text: str) -> bool:
    """A top-level ``kind: fsm`` / ``kind: bt`` line in the first lines (JSON is tried first)."""
    for line in text[:4096].splitlines():
        stripped = line.strip()
        if (
            stripped
            in ("kind: fsm", "kind: bt", "kind: 'fsm'", "kind: 'bt'", 'kind: "fsm"', 'kind: "bt"')
            and not line[:1].isspace()
        ):
            return True
    return False


register(
    Format(
        "yaml",
        (".yaml", ".yml"),
        frozenset({"fsm", "bt"}),
        "fsmbt YAML (either model; same schema as JSON)",
        read_yaml,
        write_yaml,
        _sniff,
        priority=30,
    )
)

__all__ = ["load_yaml", "read_yaml", "write_yaml"]
