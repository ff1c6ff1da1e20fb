"""A BehaviorTree.CPP file translated to v4 as the user's own file, edited where v4 needs it
(docs/formats/btcpp.md, "The user's file kept"): comments, attribute order, quoting, spacing
and every untouched byte stay as written; only what changes is changed.

``edited_source(original, doc, written)`` takes the file's text, the document read from it and
the v4 writer's text of that document, and returns the file with these edits, or ``None``
when it cannot (then the writer's text is used):

- ``<root>``: ``BTCPP_format="4"`` (set, or inserted first); ``main_tree_to_execute`` inserted
  when the file has several trees and does not name one; a ``<BehaviorTree>`` without ``ID``
  (one tree) gets ``ID="MainTree"``, the name the reader gives it;
- each node element says what its node says, as the writer would: the tag (v3's
  ``SequenceStar`` -> ``SequenceWithMemory``, ``SubTreePlus`` -> ``SubTree``, a node library's
  alias or letter-case fix; an explicit-style element keeps its style, its ``ID`` changes), its
  attributes (v3's Parallel thresholds and SubTree remaps in v4 terms, ``fsmbt.formats.btcpp.
  versions``): a changed value is replaced in place, an attribute whose name changed is
  renamed in place (the k-th dropped name becomes the k-th new one), others are removed or
  appended;
- the ``<TreeNodesModel>`` entries the writer adds (every node BehaviorTree.CPP's factory does
  not hold) that the file does not declare are inserted before ``</TreeNodesModel>``, or in a
  new ``<TreeNodesModel>`` before ``</root>``, indented like their neighbours;
- a written file is self-contained (as the writer's): each ``<include>`` is removed (with its
  line) and the trees of included files, or of other files SubTrees name, are inserted before
  ``</root>`` as the writer writes them.

Refused (``None``): a DOCTYPE with an internal subset, a self-closing ``<TreeNodesModel/>``
that needs entries, any element the scanner and lxml do not see alike. The result is kept only when it
reads back to the same document as the writer's text (``model_to_dict`` equal), so an edit can
never change what the file says.

The scanner walks the text once (comments, CDATA, processing instructions skipped), pairs the
k-th start tag with lxml's k-th element; cost O(file size) plus two reads of the result.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from lxml import etree

from fsmbt.formats.btcpp.xml_format import EXPLICIT_TAGS, read_btcpp
from fsmbt.formats.registry import ReadContext
from fsmbt.formats.xml_safe import parse_xml
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.errors import InputError
from fsmbt.model.kinds import NodeKind
from fsmbt.model.serialize import model_to_dict

_NAME = re.compile(r"[A-Za-z_:][\w.:\-]*")
_ATTR = re.compile(r"(\s+)([^\s=/>]+)(\s*=\s*)(\"[^\"]*\"|'[^']*')")
_CLOSE = re.compile(r"\s*(/?)>")


@dataclass
class _Attr:
    key: str
    start: int  # of the whitespace before the key
    key_start: int
    key_end: int
    value_start: int  # inside the quotes
    value_end: int
    quote: str


@dataclass
class _Tag:
    name: str
    name_start: int
    name_end: int
    attrs: list[_Attr]
    attrs_end: int  # where a new attribute goes (after the last one, or after the name)
    empty: bool
    start: int  # the "<"
    end_name: tuple[int, int] | None = None  # the end tag's name span
    end_start: int | None = None  # the "</" of the end tag
    close_end: int = 0  # just after the tag's last ">" (its end tag's, if any)
    children: list[_Tag] = field(default_factory=list)


def _scan(text: str) -> list[_Tag] | None:
    """Every start tag of ``text`` in document order, end tags matched; ``None`` if the text
    has something the scanner does not take (a DOCTYPE with an internal subset)."""
    tags: list[_Tag] = []
    stack: list[_Tag] = []
    i = text.find("<")
    while i != -1:
        if text.startswith("<!--", i):
            j = text.find("-->", i + 4)
            i = text.find("<", j + 3) if j != -1 else -1
            continue
        if text.startswith("<![CDATA[", i):
            j = text.find("]]>", i + 9)
            i = text.find("<", j + 3) if j != -1 else -1
            continue
        if text.startswith("<?", i):
            j = text.find("?>", i + 2)
            i = text.find("<", j + 2) if j != -1 else -1
            continue
        if text.startswith("<!", i):
            j = text.find(">", i)
            if j == -1 or "[" in text[i:j]:
                return None
            i = text.find("<", j + 1)
            continue
        if text.startswith("</", i):
            name = _NAME.match(text, i + 2)
            if name is None or not stack or stack[-1].name != name.group():
                return None
            top = stack.pop()
            top.end_name = (name.start(), name.end())
            top.end_start = i
            top.close_end = text.find(">", name.end()) + 1
            i = text.find("<", name.end())
            continue
        name = _NAME.match(text, i + 1)
        if name is None:
            return None
        pos, attrs = name.end(), []
        while (m := _ATTR.match(text, pos)) is not None:
            attrs.append(
                _Attr(
                    m.group(2),
                    m.start(1),
                    m.start(2),
                    m.end(2),
                    m.start(4) + 1,
                    m.end(4) - 1,
                    m.group(4)[0],
                )
            )
            pos = m.end()
        close = _CLOSE.match(text, pos)
        if close is None:
            return None
        tag = _Tag(name.group(), name.start(), name.end(), attrs, pos, bool(close.group(1)), i)
        tag.close_end = close.end()
        if stack:
            stack[-1].children.append(tag)
        tags.append(tag)
        if not tag.empty:
            stack.append(tag)
        i = text.find("<", close.end())
    return tags if not stack else None


def _escape(value: str, quote: str) -> str:
    value = value.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
    return value.replace(quote, "&quot;" if quote == '"' else "&apos;")


class _Edits:
    def __init__(self) -> None:
        self.items: list[tuple[int, int, str]] = []

    def replace(self, start: int, end: int, text: str) -> None:
        self.items.append((start, end, text))

    def apply(self, text: str) -> str:
        out, last = [], len(text)
        for start, end, new in sorted(self.items, key=lambda e: (e[0], e[1]), reverse=True):
            out.append(text[end:last])
            out.append(new)
            last = start
        out.append(text[:last])
        return "".join(reversed(out))


def _attributes(edits: _Edits, tag: _Tag, parsed: dict[str, str], target: dict[str, str]) -> None:
    """Edit ``tag``'s attributes (``parsed``: their values as read) into ``target``."""
    dropped = [a for a in tag.attrs if a.key not in target]
    added = [k for k in target if k not in parsed]
    for attr in tag.attrs:
        if attr.key in target and parsed[attr.key] != target[attr.key]:
            edits.replace(attr.value_start, attr.value_end, _escape(target[attr.key], attr.quote))
    for index, attr in enumerate(dropped):
        if index < len(added):  # renamed in place: the k-th dropped name is the k-th new one
            key = added[index]
            edits.replace(attr.key_start, attr.key_end, key)
            if parsed[attr.key] != target[key]:
                edits.replace(attr.value_start, attr.value_end, _escape(target[key], attr.quote))
        else:
            edits.replace(attr.start, attr.value_end + 1, "")
    extra = "".join(f' {k}="{_escape(target[k], chr(34))}"' for k in added[len(dropped) :])
    if extra:
        edits.replace(tag.attrs_end, tag.attrs_end, extra)


def _rename(edits: _Edits, tag: _Tag, name: str) -> None:
    if name == tag.name:
        return
    edits.replace(tag.name_start, tag.name_end, name)
    if tag.end_name is not None:
        edits.replace(tag.end_name[0], tag.end_name[1], name)


def _node(edits: _Edits, tag: _Tag, element: etree._Element, node: BTNode) -> None:
    parsed = dict(element.attrib)
    target: dict[str, str] = {}
    if tag.name in EXPLICIT_TAGS and tag.name != "SubTree":
        target["ID"] = node.type
    elif node.kind is NodeKind.SUBTREE:
        _rename(edits, tag, "SubTree")
    else:
        _rename(edits, tag, node.type)
    if node.name is not None:
        target["name"] = node.name
    target.update(node.attrs)
    _attributes(edits, tag, parsed, target)


def _line_indent(text: str, position: int) -> str | None:
    """The whitespace between the line's start and ``position``, ``None`` if not only blanks."""
    line_start = text.rfind("\n", 0, position) + 1
    before = text[line_start:position]
    return before if not before.strip() else None


def _written_parts(
    written: str, declared: set[str], own_trees: set[str]
) -> tuple[list[str], list[str]]:
    """The writer's ``<BehaviorTree>`` s the file does not define (from its includes or other
    files) and its ``<TreeNodesModel>`` entries the file does not declare, as XML text."""
    root = parse_xml(written, "<written>")
    trees: list[str] = []
    entries: list[str] = []
    for child in root:
        if child.tag == "BehaviorTree" and child.get("ID") not in own_trees:
            trees.append(etree.tostring(child, encoding="unicode", with_tail=False))
        elif child.tag == "TreeNodesModel":
            entries.extend(
                etree.tostring(entry, encoding="unicode", with_tail=False)
                for entry in child
                if isinstance(entry.tag, str) and entry.get("ID") not in declared
            )
    return trees, entries


def _indented(element: str, indent: str, base: int) -> str:
    """An element the writer indented at ``base`` spaces, re-indented at ``indent``."""
    lines = element.split("\n")
    rest = [
        indent + (line[base:] if line.startswith(" " * base) else line.lstrip())
        for line in lines[1:]
    ]
    return "\n".join([indent + lines[0], *rest])


def _remove_line(edits: _Edits, text: str, tag: _Tag) -> None:
    """Remove an element, with its line when nothing else is on it."""
    indent = _line_indent(text, tag.start)
    line_end = text.find("\n", tag.close_end)
    line_end = len(text) if line_end == -1 else line_end + 1
    if indent is not None and not text[tag.close_end : line_end].strip():
        edits.replace(tag.start - len(indent), line_end, "")
    else:
        edits.replace(tag.start, tag.close_end, "")


def _additions(edits: _Edits, text: str, root: _Tag, written: str, own_trees: set[str]) -> bool:
    """Insert the trees and declarations of the writer's file that the file lacks; remove its
    ``<include>`` s (their trees are inserted); ``False`` when it cannot."""
    model_tags = [t for t in root.children if t.name == "TreeNodesModel"]
    declared = {
        value
        for t in model_tags
        for entry in t.children
        for value in [_value(text, entry, "ID")]
        if value is not None
    }
    trees, entries = _written_parts(written, declared, own_trees)
    for tag in root.children:
        if tag.name == "include":
            _remove_line(edits, text, tag)
    if root.end_start is None:
        return False
    closing = _line_indent(text, root.end_start)
    unit = _line_indent(text, root.children[0].start) if root.children else None
    inline = closing is None or not unit
    block = ""
    for tree in trees:
        block += tree if inline else _indented(tree, unit or "", 2) + "\n"
    if entries and model_tags:
        models = model_tags[-1]
        if models.end_start is None:
            return False  # <TreeNodesModel/>
        last = _line_indent(text, models.end_start)
        inner = (
            _line_indent(text, models.children[-1].start)
            if models.children
            else (last or "") + "  "
        )
        if last is None or inner is None:
            edits.replace(models.end_start, models.end_start, "".join(entries))
        else:
            at = models.end_start - len(last)
            edits.replace(at, at, "".join(_indented(e, inner, 4) + "\n" for e in entries))
    elif entries and inline:
        block += "<TreeNodesModel>" + "".join(entries) + "</TreeNodesModel>"
    elif entries:
        body = "".join(_indented(e, (unit or "") * 2, 4) + "\n" for e in entries)
        block += f"{unit}<TreeNodesModel>\n{body}{unit}</TreeNodesModel>\n"
    if block:
        at = root.end_start - (0 if inline else len(closing or ""))
        edits.replace(at, at, block)
    return True


def _value(text: str, tag: _Tag, key: str) -> str | None:
    for attr in tag.attrs:
        if attr.key == key:
            return text[attr.value_start : attr.value_end]
    return None


def _root(edits: _Edits, text: str, tag: _Tag, doc: BTDocument, n_trees: int) -> None:
    keys = [a.key for a in tag.attrs]
    version = next((a for a in tag.attrs if a.key == "BTCPP_format"), None)
    insert = ""
    if version is None:
        insert += ' BTCPP_format="4"'
    elif text[version.value_start : version.value_end] != "4":
        edits.replace(version.value_start, version.value_end, "4")
    if "main_tree_to_execute" not in keys and n_trees > 1 and doc.trees:
        insert += f' main_tree_to_execute="{_escape(doc.main.id, chr(34))}"'
    if insert:
        at = version.value_end + 1 if version is not None else tag.name_end
        edits.replace(at, at, insert)


def edited_source(original: str, doc: BTDocument, written: str) -> str | None:
    """The user's file with the edits v4 needs (module docstring), or ``None``.

    Args:
        original: the file's text, as decoded (line ends kept).
        doc: the document read from it.
        written: the v4 writer's text of ``doc``.
    """
    try:
        root_element = parse_xml(original, "<source>", [])
    except InputError:
        return None
    tags = _scan(original)
    elements = [e for e in root_element.iter() if isinstance(e.tag, str)]
    if tags is None or len(tags) != len(elements):
        return None
    if any(
        t.name != e.tag or [a.key for a in t.attrs] != list(e.attrib)
        for t, e in zip(tags, elements)
    ):
        return None
    by_element = dict(zip(elements, tags))
    edits = _Edits()
    root = tags[0]
    trees = [e for e in root_element if e.tag == "BehaviorTree"]
    _root(edits, original, root, doc, len(doc.trees))
    for tree_element in trees:
        tree_id = tree_element.get("ID") or "MainTree"
        if tree_element.get("ID") is None:
            tag = by_element[tree_element]
            edits.replace(tag.attrs_end, tag.attrs_end, ' ID="MainTree"')
        tree = doc.trees.get(tree_id)
        if tree is None:
            return None
        nodes = list(tree.root.walk()) if tree.root is not None else []
        node_elements = [e for e in tree_element.iter() if isinstance(e.tag, str)][1:]
        if len(nodes) != len(node_elements):
            return None
        for element, node in zip(node_elements, nodes):
            _node(edits, by_element[element], element, node)
    own = {t.get("ID") or "MainTree" for t in trees}
    if not _additions(edits, original, root, written, own):
        return None
    text = edits.apply(original)
    try:
        same = model_to_dict(read_btcpp(text, ReadContext())) == model_to_dict(
            read_btcpp(written, ReadContext())
        )
    except InputError:
        return None
    return text if same else None


__all__ = ["edited_source"]
