"""File formats: one module per format, each registering itself in ``registry``."""

from fsmbt.formats.registry import (
    Format,
    ReadContext,
    detect_format,
    dumps,
    formats,
    get_format,
    loads,
    register,
)

__all__ = [
    "Format",
    "ReadContext",
    "detect_format",
    "dumps",
    "formats",
    "get_format",
    "loads",
    "register",
]
