"""Certificates of per-node proofs (issue 27 item 3; docs/verification.md §6): one ``pernode``
unit per distinct local check, re-checked on the local machines rebuilt from the two models
(``pernode.NodeWalk``, ``pernode.local_machines``), the units covering every node the walk
needs; an edited table, relation, interface or coverage, a dropped, duplicated or swapped
unit, other files and a certificate patched onto a mutant are refused; a lifted
counterexample's certificate replays."""

from __future__ import annotations

import copy
import json
import random
from collections import Counter
from typing import Any

import pytest

from fsmbt import api
from fsmbt.cli import main
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.model.errors import InputError
from fsmbt.verify import certificate
from fsmbt.verify.compositional import compositional_report, structure
from fsmbt.verify.native import check_witnessed
from fsmbt.verify.pernode import LOCAL_LIMIT, STATUS_OF, NodeWalk, local_machines
from fsmbt.verify.report import COMPOSITIONAL_LIFTED, LIFTED, PER_NODE
from support.pernode_certs import FAMILIES, SOURCE, certify, family_pair, recheck
from support.pernode_mutants import mutate, pernode_machine, whole
from support.pernode_trees import pernode_tree, seeded_trees

PERNODE = certificate.PERNODE
STATUSES = ("success", "failure", "running")


def _pernode_units(data):  # type: ignore[no-untyped-def]
    return [unit for unit in data["units"] if unit["kind"] == PERNODE]


@pytest.mark.parametrize("family", FAMILIES)
def test_a_per_node_proof_gets_a_certificate_that_checks(family: str) -> None:
    for seed in (1, 2):
        doc, model = family_pair(family, 40, seed)
        report, data = certify(doc, model)
        assert report.equivalent and report.method == PER_NODE
        units = _pernode_units(data)
        assert units and data["units"][-1]["kind"] == "skeleton"
        nodes = [(unit["tree_region"], path) for unit in units for path in unit["nodes"]]
        assert len(nodes) == len(set(nodes))  # one unit per node of a region
        assert len(units) <= report.stats["per_node_distinct"]
        checked = recheck(data, doc, model)
        assert checked.equivalent and checked.method == PER_NODE
        assert checked.units[PERNODE] == len(units)
        assert checked.pairs == certificate.relation_pairs(data)


def test_a_certificate_changes_no_verdict_on_seeded_small_trees() -> None:
    """The bench families and every kind ``convert/bt_pernode`` writes (Async*, Parallel,
    ParallelAll, loops with -1): with a certificate the method is the one without, and every
    certificate checks."""
    rng = random.Random(5)
    tally: Counter[str] = Counter()
    for index in range(120):
        if index % 2:
            doc = pernode_tree(rng.randint(2, 7), 1000 + index)
            model = bt_to_hfsm(doc, pernode=True).model
        else:
            doc, model = family_pair(FAMILIES[index // 2 % 4], rng.randint(2, 12), 1000 + index)
        plain, _why = compositional_report(doc, model)
        report, data = certify(doc, model)
        if plain is not None:
            assert report.method == plain.method
        tally[report.method] += 1
        assert report.equivalent and recheck(data, doc, model).equivalent
    print(f"\n[certificates on small trees] {dict(tally)}")
    assert tally[PER_NODE] >= 90


def _walk_units(doc, model, data):  # type: ignore[no-untyped-def]
    """The local checks of ``data``'s regions proven per node, re-derived as the checker does
    (``pernode.NodeWalk``): per first node of each unit, the unit, its problem and its σ."""
    shape = structure(doc, model)
    units = _pernode_units(data)
    for k, j in sorted({(u["tree_region"], u["fsm_region"]) for u in units}):
        mine = [u for u in units if (u["tree_region"], u["fsm_region"]) == (k, j)]
        owner = {path: u for u in mine for path in u["nodes"]}
        walk = NodeWalk(shape.regions[k], shape.machine_regions[j].machine, shape.declared)
        done: set[int] = set()
        for problem in walk.problems():
            unit = owner[problem.node.path]
            sigma = {
                STATUS_OF[s]: (int(e[0]), tuple(int(a) for a in e[1]))
                for s, e in unit["interface"].items()
            }
            if id(unit) not in done:
                done.add(id(unit))
                yield unit, problem, sigma
            walk.settle(problem, sigma, bool(unit["halt"]))


def _native_units(doc, model, data):  # type: ignore[no-untyped-def]
    """Each pernode unit of ``data`` next to the native checker's witness on the
    ``local_machines`` of the first node it covers."""
    for unit, problem, sigma in _walk_units(doc, model, data):
        machines = local_machines(problem, sigma, bool(unit["halt"]))
        report, witness = check_witnessed(*machines, max_states=LOCAL_LIMIT)
        assert report.equivalent
        yield unit, json.loads(json.dumps(witness.to_data()))


def test_the_witness_from_the_proofs_own_steps_is_the_native_checkers() -> None:
    """A unit is numbered from the per-node check's own lockstep steps (``pernode._witness_of``,
    no second search): on the bench families and every kind ``convert/bt_pernode`` writes, it
    is exactly the native checker's witness on ``pernode.local_machines`` (same outputs, same
    tables state for state and edge for edge, same relation as a set)."""
    compared = 0
    for index in range(24):
        if index % 2:
            doc = pernode_tree(3 + index % 5, 2000 + index)
            model = bt_to_hfsm(doc, pernode=True).model
        else:
            doc, model = family_pair(FAMILIES[index // 2 % 4], 4 + index, 2000 + index)
        report, data = certify(doc, model)
        if report.method != PER_NODE:
            continue
        for unit, native in _native_units(doc, model, data):
            assert unit["outputs"] == native["outputs"]
            assert unit["machines"] == native["machines"]
            assert sorted(map(tuple, unit["relation"])) == sorted(map(tuple, native["relation"]))
            compared += 1
    print(f"\n[units compared with the native witness] {compared}")
    assert compared >= 60


def test_a_certificate_does_not_make_a_large_proof_fall_back() -> None:
    """With a certificate asked, a 1 000-node mixed tree is still proven per node (before,
    a certificate checked each region whole)."""
    doc, model = family_pair("mixed", 500, 1000)
    report, data = certify(doc, model)
    assert report.method == PER_NODE
    assert "compositional" not in report.stats  # no fall-back reason
    assert recheck(data, doc, model).equivalent


@pytest.fixture(scope="module")
def proof():  # type: ignore[no-untyped-def]
    doc, model = family_pair("mixed", 40, 3)  # a node that never returns RUNNING among them
    _report, data = certify(doc, model)
    units = _pernode_units(data)
    assert len(units) >= 3
    return doc, model, data


def _pernode_index(data, rank: int = 0) -> int:  # type: ignore[no-untyped-def]
    return [i for i, u in enumerate(data["units"]) if u["kind"] == PERNODE][rank]


def _largest(data) -> int:  # type: ignore[no-untyped-def]
    """The pernode unit with the most states (its tables have edges to edit)."""
    found = [i for i, u in enumerate(data["units"]) if u["kind"] == PERNODE]
    return max(found, key=lambda i: len(data["units"][i]["relation"]))


def _edit_edge(d) -> None:  # type: ignore[no-untyped-def]
    unit = d["units"][_largest(d)]
    edge = unit["machines"]["result"]["edges"][0][0]
    edge[2] = (edge[2] + 1) % len(unit["outputs"])


def _edit_state(d) -> None:  # type: ignore[no-untyped-def]
    d["units"][_largest(d)]["machines"]["source"]["states"][0][0] = "at child 7"


def _drop_pair(d) -> None:  # type: ignore[no-untyped-def]
    d["units"][_largest(d)]["relation"].pop()


def _edit_interface(d) -> None:  # type: ignore[no-untyped-def]
    interface = d["units"][_largest(d)]["interface"]
    status = sorted(interface)[0]
    interface[status] = [interface[status][0] + 1, interface[status][1]]


def _extra_status(d) -> None:  # type: ignore[no-untyped-def]
    """σ pairs a status the node never returns (with an exit the node has)."""
    unit = next(
        u for u in d["units"] if u["kind"] == PERNODE and len(u["interface"]) < len(STATUSES)
    )
    interface = unit["interface"]
    missing = next(s for s in STATUSES if s not in interface)
    interface[missing] = next(iter(interface.values()))


def _drop_unit(d) -> None:  # type: ignore[no-untyped-def]
    d["units"].pop(_pernode_index(d))


def _duplicate_unit(d) -> None:  # type: ignore[no-untyped-def]
    i = _pernode_index(d)
    d["units"].insert(i, copy.deepcopy(d["units"][i]))


def _swap_tables(d) -> None:  # type: ignore[no-untyped-def]
    """Two units exchange their tables, each keeping its nodes."""
    first, second = d["units"][_pernode_index(d, 0)], d["units"][_pernode_index(d, 1)]
    for key in ("outputs", "machines", "relation", "interface", "halt"):
        first[key], second[key] = second[key], first[key]


def _swap_nodes(d) -> None:  # type: ignore[no-untyped-def]
    first, second = d["units"][_pernode_index(d, 0)], d["units"][_pernode_index(d, 1)]
    first["nodes"], second["nodes"] = second["nodes"], first["nodes"]


def _merge_units(d) -> None:  # type: ignore[no-untyped-def]
    """Two units of one region merged: the second's nodes listed with the first's problem."""
    units = [u for u in d["units"] if u["kind"] == PERNODE]
    donor = units[1]
    taker = next(u for u in units if u is not donor and u["tree_region"] == donor["tree_region"])
    taker["nodes"].extend(donor["nodes"])
    d["units"].remove(donor)


def _unknown_node(d) -> None:  # type: ignore[no-untyped-def]
    d["units"][_pernode_index(d)]["nodes"].append("9/9/9")


def _as_region(d) -> None:  # type: ignore[no-untyped-def]
    d["units"][_pernode_index(d)]["kind"] = "region"


def _claim_compositional(d) -> None:  # type: ignore[no-untyped-def]
    d["method"] = "compositional"


TAMPERS = {
    "edited-edge": _edit_edge,
    "edited-state": _edit_state,
    "relation-pair-dropped": _drop_pair,
    "interface-edited": _edit_interface,
    "interface-extra-status": _extra_status,
    "unit-dropped": _drop_unit,
    "unit-duplicated": _duplicate_unit,
    "tables-swapped": _swap_tables,
    "nodes-swapped": _swap_nodes,
    "units-merged": _merge_units,
    "node-unknown": _unknown_node,
    "unit-kind": _as_region,
    "method": _claim_compositional,
}


@pytest.mark.parametrize("name", sorted(TAMPERS))
def test_a_tampered_per_node_certificate_is_refused(proof, name: str) -> None:  # type: ignore[no-untyped-def]
    doc, model, data = proof
    assert recheck(data, doc, model).equivalent  # the untouched one is valid
    edited = copy.deepcopy(data)
    TAMPERS[name](edited)
    assert edited != data
    with pytest.raises(certificate.CertificateError):
        recheck(edited, doc, model)


def test_a_unit_repeating_an_earlier_regions_is_replayed_once_and_still_checked(
    monkeypatch,  # type: ignore[no-untyped-def]
) -> None:
    """The checker replays a unit equal to one already replayed for the same local problem
    only once; the repeat still counts, and the same repeat with one edited edge output or
    relation pair is replayed and refused."""
    doc, model = family_pair("mixed", 80, 3)  # regions proven per node, two repeated units
    _report, data = certify(doc, model)
    seen: set[Any] = set()
    repeat = None
    for unit, problem, _sigma in _walk_units(doc, model, data):
        fingerprint = json.dumps([unit[k] for k in ("interface", "halt", "outputs", "machines")])
        if (problem.key, fingerprint) in seen:
            repeat = data["units"].index(unit)
        seen.add((problem.key, fingerprint))
    assert repeat is not None
    replays: list[str] = []
    original = certificate.check_unit

    def counted(unit, source, result, name):  # type: ignore[no-untyped-def]
        replays.append(name)
        return original(unit, source, result, name)

    monkeypatch.setattr(certificate, "check_unit", counted)
    checked = recheck(data, doc, model)
    assert checked.equivalent and checked.pairs == certificate.relation_pairs(data)
    assert len(replays) < len(data["units"])  # the repeat was not replayed
    edited = copy.deepcopy(data)
    edge = edited["units"][repeat]["machines"]["source"]["edges"][0][0]
    edge[2] = (edge[2] + 1) % len(edited["units"][repeat]["outputs"])
    with pytest.raises(certificate.CertificateError, match="not as certified"):
        recheck(edited, doc, model)
    edited = copy.deepcopy(data)
    edited["units"][repeat]["relation"].pop()
    with pytest.raises(certificate.CertificateError):
        recheck(edited, doc, model)


def test_other_files_digests_are_refused(proof) -> None:  # type: ignore[no-untyped-def]
    doc, model, data = proof
    with pytest.raises(certificate.CertificateError, match="other files"):
        certificate.check(data, doc, model, source_digest=SOURCE, result_digest="another")


def test_a_certificate_patched_onto_a_differing_mutant_is_refused() -> None:
    rng = random.Random(8)
    refused = 0
    for seed in (1, 2, 3):
        doc, model = family_pair("mixed", 12, seed)
        _report, data = certify(doc, model)
        assert _pernode_units(data)
        for _ in range(8):
            mutant = mutate(model, rng)
            assert mutant is not None
            if whole(doc, mutant) is not False:
                continue  # only mutants the whole product tells apart
            with pytest.raises((certificate.CertificateError, InputError)):
                recheck(data, doc, mutant)
            refused += 1
    assert refused >= 5


def test_a_lifted_not_equivalent_certificate_replays() -> None:
    rng = random.Random(1)
    doc, model = family_pair("mixed", 40, 1)
    found = 0
    for _ in range(6):
        mutant = mutate(model, rng)
        assert mutant is not None
        try:
            report, data = certify(doc, mutant)
        except InputError:
            continue  # the whole product refuses this mutant (an eventless cycle)
        if report.method not in LIFTED:
            continue
        assert not data["equivalent"] and data["counterexamples"]
        checked = recheck(data, doc, mutant)
        assert not checked.equivalent and checked.steps > 0
        with pytest.raises(certificate.CertificateError):  # not a counterexample on the original
            recheck(data, doc, model)
        forged = copy.deepcopy(data)
        forged["counterexamples"] = {name: [] for name in forged["counterexamples"]}
        with pytest.raises(certificate.CertificateError):
            recheck(forged, doc, mutant)
        found += 1
        if found == 2:
            break
    assert found >= 2


def test_a_region_lifted_certificate_replays() -> None:
    """A mutant whose region is checked whole (a broken per-node side condition) and fails is
    refuted by the region's counterexample lifted to the whole tree (``compositional,
    lifted``): its certificate replays on the mutant and is refused on the original."""
    rng = random.Random(5)
    for doc in seeded_trees(60, seed=4):
        model = bt_to_hfsm(doc, pernode=True).model
        if pernode_machine(model) is None:
            continue
        mutant = mutate(model, rng)
        assert mutant is not None
        try:
            report, data = certify(doc, mutant)
        except InputError:
            continue
        if report.method != COMPOSITIONAL_LIFTED:
            continue
        assert not data["equivalent"] and data["method"] == COMPOSITIONAL_LIFTED
        assert not recheck(data, doc, mutant).equivalent
        with pytest.raises(certificate.CertificateError):
            recheck(data, doc, model)
        return
    raise AssertionError("no mutant of the sample was refuted by a lifted region")


def test_the_cli_writes_and_checks_a_per_node_certificate(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    doc, model = family_pair("memory", 30, 3)
    tree = api.write(doc, tmp_path / "tree.xml")
    machine = api.write(model, tmp_path / "tree.scxml")
    cert = tmp_path / "proof.json"
    assert main(["verify", str(tree), str(machine), "--certificate", str(cert)]) == 0
    capsys.readouterr()
    assert main(["check-certificate", str(tree), str(machine), str(cert)]) == 0
    out = capsys.readouterr().out
    assert "certificate valid: EQUIVALENT" in out and PER_NODE in out and PERNODE in out
