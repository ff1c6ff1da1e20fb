"""Certificates of compositional proofs (docs/verification.md §6, "Certificates"): one unit per
region and one for the skeleton, re-checked without the search on machines rebuilt from the two
files; an edited unit, relation, pairing or decomposition, a certificate for other files and one
patched onto a mutant are refused (``fsmbt.verify.certificate``, docs/semantics.md §4c)."""

from __future__ import annotations

import copy
import json
import random

import pytest

from fsmbt import api
from fsmbt.cli import main
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.convert.lebt import fsm_to_lebt
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM
from fsmbt.verify import certificate, verify
from fsmbt.verify.mutations import mutants
from fsmbt.verify.report import COMPOSITIONAL
from support.random_trees import random_tree
from support.sampling import seed
from support.ver_models import act, cond, ctrl, paper_fsm
from support.whole_mutants import DECORATORS


def memory_tree() -> BTDocument:
    """Four regions with memory under plain controls (three SequenceWithMemory, one reactive)."""
    return BTDocument.single(
        ctrl(
            "Sequence",
            ctrl(
                "Fallback",
                ctrl("SequenceWithMemory", act("a1"), act("a2"), act("a3")),
                cond("c1"),
            ),
            ctrl("SequenceWithMemory", act("b1"), cond("c2")),
            ctrl("Fallback", cond("c3"), ctrl("SequenceWithMemory", act("d1"), act("d2"))),
            ctrl("Sequence", cond("c4"), ctrl("ReactiveSequence", cond("c5"), act("e1"))),
        )
    )


@pytest.fixture()
def files(tmp_path):
    doc = memory_tree()
    tree = api.write(doc, tmp_path / "tree.xml")
    machine = api.write(bt_to_hfsm(doc).model, tmp_path / "tree.scxml")
    cert = tmp_path / "proof.json"
    assert main(["verify", str(tree), str(machine), "--certificate", str(cert)]) == 0
    return {"tree": str(tree), "machine": str(machine), "cert": str(cert)}


def _edit(path: str, change) -> None:
    with open(path, encoding="utf-8") as stream:
        data = json.load(stream)
    change(data)
    with open(path, "w", encoding="utf-8") as stream:
        json.dump(data, stream)


def _check(files, capsys) -> tuple[int, str]:
    capsys.readouterr()
    code = main(["check-certificate", files["tree"], files["machine"], files["cert"]])
    captured = capsys.readouterr()
    return code, captured.out + captured.err


def test_a_compositional_proof_gets_a_certificate_per_unit(files, capsys):
    data = json.loads(open(files["cert"], encoding="utf-8").read())
    assert data["method"] == COMPOSITIONAL
    kinds = [unit["kind"] for unit in data["units"]]
    assert kinds == ["region"] * 4 + ["skeleton"]
    assert len(data["decomposition"]["tree_regions"]) == 4
    pairs = {(u["tree_region"], u["fsm_region"]) for u in data["units"][:-1]}
    assert len({k for k, _j in pairs}) == len({j for _k, j in pairs}) == 4
    code, out = _check(files, capsys)
    assert code == 0, out
    assert "certificate valid: EQUIVALENT" in out and "4 region, 1 skeleton" in out


def _swap_pairing(data) -> None:
    first, second = data["units"][0], data["units"][1]
    first["fsm_region"], second["fsm_region"] = second["fsm_region"], first["fsm_region"]


def _pair_twice(data) -> None:
    data["units"][1]["fsm_region"] = data["units"][0]["fsm_region"]


def _swap_units(data) -> None:
    """The two regions' tables exchanged, each unit keeping its pair."""
    first, second = data["units"][0], data["units"][1]
    for key in ("outputs", "machines", "relation"):
        first[key], second[key] = second[key], first[key]


@pytest.mark.parametrize(
    "tamper",
    [
        lambda d: d["units"][0]["machines"]["result"]["edges"][0][0].__setitem__(1, 0),
        lambda d: d["units"][2]["machines"]["source"]["states"][1].__setitem__(1, "final"),
        lambda d: d["units"][1]["relation"].pop(),
        lambda d: d["units"][-1]["relation"].pop(),
        lambda d: d["units"][-1]["machines"]["source"]["edges"][0][0].__setitem__(2, 0),
        _swap_pairing,
        _pair_twice,
        _swap_units,
        lambda d: d["units"].pop(0),  # a region left unproved: its labels differ
        lambda d: d["units"].pop(),  # no skeleton
        lambda d: d["decomposition"]["tree_regions"].reverse(),
        lambda d: d["decomposition"]["fsm_regions"].pop(),
        lambda d: d.__setitem__("method", "canonical"),
        lambda d: d.__setitem__("loop", True),
        lambda d: d["units"][0].__setitem__("kind", "product"),
    ],
    ids=[
        "region-edge",
        "region-status",
        "region-relation",
        "skeleton-relation",
        "skeleton-outputs",
        "pairing-swapped",
        "pairing-twice",
        "units-swapped",
        "region-dropped",
        "skeleton-dropped",
        "tree-regions",
        "fsm-regions",
        "method",
        "loop",
        "unit-kind",
    ],
)
def test_an_edited_compositional_certificate_is_refused(files, capsys, tamper):
    _edit(files["cert"], tamper)
    code, out = _check(files, capsys)
    assert code == 1, out
    assert "certificate REFUSED" in out


def test_a_compositional_certificate_for_other_files_is_refused(files, tmp_path, capsys):
    other = copy.deepcopy(memory_tree())
    assert other.main.root is not None
    other.main.root.children.pop()  # one region fewer
    other_tree = api.write(other, tmp_path / "other.xml")
    capsys.readouterr()
    code = main(["check-certificate", str(other_tree), files["machine"], files["cert"]])
    assert code == 1
    assert "other files" in capsys.readouterr().err


def _deep_mutants(hfsm: FSM, rng: random.Random) -> list[FSM]:
    """One mutant per operator of each machine of ``hfsm`` (the top machine and every region's
    sub-machine), as whole HFSMs."""
    out: list[FSM] = []
    for index, inner in enumerate(list(hfsm.machines())):
        for mutant in mutants(inner, seed=rng.randrange(1 << 30), per_operator=1):
            assert isinstance(mutant.model, FSM)
            whole = copy.deepcopy(hfsm)
            target = list(whole.machines())[index]
            target.states, target.transitions = mutant.model.states, mutant.model.transitions
            target.initial = mutant.model.initial
            out.append(whole)
    return out


def test_a_certificate_patched_onto_a_mutant_is_refused():
    """The digests are made to match (the check is given the mutant with the certificate's own
    digests): every mutant the whole product tells apart, in a region or in the skeleton, is
    refused by the replay or by the re-derived decomposition."""
    doc = memory_tree()
    hfsm = bt_to_hfsm(doc).model
    with certificate.collecting() as sink:
        report = verify(doc, hfsm)
    assert report.method == COMPOSITIONAL
    data = json.loads(
        json.dumps(certificate.build(sink, report, source_digest="s", result_digest="r"))
    )
    assert certificate.check(data, doc, hfsm, source_digest="s", result_digest="r").equivalent
    refused = 0
    for mutant in _deep_mutants(hfsm, random.Random(seed())):
        try:
            if verify(doc, mutant).equivalent:
                continue
        except InputError:  # not a valid machine (e.g. an eventless cycle)
            continue
        with pytest.raises(certificate.CertificateError):
            certificate.check(data, doc, mutant, source_digest="s", result_digest="r")
        refused += 1
    assert refused >= 10


def test_a_certificate_of_the_first_format_still_checks(tmp_path):
    """``fsmbt-certificate/1`` (one whole-product proof at the top level) is read as one
    ``product`` unit."""
    source = paper_fsm()
    lebt = fsm_to_lebt(source).model
    with certificate.collecting() as sink:
        report = verify(source, lebt)
    data = certificate.build(sink, report, source_digest="s", result_digest="r")
    (unit,) = data.pop("units")
    unit.pop("kind")
    data.update(unit, format=certificate.FORMAT_1)
    path = tmp_path / "old.json"
    path.write_text(json.dumps(data))
    loaded = certificate.load(path)
    assert certificate.check(loaded, source, lebt, source_digest="s", result_digest="r").pairs
    loaded["units"][0]["relation"].pop()
    with pytest.raises(certificate.CertificateError):
        certificate.check(loaded, source, lebt, source_digest="s", result_digest="r")


#: Controls of the compositional family: plain ones (the skeleton) and ones with memory.
CONTROLS = (
    "Sequence",
    "Fallback",
    "Sequence",
    "Fallback",
    "SequenceWithMemory",
    "ReactiveSequence",
)


def test_random_compositional_certificates_check_and_tree_mutants_are_refused():
    """A seeded sample of random trees with memory under plain controls: every compositional
    proof's certificate checks (through JSON), and offered for a mutant of the *tree* that
    the whole product tells apart (the mutants are valid trees: ``mutations`` keeps each kind's
    arity), it is refused."""
    rng = random.Random(f"{seed()}:certificate-units")
    proved = refused = 0
    for _ in range(250):
        doc = random_tree(rng, controls=CONTROLS, decorators=DECORATORS, max_nodes=16)
        try:
            hfsm = bt_to_hfsm(doc).model
        except InputError:
            continue
        with certificate.collecting() as sink:
            report = verify(doc, hfsm)
        if report.method != COMPOSITIONAL:
            continue
        data = certificate.build(sink, report, source_digest="s", result_digest="r")
        data = json.loads(json.dumps(data))
        checked = certificate.check(data, doc, hfsm, source_digest="s", result_digest="r")
        assert checked.equivalent and checked.units["region"] >= 2
        proved += 1
        for mutant in mutants(doc, seed=rng.randrange(1 << 30), per_operator=1)[:3]:
            assert isinstance(mutant.model, BTDocument)
            try:
                if verify(mutant.model, hfsm).equivalent:
                    continue
            except InputError:
                continue
            with pytest.raises(certificate.CertificateError):
                certificate.check(data, mutant.model, hfsm, source_digest="s", result_digest="r")
            refused += 1
    print(f"{proved} compositional certificates checked, {refused} mutants refused")
    assert proved >= 15 and refused >= 15
