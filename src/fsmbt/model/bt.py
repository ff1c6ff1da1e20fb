"""The behavior tree model (docs/semantics.md, 'Models'), kept close to BehaviorTree.CPP v4's XML.

A ``BTDocument`` is what one file (plus its includes) holds: several ``BehaviorTree`` s, the one to
execute, and the ``TreeNodesModel`` declarations. Attributes and ports stay on the nodes in order,
so reading and writing a file loses nothing.

``BTNode`` is a slotted dataclass (one allocation of 96 bytes per node, fields read without a
dictionary: a converted tree holds 3-4 nodes per FSM state); a node has its fields and no
others - setting any other attribute raises ``AttributeError``.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

from fsmbt.model.bt_nodes import NodeKind, builtin_spec
from fsmbt.model.errors import SourceLocation


@dataclass(eq=False, repr=False, slots=True)
class BTNode:
    """One node. ``type`` is the v4 registration ID (``Sequence``, ``Inverter``, ``MoveTo``...).

    ``attrs`` holds every XML attribute except ``name`` (ports included), in file order. For a
    ``SubTree`` node the referenced tree is ``attrs["ID"]``. ``kind_declared`` is False when a
    leaf's kind was not declared anywhere and was assumed (Action, the safe choice: it may
    return RUNNING). ``semantics`` is the registered kind that gives the node its meaning when
    a node library or an option enabled one (``fsmbt.model.nodes.library``): a project kind
    (``RateController`` under ``--nodes nav2``), an abstraction (``Sleep`` under ``--abstract
    time``) or the kind a user's ``--nodes`` file maps a custom type to; ``None``: the type's
    own kind, if it needs no option.

    Attributes:
        type: The node type (registration ID).
        kind: Its family: control, decorator, action, condition or subtree.
        name: The instance name, when the file gives one.
        attrs: The other XML attributes (ports), in file order.
        children: The child nodes, in order.
        kind_declared: False when a leaf's kind was assumed (see above).
        semantics: The registered kind that gives the node its meaning (see above), or None.
        location: Where the node was read (not compared).
    """

    type: str
    kind: NodeKind
    name: str | None = None
    attrs: dict[str, str] = field(default_factory=dict)
    children: list[BTNode] = field(default_factory=list)
    kind_declared: bool = True
    location: SourceLocation | None = field(default=None, compare=False, repr=False)
    semantics: str | None = field(default=None, compare=False, repr=False)

    @property
    def label(self) -> str:
        """What a person calls this node: its name, else its type."""
        return self.name or self.type

    @property
    def is_leaf(self) -> bool:
        """Whether the node is an Action or a Condition."""
        return self.kind in (NodeKind.ACTION, NodeKind.CONDITION)

    @property
    def is_builtin(self) -> bool:
        """Whether the type is one of BehaviorTree.CPP v4's built-in nodes."""
        return builtin_spec(self.type) is not None

    @property
    def subtree_id(self) -> str | None:
        """The referenced tree's ID for a ``SubTree`` node, else ``None``."""
        return self.attrs.get("ID") if self.kind is NodeKind.SUBTREE else None

    def __eq__(self, other: object) -> bool:
        """Structural equality (location ignored), iterative: trees may be 100 000 deep."""
        if not isinstance(other, BTNode):
            return NotImplemented
        stack: list[tuple[BTNode, BTNode]] = [(self, other)]
        while stack:
            a, b = stack.pop()
            if (a.type, a.kind, a.name, a.attrs, a.kind_declared, len(a.children)) != (
                b.type,
                b.kind,
                b.name,
                b.attrs,
                b.kind_declared,
                len(b.children),
            ):
                return False
            stack.extend(zip(a.children, b.children))
        return True

    __hash__ = None  # type: ignore[assignment]  # mutable, like the other model classes

    def __repr__(self) -> str:
        """Shallow on purpose: a deep tree's full repr would recurse and be unreadable."""
        name = f" name={self.name!r}" if self.name else ""
        return f"<BTNode {self.type}{name} kind={self.kind.value} children={len(self.children)}>"

    def walk(self) -> Iterator[BTNode]:
        """Pre-order traversal without recursion (trees may be 100 000 deep).

        Returns:
            An iterator over this node and its descendants, parents before children,
            children in order.
        """
        stack: list[BTNode] = [self]
        while stack:
            node = stack.pop()
            yield node
            stack.extend(reversed(node.children))


@dataclass
class PortModel:
    """A port of a declared node type (``<input_port>``, ``<output_port>``, ``<inout_port>``).

    Attributes:
        name: The port's name.
        direction: ``input``, ``output`` or ``inout``.
        default: The default value, when declared.
        description: The port's description text, when given.
        type: The declared value type, when given.
    """

    name: str
    direction: str = "input"  # input | output | inout
    default: str | None = None
    description: str | None = None
    type: str | None = None


@dataclass
class NodeModel:
    """A ``<TreeNodesModel>`` entry: declares a custom node type's kind and ports (for Groot2).

    Attributes:
        type: The node type it declares.
        kind: The declared family (action, condition, control, decorator, subtree).
        ports: The declared ports.
        attrs: The entry's other attributes.
    """

    type: str
    kind: NodeKind
    ports: list[PortModel] = field(default_factory=list)
    attrs: dict[str, str] = field(default_factory=dict)


@dataclass
class BehaviorTree:
    """One ``<BehaviorTree ID=...>`` of a document.

    Attributes:
        id: The tree's ID (``SubTree`` nodes refer to it).
        root: Its root node (``None`` for an empty tree).
        attrs: The element's other attributes.
        location: Where the tree was read (not compared).
    """

    id: str
    root: BTNode | None
    attrs: dict[str, str] = field(default_factory=dict)
    location: SourceLocation | None = field(default=None, compare=False, repr=False)


@dataclass
class BTDocument:
    """Everything one BT file holds. ``main_tree`` is the tree to execute.

    Attributes:
        trees: The trees by ID, in file order.
        main_tree: The ID of the tree to execute (``None``: the only or first tree).
        node_models: Declared node types by type name.
        format_version: BehaviorTree.CPP's ``BTCPP_format`` (``"3"`` or ``"4"``).
        includes: The ``<include path=...>`` files merged in.
        attrs: The root element's other attributes.
    """

    trees: dict[str, BehaviorTree] = field(default_factory=dict)
    main_tree: str | None = None
    node_models: dict[str, NodeModel] = field(default_factory=dict)
    format_version: str = "4"
    includes: list[str] = field(default_factory=list)
    attrs: dict[str, str] = field(default_factory=dict)

    @classmethod
    def single(cls, root: BTNode, tree_id: str = "MainTree") -> BTDocument:
        """A document with one tree, the usual shape of a converter's output.

        Args:
            root: The tree's root node.
            tree_id: The tree's ID, also the main tree.

        Returns:
            The document.
        """
        return cls(trees={tree_id: BehaviorTree(tree_id, root)}, main_tree=tree_id)

    @property
    def main(self) -> BehaviorTree:
        """The tree to execute: ``main_tree``, else the only / first tree.

        Raises:
            KeyError: The document holds no tree.
        """
        if self.main_tree is not None and self.main_tree in self.trees:
            return self.trees[self.main_tree]
        if not self.trees:
            raise KeyError("the document holds no behavior tree")
        return next(iter(self.trees.values()))

    def nodes(self) -> Iterator[tuple[str, BTNode]]:
        """Every node of every tree.

        Returns:
            An iterator of ``(tree id, node)``, trees in order, each tree pre-order.
        """
        for tree in self.trees.values():
            if tree.root is not None:
                for node in tree.root.walk():
                    yield tree.id, node
