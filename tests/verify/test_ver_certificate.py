"""Certificates (``--certificate``, ``fsmbt check-certificate``): a verdict re-checked without the
search, and a tampered or forged certificate refused (docs/verification.md, "Certificates")."""

from __future__ import annotations

import copy
import json
import random

import pytest

from fsmbt import api
from fsmbt.cli import main
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.convert.lebt import fsm_to_lebt
from fsmbt.model.errors import InputError
from fsmbt.verify import certificate, verify
from fsmbt.verify.report import METHODS
from support.random_trees import random_tree
from support.ver_models import PAPER_EDGES, paper_fsm


@pytest.fixture()
def files(tmp_path):
    source = paper_fsm()
    mutated = copy.deepcopy(source)
    mutated.transitions[PAPER_EDGES.index("BC")].target = "D"
    paths = {
        "source": api.write(source, tmp_path / "source.json"),
        "mutated": api.write(mutated, tmp_path / "mutated.json"),
        "lebt": api.write(fsm_to_lebt(source).model, tmp_path / "lebt.json"),
    }
    return {k: str(v) for k, v in paths.items()}


def _edit(path, change) -> None:
    data = json.loads(open(path, encoding="utf-8").read())
    change(data)
    with open(path, "w", encoding="utf-8") as stream:
        json.dump(data, stream)


def _unit(data, index=0):
    return data["units"][index]


def test_verify_writes_a_certificate_that_checks(files, tmp_path, capsys):
    cert = tmp_path / "c.json"
    assert main(["verify", files["source"], files["lebt"], "--certificate", str(cert)]) == 0
    out = capsys.readouterr().out
    assert "proven by: whole product" in out
    data = json.loads(cert.read_text())
    assert data["equivalent"] is True and [u["kind"] for u in data["units"]] == ["product"]
    assert _unit(data)["relation"]
    assert main(["check-certificate", files["source"], files["lebt"], str(cert)]) == 0
    out = capsys.readouterr().out
    assert "certificate valid: EQUIVALENT" in out and "no search" in out


def test_arguments_in_either_order(files, tmp_path):
    cert = tmp_path / "c.json"
    assert main(["verify", files["lebt"], files["source"], "--certificate", str(cert)]) == 0
    assert main(["check-certificate", files["lebt"], files["source"], str(cert)]) == 0


@pytest.mark.parametrize(
    "tamper",
    [
        lambda d: _unit(d)["machines"]["result"]["edges"][1][0].__setitem__(1, 0),  # edge target
        lambda d: _unit(d)["machines"]["source"]["edges"][1][0].__setitem__(2, 0),  # outputs
        lambda d: _unit(d)["relation"].pop(),  # relation no longer closed
        lambda d: _unit(d)["machines"]["source"]["states"][2].__setitem__(1, "final"),  # status
        lambda d: _unit(d)["machines"]["result"]["edges"][2].pop(),  # an input left out
        lambda d: d.__setitem__("method", "symbolic"),  # a method the pair was not proven by
        lambda d: d.__setitem__("method", "compositional"),  # parts it does not have
        lambda d: _unit(d).__setitem__("kind", "skeleton"),  # a unit kind of another method
    ],
    ids=[
        "edge-target",
        "edge-outputs",
        "relation",
        "status",
        "missing-edge",
        "method",
        "method-compositional",
        "unit-kind",
    ],
)
def test_a_tampered_certificate_is_refused(files, tmp_path, capsys, tamper):
    cert = tmp_path / "c.json"
    assert main(["verify", files["source"], files["lebt"], "--certificate", str(cert)]) == 0
    _edit(cert, tamper)
    capsys.readouterr()
    assert main(["check-certificate", files["source"], files["lebt"], str(cert)]) == 1
    assert "certificate REFUSED" in capsys.readouterr().err


def test_a_certificate_for_other_files_is_refused(files, tmp_path, capsys):
    cert = tmp_path / "c.json"
    assert main(["verify", files["source"], files["lebt"], "--certificate", str(cert)]) == 0
    assert main(["check-certificate", files["mutated"], files["lebt"], str(cert)]) == 1
    assert "other files" in capsys.readouterr().err


def test_a_forged_certificate_for_a_non_equivalent_pair_is_refused(files, tmp_path, capsys):
    """The digests are made to match, the claimed tables are those of an equivalent pair: the
    replay of the real machines must catch it."""
    cert = tmp_path / "c.json"
    assert main(["verify", files["source"], files["lebt"], "--certificate", str(cert)]) == 0
    mutated_lebt = api.write(
        fsm_to_lebt(api.load(files["mutated"]).model).model, tmp_path / "mutated_lebt.json"
    )
    forged = certificate.digest(mutated_lebt.read_bytes())
    _edit(cert, lambda d: d["files"].__setitem__("result", forged))
    capsys.readouterr()
    assert main(["check-certificate", files["source"], str(mutated_lebt), str(cert)]) == 1
    assert "certificate REFUSED" in capsys.readouterr().err


def test_not_equivalent_certificate_replays_its_counterexample(files, tmp_path, capsys):
    cert = tmp_path / "c.json"
    assert main(["verify", files["source"], files["mutated"], "--certificate", str(cert)]) == 1
    assert main(["check-certificate", files["source"], files["mutated"], str(cert)]) == 0
    assert "NOT EQUIVALENT" in capsys.readouterr().out
    _edit(cert, lambda d: d.__setitem__("counterexamples", {"completeness": []}))
    assert main(["check-certificate", files["source"], files["mutated"], str(cert)]) == 1


def test_convert_writes_a_certificate(tmp_path, capsys):
    doc = random_tree(random.Random(5), max_nodes=12)
    source = api.write(doc, tmp_path / "tree.xml")
    out, cert = tmp_path / "tree.scxml", tmp_path / "c.json"
    assert main(["convert", str(source), "-o", str(out), "--certificate", str(cert)]) == 0
    assert "proven by:" in capsys.readouterr().out
    assert main(["check-certificate", str(source), str(out), str(cert)]) == 0


def test_random_trees_certificates_check_and_mutants_are_caught():
    """Seeded sample of random trees (every control and decorator the interpreter knows): each
    BT -> HFSM certificate checks; the same certificate offered for a mutated HFSM is refused."""
    from fsmbt.verify.mutations import mutants

    checked = refused = 0
    for seed in range(40):
        doc = random_tree(random.Random(seed), max_nodes=12)
        try:
            hfsm = bt_to_hfsm(doc).model
        except InputError:  # a tree the converter refuses (located error) is not this test's
            continue
        with certificate.collecting() as sink:
            report = verify(doc, hfsm)
        assert report.equivalent and report.method in METHODS
        data = certificate.build(sink, report, source_digest="s", result_digest="r")
        data = json.loads(json.dumps(data))
        certificate.check(data, doc, hfsm, source_digest="s", result_digest="r")
        checked += 1
        for mutant in list(mutants(hfsm))[:2]:
            try:
                if verify(doc, mutant.model).equivalent:
                    continue
            except InputError:  # a mutant that is not a valid machine (e.g. an eventless cycle)
                continue
            with pytest.raises(certificate.CertificateError):
                certificate.check(data, doc, mutant.model, source_digest="s", result_digest="r")
            refused += 1
    assert checked >= 20 and refused >= 10
