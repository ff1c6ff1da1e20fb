"""fsmbt.limits: one place for every bound; each overridable (environment, a copy with
changes, ``use``) and each honoured by the reader it bounds, with an error naming the limit
and the variable that raises it."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import pytest

from fsmbt import api, limits
from fsmbt.formats import loads
from fsmbt.model.errors import InputError

FSM_JSON = json.dumps(
    {
        "kind": "fsm",
        "initial": "A",
        "states": [
            {"name": "A", "action": "A"},
            {"name": "B", "action": "B"},
            {"name": "C", "action": "C"},
        ],
        "transitions": [{"source": "A", "event": "go", "target": "B"}],
    }
)
BT_XML = (
    '<root BTCPP_format="4"><BehaviorTree ID="T"><Sequence><Inverter><Inverter>'
    "<AlwaysSuccess/></Inverter></Inverter><AlwaysFailure/></Sequence></BehaviorTree></root>"
)


@pytest.fixture
def override() -> Iterator[None]:
    previous = limits.current()
    yield
    limits.use(previous)


def use(**changes: int | float) -> None:
    limits.use(limits.current().with_changes(**changes))


def test_every_limit_has_a_documented_environment_variable() -> None:
    docs = (Path(__file__).resolve().parents[1] / "docs" / "security.md").read_text("utf-8")
    for field in limits.Limits.__dataclass_fields__:
        name = limits.env_name(field)
        assert name.startswith("FSMBT_MAX_")
        assert name in docs, f"{name} is not documented in docs/security.md"
        assert field in (limits.Limits.__doc__ or ""), f"{field} has no docstring entry"


def test_environment_overrides_and_bad_values_are_refused() -> None:
    env = {
        "FSMBT_MAX_STATES": "7",
        "FSMBT_MAX_NUSMV_SECONDS": "2.5",
        "FSMBT_MAX_CHECKER_STATES": "99",
    }
    got = limits.from_environment(environ=env)
    assert (got.max_states, got.nusmv_max_seconds, got.checker_max_states) == (7, 2.5, 99)
    assert got.max_nodes == limits.Limits().max_nodes  # the rest keep their defaults
    with pytest.raises(ValueError, match="FSMBT_MAX_STATES='many' is not a number"):
        limits.from_environment(environ={"FSMBT_MAX_STATES": "many"})
    with pytest.raises(ValueError, match="must be positive"):
        limits.from_environment(environ={"FSMBT_MAX_NODES": "0"})


def test_with_changes_is_a_copy_and_checks_names(override: None) -> None:
    base = limits.current()
    changed = base.with_changes(max_states=3)
    assert changed.max_states == 3 and base.max_states != 3
    with pytest.raises(ValueError, match="unknown limit 'max_cats'"):
        base.with_changes(max_cats=1)
    with pytest.raises(ValueError, match="positive"):
        base.with_changes(max_nodes=-1)


def test_environment_is_read_after_reset(monkeypatch: pytest.MonkeyPatch, override: None) -> None:
    monkeypatch.setenv("FSMBT_MAX_INPUT_BYTES", "10")
    limits.reset()
    with pytest.raises(InputError, match=r"exceed\(s\) the limit of 10 .*FSMBT_MAX_INPUT_BYTES"):
        loads(FSM_JSON, "json")
    monkeypatch.delenv("FSMBT_MAX_INPUT_BYTES")
    limits.reset()
    assert loads(FSM_JSON, "json")


def test_input_size_bounds_files_and_text(tmp_path: Path, override: None) -> None:
    path = tmp_path / "m.json"
    path.write_text(FSM_JSON, encoding="utf-8")
    use(max_input_bytes=50)
    with pytest.raises(InputError, match=f"{path}.*bytes exceed.*limit of 50"):
        api.load(path)
    with pytest.raises(InputError, match="limit of 50"):
        loads(FSM_JSON, "json")


def test_state_and_node_counts(override: None) -> None:
    use(max_states=2)
    with pytest.raises(InputError, match=r"states exceed\(s\) the limit of 2 .*FSMBT_MAX_STATES"):
        loads(FSM_JSON, "json")
    use(max_states=3, max_nodes=4)
    assert loads(FSM_JSON, "json")
    with pytest.raises(InputError, match=r"nodes exceed\(s\) the limit of 4 .*FSMBT_MAX_NODES"):
        loads(BT_XML, "btcpp")


def test_the_interpreter_bounds_expanded_subtrees_by_the_limit_in_force(override: None) -> None:
    """A SubTree used twice per level doubles the tree at every level: 9 read nodes, at least
    15 once expanded. The interpreter's bound is the ``max_nodes`` in force, not the default."""
    from fsmbt.semantics.bt_interpreter import BTInterpreter

    text = (
        '<root BTCPP_format="4" main_tree_to_execute="T">'
        '<BehaviorTree ID="T"><Sequence><SubTree ID="U"/><SubTree ID="U"/></Sequence></BehaviorTree>'
        '<BehaviorTree ID="U"><Sequence><SubTree ID="V"/><SubTree ID="V"/></Sequence></BehaviorTree>'
        '<BehaviorTree ID="V"><Sequence><AlwaysSuccess/><AlwaysFailure/></Sequence></BehaviorTree>'
        "</root>"
    )
    use(max_nodes=10)
    doc = loads(text, "btcpp")
    with pytest.raises(InputError, match=r"expanded exceed\(s\) the limit of 10 .*FSMBT_MAX_NODES"):
        BTInterpreter(doc)
    use(max_nodes=100)
    assert BTInterpreter(doc) is not None


@pytest.mark.parametrize(
    ("fmt", "text", "variable"),
    [
        ("btcpp", BT_XML, "FSMBT_MAX_XML_DEPTH"),
        ("json", FSM_JSON, "FSMBT_MAX_JSON_DEPTH"),
        (
            "yaml",
            "kind: fsm\nstates:\n  - name: A\n    attrs: {x: {y: 1}}\n",
            "FSMBT_MAX_YAML_DEPTH",
        ),
    ],
)
def test_nesting_depth(fmt: str, text: str, variable: str, override: None) -> None:
    assert loads(text, fmt)
    use(max_xml_depth=3, max_json_depth=2, max_yaml_depth=3)
    with pytest.raises(InputError, match=f"nested deeper than .*{variable}"):
        loads(text, fmt)


def test_include_chain_depth(tmp_path: Path, override: None) -> None:
    body = '<BehaviorTree ID="T{n}"><AlwaysSuccess/></BehaviorTree>'
    for n in range(4):
        include = f'<include path="f{n + 1}.xml"/>' if n < 3 else ""
        (tmp_path / f"f{n}.xml").write_text(
            f'<root BTCPP_format="4" main_tree_to_execute="T0">{include}{body.format(n=n)}</root>',
            encoding="utf-8",
        )
    assert api.load(tmp_path / "f0.xml").model
    use(max_include_depth=2)
    with pytest.raises(InputError, match="include chain of 3 files.*FSMBT_MAX_INCLUDE_DEPTH"):
        api.load(tmp_path / "f0.xml")


def test_includes_are_confined_to_the_read_files_folder(tmp_path: Path) -> None:
    outside = tmp_path / "outside.xml"
    outside.write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="X"><AlwaysSuccess/></BehaviorTree></root>',
        encoding="utf-8",
    )
    project = tmp_path / "project"
    (project / "sub").mkdir(parents=True)
    (project / "sibling.xml").write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="S"><AlwaysSuccess/></BehaviorTree></root>',
        encoding="utf-8",
    )
    # ../sibling.xml from a subfolder stays inside the read file's folder: allowed
    (project / "sub" / "child.xml").write_text(
        '<root BTCPP_format="4"><include path="../sibling.xml"/><BehaviorTree ID="C">'
        '<SubTree ID="S"/></BehaviorTree></root>',
        encoding="utf-8",
    )
    main = project / "main.xml"
    main.write_text(
        '<root BTCPP_format="4" main_tree_to_execute="M">'
        '<include path="sub/child.xml"/><BehaviorTree ID="M"><SubTree ID="C"/>'
        "</BehaviorTree></root>",
        encoding="utf-8",
    )
    assert set(api.load(main).model.trees) == {"M", "C", "S"}
    for target in ("../outside.xml", str(outside), "/etc/passwd", "/dev/zero"):
        main.write_text(
            f'<root BTCPP_format="4"><include path="{target}"/>'
            '<BehaviorTree ID="M"><AlwaysSuccess/></BehaviorTree></root>',
            encoding="utf-8",
        )
        with pytest.raises(InputError, match="outside the folder of the file read"):
            api.load(main)
    (project / "link.xml").symlink_to(outside)
    main.write_text(
        '<root BTCPP_format="4"><include path="link.xml"/>'
        '<BehaviorTree ID="M"><AlwaysSuccess/></BehaviorTree></root>',
        encoding="utf-8",
    )
    with pytest.raises(InputError, match="outside the folder"):
        api.load(main)
    fifo = project / "pipe.xml"
    import os

    os.mkfifo(fifo)
    main.write_text(
        '<root BTCPP_format="4"><include path="pipe.xml"/>'
        '<BehaviorTree ID="M"><AlwaysSuccess/></BehaviorTree></root>',
        encoding="utf-8",
    )
    with pytest.raises(InputError, match="not a regular file"):
        api.load(main)


def test_limits_module_imports_nothing_from_fsmbt() -> None:
    import ast

    source = Path(limits.__file__).read_text(encoding="utf-8")
    imported = [
        n
        for node in ast.walk(ast.parse(source))
        if isinstance(node, (ast.Import, ast.ImportFrom))
        for n in (
            [node.module or ""]
            if isinstance(node, ast.ImportFrom)
            else [a.name for a in node.names]
        )
    ]
    assert not [n for n in imported if n.startswith("fsmbt")], imported


def test_include_root_option_widens_the_confinement(tmp_path: Path) -> None:
    (tmp_path / "common.xml").write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="S"><AlwaysSuccess/></BehaviorTree></root>',
        encoding="utf-8",
    )
    (tmp_path / "sub").mkdir()
    child = tmp_path / "sub" / "child.xml"
    child.write_text(
        '<root BTCPP_format="4" main_tree_to_execute="C"><include path="../common.xml"/>'
        '<BehaviorTree ID="C"><SubTree ID="S"/></BehaviorTree></root>',
        encoding="utf-8",
    )
    with pytest.raises(InputError, match="outside the folder of the file read"):
        api.load(child)
    assert set(api.load(child, options={"include_root": str(tmp_path)}).model.trees) == {"C", "S"}


def test_changed_holds_for_its_block_only_even_when_the_block_raises() -> None:
    before = limits.current()
    with limits.changed(max_states=7) as inside:
        assert limits.current() is inside and inside.max_states == 7
        assert inside.max_nodes == before.max_nodes
    assert limits.current() is before
    with pytest.raises(RuntimeError), limits.changed(max_nodes=3):
        raise RuntimeError("the block failed")
    assert limits.current() is before
