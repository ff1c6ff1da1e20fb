"""The jinja2 environment of the skeleton templates (``templates/*.j2``) and its filters.

Filters turn model text into source text safely: ``cpp_str`` a C++ string literal (every
character escaped that could end it), ``py_str`` a Python literal (``repr``), ``cpp_port`` a
``BT::InputPort``/``OutputPort``/``BidirectionalPort`` declaration. Templates never paste model
text into code unescaped: a port or type name with a quote or a backslash stays a string.
"""

from __future__ import annotations

import math
import re
from functools import lru_cache

import jinja2

from fsmbt.model.bt import PortModel

#: Declared port types that map to a C++ type of their own; any other type is read as text.
CPP_TYPES = {
    "std::string": "std::string",
    "string": "std::string",
    "str": "std::string",
    "int": "int",
    "long": "long",
    "unsigned": "unsigned",
    "unsigned int": "unsigned",
    "double": "double",
    "float": "double",
    "bool": "bool",
}
_DIRECTION = {"input": "InputPort", "output": "OutputPort", "inout": "BidirectionalPort"}


def cpp_str(text: str) -> str:
    """A C++ string literal holding ``text`` (UTF-8 bytes of non-ASCII as octal escapes)."""
    out = ['"']
    for byte in str(text).encode("utf-8"):
        ch = chr(byte)
        if ch in '"\\':
            out.append("\\" + ch)
        elif 32 <= byte < 127 and ch != "?":  # '?' escaped: no trigraphs
            out.append(ch)
        else:
            out.append(f"\\{byte:03o}")
    out.append('"')
    return "".join(out)


def one_line(text: str) -> str:
    """Model text made safe for a comment or docstring: one line, no quotes that end it."""
    flat = re.sub(r"\s+", " ", str(text)).strip()
    return flat.replace("\\", "/").replace('"""', "'''").replace("*/", "* /")


def cpp_type(port: PortModel) -> str:
    """The C++ type of a port (``std::string`` for undeclared or unknown types)."""
    return CPP_TYPES.get((port.type or "").strip(), "std::string")


def _cpp_default(port: PortModel, ctype: str) -> str | None:
    """The default value as a C++ expression of ``ctype``, ``None`` when it does not parse."""
    value = port.default
    if value is None or value.startswith("{"):
        return None
    if ctype == "std::string":
        return f"std::string({cpp_str(value)})"
    if ctype == "bool":
        lowered = value.strip().lower()
        return {"true": "true", "false": "false", "1": "true", "0": "false"}.get(lowered)
    try:
        number = float(value) if ctype == "double" else int(value, 10)
    except ValueError:
        return None
    return repr(number) if math.isfinite(number) else None


def cpp_port(port: PortModel) -> str:
    """``BT::InputPort<T>("name", default, "description")`` for a model port."""
    ctype = cpp_type(port)
    what = _DIRECTION.get(port.direction, "InputPort")
    description = port.description or ""
    if port.type and ctype == "std::string" and port.type.strip() not in CPP_TYPES:
        description = f"{description} (declared type {port.type}, read as text)".strip()
    default = _cpp_default(port, ctype) if what != "OutputPort" else None
    if default is not None:
        return f"BT::{what}<{ctype}>({cpp_str(port.name)}, {default}, {cpp_str(description)})"
    return f"BT::{what}<{ctype}>({cpp_str(port.name)}, {cpp_str(description)})"


@lru_cache(maxsize=1)
def environment() -> jinja2.Environment:
    """The templates' environment: strict undefined, no HTML escaping (this is source code)."""
    env = jinja2.Environment(
        loader=jinja2.PackageLoader("fsmbt.runtime.skeleton", "templates"),
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
        autoescape=False,
    )
    env.filters["cpp_str"] = cpp_str
    env.filters["cpp_port"] = cpp_port
    env.filters["py_str"] = repr
    env.filters["oneline"] = one_line
    return env


def render(template: str, **context: object) -> str:
    return environment().get_template(template).render(**context)
