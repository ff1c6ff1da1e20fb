"""Small helpers for writing SMV text: safe identifiers with a decoding table, case blocks.

NuSMV reserves many words (``A``, ``E``, ``F``, ``G``, ``X``, ``U``, ``AF``, ``case``, ``init``,
...) and only takes ``[A-Za-z_][A-Za-z0-9_$#-]*``. Rather than escaping user names, every model
name becomes a generated identifier (``prefix`` + number) and the table maps it back, so
counterexamples decode to the original names exactly.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field


@dataclass
class Symbols:
    """Strings of one kind (states, inputs, outputs...) as SMV enum constants, both ways."""

    prefix: str
    to_id: dict[str, str] = field(default_factory=dict)
    to_name: dict[str, str] = field(default_factory=dict)

    def id(self, name: str) -> str:
        found = self.to_id.get(name)
        if found is None:
            found = f"{self.prefix}{len(self.to_id)}"
            self.to_id[name] = found
            self.to_name[found] = name
        return found

    def add_all(self, names: Iterable[str]) -> None:
        for name in names:
            self.id(name)

    def enum(self, extra: Sequence[str] = ()) -> str:
        """The SMV enumeration type; padded to two values when it would have one (NuSMV turns
        a single-value variable into a constant, and then rejects its ``init``/``next``)."""
        return enum_type(list(extra) + list(self.to_id.values()), f"{self.prefix}pad")

    def name(self, smv_id: str) -> str | None:
        return self.to_name.get(smv_id)


def enum_type(values: Sequence[str], pad: str) -> str:
    """``{v1, v2, ...}``, with ``pad`` added when fewer than two values (see ``Symbols.enum``)."""
    values = list(values)
    if len(values) < 2:
        values.append(pad)
    return "{" + ", ".join(values) + "}"


def case(rows: Sequence[tuple[str, str]], default: str) -> str:
    """``case c1 : v1; ... TRUE : default; esac`` (rows in priority order)."""
    if not rows:
        return default
    body = "".join(f"      {cond} : {value};\n" for cond, value in rows)
    return f"case\n{body}      TRUE : {default};\n    esac"


def any_of(parts: Iterable[str]) -> str:
    items = [p for p in parts if p != "FALSE"]
    if not items:
        return "FALSE"
    if "TRUE" in items:
        return "TRUE"
    return "(" + " | ".join(items) + ")"


def all_of(parts: Iterable[str]) -> str:
    items = [p for p in parts if p != "TRUE"]
    if not items:
        return "TRUE"
    if "FALSE" in items:
        return "FALSE"
    return "(" + " & ".join(items) + ")"


def subsequence(small: Sequence[str], big: Sequence[str], none: str) -> str:
    """SMV expression: the non-``none`` items of ``small`` (in order) are a subsequence of the
    non-``none`` items of ``big``. Enumerates which slots of ``small`` are filled and every
    increasing match into ``big``: O(2^m · C(n, k)) terms for m, n slots (both tiny)."""
    m = len(small)
    cases = []
    for mask in range(1 << m):
        filled = [i for i in range(m) if mask >> i & 1]
        pattern = all_of(
            [f"{small[i]} != {none}" if mask >> i & 1 else f"{small[i]} = {none}" for i in range(m)]
        )
        matches = []
        for combo in _increasing(len(filled), len(big)):
            matches.append(all_of(f"{small[i]} = {big[j]}" for i, j in zip(filled, combo)))
        cases.append(all_of([pattern, any_of(matches) if filled else "TRUE"]))
    return any_of(cases)


def _increasing(k: int, n: int) -> list[tuple[int, ...]]:
    from itertools import combinations

    return list(combinations(range(n), k))
