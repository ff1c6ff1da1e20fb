"""Models for the web tests, written as text (nothing read from the corpus)."""

from __future__ import annotations


def hierarchical_scxml(groups: int = 8, inner: int = 10) -> str:
    """An SCXML machine of ``groups`` composite states ``G<g>``, each a cycle of ``inner``
    states ``G<g>_<i>`` on ``step``, the composites a cycle on ``next``. With 8 x 10 it has
    more states than one layered picture holds, so its picture closes every composite."""
    parts = ['<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0" initial="G0">']
    for g in range(groups):
        parts.append(f'<state id="G{g}" initial="G{g}_0">')
        for i in range(inner):
            target = f"G{g}_{(i + 1) % inner}"
            parts.append(
                f'<state id="G{g}_{i}"><transition event="step" target="{target}"/></state>'
            )
        parts.append(f'<transition event="next" target="G{(g + 1) % groups}"/></state>')
    parts.append("</scxml>")
    return "\n".join(parts)


def nested_scxml(outer: int = 3, groups: int = 8, inner: int = 10) -> str:
    """``outer`` composite states ``O<o>`` on a cycle (``out``), each holding
    ``hierarchical_scxml``'s machine with names prefixed ``O<o>`` (``O1G2_3``): three levels,
    so a composite opened alone shows composites closed in it."""
    parts = ['<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0" initial="O0">']
    for o in range(outer):
        parts.append(f'<state id="O{o}" initial="O{o}G0">')
        for g in range(groups):
            name = f"O{o}G{g}"
            parts.append(f'<state id="{name}" initial="{name}_0">')
            for i in range(inner):
                target = f"{name}_{(i + 1) % inner}"
                parts.append(
                    f'<state id="{name}_{i}"><transition event="step" target="{target}"/></state>'
                )
            parts.append(f'<transition event="next" target="O{o}G{(g + 1) % groups}"/></state>')
        parts.append(f'<transition event="out" target="O{(o + 1) % outer}"/></state>')
    parts.append("</scxml>")
    return "\n".join(parts)
