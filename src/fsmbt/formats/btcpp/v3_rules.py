"""What BehaviorTree.CPP 3.8 accepts in a file, as a check (no v3 XSD exists and no v3 build is
made here): the rules of its ``VerifyXML`` and ``createNodeFromXML`` that a written file can
break (docs/formats/btcpp.md, "Version 3").

- ``<root>``, with ``BTCPP_format`` absent or ``"3"``; at most one ``<TreeNodesModel>``;
- every node is a 3.8 built-in (``versions.V3_PORTS``: v3 names only, so no
  ``SequenceWithMemory``, ``Script``...), a type the file's ``<TreeNodesModel>`` declares, or
  Groot's explicit style (``<Action ID>``...) naming one of those;
- a built-in's attributes are its v3 ports or ``ID`` / ``name`` / ``_description`` (3.8 throws
  "Possible typo?" otherwise); no node carries another ``_`` attribute (v4's ``_skipIf``,
  ``_autoremap``...);
- ``<SubTree>``: no child, an ``ID``; its remaps name a parent key without braces (a ``{key}``
  value is v4's, or ``<SubTreePlus>``'s, syntax);
- ``<WhileDoElse>`` has three children (3.8 throws on two, v4 allows them).

Cost: one parse, one pass over the elements (lxml iterates; no recursion).
"""

from __future__ import annotations

from lxml import etree

from fsmbt.formats.btcpp import versions
from fsmbt.formats.xml_safe import parse_xml

_EXPLICIT = ("Action", "Condition", "Control", "Decorator")


def v3_problems(text: str) -> list[str]:
    """Every rule of BehaviorTree.CPP 3.8 the file breaks, one ``line N: ...`` each (empty: none).

    Raises:
        InputError: the text is not well-formed XML.
    """
    root = parse_xml(text, "<v3 check>")
    problems: list[str] = []
    if root.tag != "root":
        return [f"line {root.sourceline}: the root element is <{str(root.tag)}>, not <root>"]
    version = root.get("BTCPP_format")
    if version not in (None, "3"):
        problems.append(f'line {root.sourceline}: BTCPP_format="{version}" is not v3')
    models = [c for c in root if c.tag == "TreeNodesModel"]
    if len(models) > 1:
        problems.append(f"line {models[1].sourceline}: a second <TreeNodesModel>")
    declared = {str(e.get("ID")) for m in models for e in m if isinstance(e.tag, str)}
    for tree in root:
        if tree.tag != "BehaviorTree":
            continue
        for element in tree.iter():
            if element is tree or not isinstance(element.tag, str):
                continue
            problems.extend(_element_problems(element, declared))
    return problems


def _element_problems(element: etree._Element, declared: set[str]) -> list[str]:
    tag, line = str(element.tag), element.sourceline
    attrs = dict(element.attrib)
    out: list[str] = []
    ports = versions.V3_PORTS.get(tag, frozenset())
    for key in attrs:
        if key.startswith("_") and key not in versions.V3_RESERVED and key not in ports:
            out.append(f"line {line}: <{tag}> {key}: v3 has no such attribute")
    if tag in ("SubTree", "SubTreePlus"):
        if "ID" not in attrs:
            out.append(f"line {line}: <{tag}> without ID")
        if len(element):
            out.append(f"line {line}: <{tag}> has a child")
        if tag == "SubTree":
            for key, value in attrs.items():
                if key not in ("ID", "__shared_blackboard") and key not in versions.V3_RESERVED:
                    if value.startswith("{"):
                        out.append(
                            f'line {line}: <SubTree> {key}="{value}": v3\'s SubTree remaps '
                            "a key named without braces"
                        )
        return out
    type_name = tag
    if tag in _EXPLICIT:
        type_name = attrs.get("ID", "")
        if not type_name:
            return [*out, f"line {line}: <{tag}> without ID"]
    if type_name == "WhileDoElse" and len([c for c in element if isinstance(c.tag, str)]) != 3:
        out.append(f"line {line}: <WhileDoElse> needs three children in v3")
    if type_name in versions.V3_PORTS:
        allowed = versions.V3_PORTS[type_name] | versions.V3_RESERVED
        for key in attrs:
            if key not in allowed and not key.startswith("_"):
                out.append(f"line {line}: <{type_name}> has no port '{key}' in v3")
    elif type_name not in declared:
        out.append(
            f"line {line}: <{type_name}> is neither a BehaviorTree.CPP 3.8 node nor declared "
            "in the file's <TreeNodesModel>"
        )
    return out


__all__ = ["v3_problems"]
