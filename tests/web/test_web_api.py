"""The JSON API in-process (FastAPI's TestClient; the workers are real processes): every answer's
shape, both body kinds, verification of a pair, exports read back, runtimes, report browsing."""

from __future__ import annotations

import json
import sqlite3

import pytest
from fastapi.testclient import TestClient

from fsmbt import api
from fsmbt.verify.mutations import mutants
from fsmbt.web import WebSettings, create_app
from support.web_server import REPO

PAPER = (REPO / "examples" / "paper_fsm.xml").read_text(encoding="utf-8")
ROBOT = (REPO / "examples" / "robot_bt.xml").read_text(encoding="utf-8")


@pytest.fixture(scope="module")
def reports_dir(tmp_path_factory):
    root = tmp_path_factory.mktemp("reports")
    (root / "eval").mkdir()
    (root / "eval" / "index.html").write_text("<h1>evaluation</h1>", encoding="utf-8")
    (root / "batch").mkdir()
    with sqlite3.connect(root / "batch" / "results.sqlite") as db:
        db.execute("CREATE TABLE results (input TEXT, verdict TEXT)")
        db.execute("INSERT INTO results VALUES ('a.xml', 'EQUIVALENT')")
    (root.parent / "secret.txt").write_text("outside", encoding="utf-8")
    return root


@pytest.fixture(scope="module")
def client(reports_dir):
    settings = WebSettings.default(workers=1, reports_dir=reports_dir)
    with TestClient(create_app(settings)) as test_client:
        yield test_client


def test_formats_and_engines(client):
    names = {f["name"] for f in client.get("/api/formats").json()}
    assert {"btcpp", "scxml", "json", "yaml", "mermaid", "dot", "svg", "png"} <= names
    engines = client.get("/api/engines").json()
    assert engines["engines"][:3] == ["rules", "bsd", "chds"]


def test_every_style_is_offered_and_applied(client):
    styles = client.get("/api/engines").json()["styles"]
    assert styles == ["auto", "structured", "dispatch", "lebt"]
    leaves = {"auto": "DispatchEntry", "dispatch": "DispatchEntry", "lebt": "LebtState"}
    for style, leaf in leaves.items():
        data = client.post("/api/convert", json={"text": PAPER, "options": {"style": style}})
        assert data.status_code == 200, data.text
        answer = data.json()
        assert answer["verdict"] == "EQUIVALENT" and answer["style"] == style.replace(
            "auto", "dispatch"
        )
        assert f"<{leaf}" in answer["result"]["text"]
        # v3 has no Script, and the LEBT runtimes do not run the dispatch form
        assert ("btcpp3" in answer["downloads"]) == (leaf == "LebtState")
        assert (answer["runtimes"] == []) == (leaf == "DispatchEntry")
    refused = client.post("/api/convert", json={"text": PAPER, "options": {"style": "structured"}})
    assert refused.status_code == 400 and "event-driven" in refused.text


def test_examples_are_listed_by_name_and_read_by_name(client):
    listing = {e["name"]: e["format"] for e in client.get("/api/examples").json()}
    assert listing["paper_fsm.xml"] == "paper-xml"
    assert "README.md" not in listing
    assert client.get("/api/examples/paper_fsm.xml").json()["text"] == PAPER


def test_convert_json_answer_has_every_part(client):
    answer = client.post("/api/convert", json={"text": PAPER, "filename": "paper_fsm.xml"})
    assert answer.status_code == 200
    data = answer.json()
    assert data["verdict"] == "EQUIVALENT" and data["direction"] == "fsm->bt"
    assert [p["name"] for p in data["properties"]] == [
        "reachability",
        "completeness",
        "no_additional_behavior",
        "deadlock_absence",
        "termination_consistency",
    ]
    assert data["counterexample"] is None
    result = api.load_text(data["result"]["text"], data["result"]["format"])
    assert api.verify_models(api.load_text(PAPER).model, result.model).equivalent
    assert data["svg"]["source"].startswith("<svg") and 'id="s@A"' in data["svg"]["source"]
    assert 'id="n@root"' in data["svg"]["result"]
    assert data["metrics"]["source"]["states"] == 10
    assert {"btcpp", "json", "yaml", "dot", "svg", "png"} <= set(data["downloads"])
    assert (
        data["loads"] == "loads in BehaviorTree.CPP 4.8.2: yes" or "ports stripped" in data["loads"]
    )


def test_convert_multipart_upload_with_options(client):
    answer = client.post(
        "/api/convert",
        files={"file": ("robot_bt.xml", ROBOT)},
        data={"engine": "rules", "loop": "true"},
    )
    assert answer.status_code == 200, answer.text
    data = answer.json()
    assert data["direction"] == "bt->fsm" and data["result"]["format"] == "scxml"
    assert data["verdict"] == "EQUIVALENT"
    assert data["runtimes"] == []  # an FSM result has no runtime files


def test_convert_with_each_plain_engine(client):
    for engine in ("bsd", "chds"):
        data = client.post("/api/convert", json={"text": PAPER, "engine": engine}).json()
        assert data["engine"] == engine and data["verdict"] == "EQUIVALENT", data


def test_llm_engine_is_refused_without_an_endpoint(client, monkeypatch):
    monkeypatch.delenv("FSMBT_LLM_BASE_URL", raising=False)
    answer = client.post("/api/convert", json={"text": PAPER, "engine": "llm"})
    assert answer.status_code == 400 and "not offered" in answer.json()["error"]


def test_verify_a_pair_gives_a_located_counterexample(client):
    source = api.load_text(PAPER)
    mutant = next(
        m for m in mutants(source.model, per_operator=1) if m.operator == "drop_transition"
    )
    data = client.post(
        "/api/verify",
        json={"first": {"text": PAPER}, "second": {"text": api.dumps(mutant.model, "scxml")}},
    ).json()
    assert data["verdict"] == "NOT EQUIVALENT"
    steps = data["counterexample"]["steps"]
    report = api.verify_either_order(source.model, mutant.model)
    failed = [p for p in report.properties.values() if not p.holds and p.counterexample]
    assert len(steps) == min(len(p.counterexample or []) for p in failed)
    for step in steps:
        expected = "start@" if step["source_state"] == "Start" else f"s@{step['source_state']}"
        assert step["source_anchors"][0] == expected


def test_export_every_download_reads_back(client):
    data = client.post("/api/convert", json={"text": PAPER}).json()
    for fmt in data["downloads"]:
        answer = client.post(
            "/api/export",
            json={
                "text": data["result"]["text"],
                "format": data["result"]["format"],
                "to": fmt,
                "name": "../../etc/paper",
            },
        )
        assert answer.status_code == 200, (fmt, answer.text)
        disposition = answer.headers["content-disposition"]
        assert "/" not in disposition.split("filename=")[1]
        if fmt == "png":
            assert answer.content.startswith(b"\x89PNG")
        elif fmt == "svg":
            assert answer.text.startswith("<svg")
        elif fmt == "dot":  # BT DOT is write-only (docs/formats/dot.md)
            assert answer.text.startswith("digraph")
        else:
            back = api.load_text(answer.text, fmt)
            assert back.kind == "bt"


def test_runtime_zip_when_the_runtime_is_installed(client):
    import zipfile
    from io import BytesIO

    kinds = client.get("/api/engines").json()["runtimes"]
    assert kinds, "fsmbt.runtime is part of this checkout"
    for kind in kinds:
        answer = client.get(f"/api/runtime/{kind}")
        assert answer.status_code == 200
        names = zipfile.ZipFile(BytesIO(answer.content)).namelist()
        assert names and all(not n.startswith("/") and ".." not in n for n in names)


def test_inspect_lists_validation_issues_with_locations(client):
    broken = PAPER.replace(
        '<Transition from="A" to="B" event="eventAB"/>',
        '<Transition from="A" to="Nowhere" event="eventAB"/>',
    )
    assert broken != PAPER
    answer = client.post("/api/inspect", json={"text": broken})
    body = answer.json()
    if answer.status_code == 200:
        assert any(i["severity"] == "error" for i in body["issues"]), body
    else:
        assert answer.status_code == 400 and "Nowhere" in body["error"]
        assert body["where"]["line"] is not None


def test_reports_are_browsed_read_only_inside_the_folder(client, reports_dir):
    listing = client.get("/api/reports").json()
    assert listing == {"reports": ["eval/index.html"], "batches": ["batch/results.sqlite"]}
    assert "evaluation" in client.get("/reports/eval/index.html").text
    store = client.get("/api/batch/batch/results.sqlite").json()
    assert store["tables"]["results"]["rows"] == [["a.xml", "EQUIVALENT"]]
    for path in ("../secret.txt", "..%2Fsecret.txt", "eval/../../secret.txt"):
        answer = client.get(f"/reports/{path}")
        assert answer.status_code in (400, 404), path
        assert "outside" not in answer.text
    assert (reports_dir / "batch" / "results.sqlite").stat().st_size > 0


def test_openapi_documents_the_api(client):
    paths = client.get("/openapi.json").json()["paths"]
    assert {"/api/formats", "/api/convert", "/api/verify", "/api/export"} <= set(paths)
    body = paths["/api/convert"]["post"]["requestBody"]["content"]
    assert {"application/json", "multipart/form-data"} <= set(body)
    assert json.dumps(body).count("engine") >= 1


def test_llm_engines_are_offered_only_with_a_server_endpoint(client, monkeypatch, tmp_path):
    for name in (
        "FSMBT_LLM_BASE_URL",
        "FSMBT_LLM_MODEL",
        "FSMBT_LLM_API_KEY",
        "OPENAI_API_KEY",
        "FSMBT_LLM_CONFIG",
    ):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.chdir(tmp_path)  # no fsmbt.toml here
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path))
    assert "llm" not in client.get("/api/engines").json()["engines"]
    monkeypatch.setenv("FSMBT_LLM_BASE_URL", "http://127.0.0.1:9/v1")
    monkeypatch.setenv("FSMBT_LLM_MODEL", "some-model")
    monkeypatch.setenv("FSMBT_LLM_API_KEY", "none")
    assert {"llm", "nllm", "hybrid"} <= set(client.get("/api/engines").json()["engines"])


def test_verify_multipart_upload_of_two_files(client):
    converted = client.post("/api/convert", json={"text": PAPER}).json()["result"]["text"]
    answer = client.post(
        "/api/verify",
        files={"first": ("paper_bt.xml", converted), "second": ("paper_fsm.xml", PAPER)},
    )
    assert answer.status_code == 200, answer.text
    data = answer.json()
    assert data["verdict"] == "EQUIVALENT" and data["source_side"] == "second"
    assert data["counterexample"] is None


def test_errors_name_the_uploaded_file_and_the_line_as_the_cli_does(client, tmp_path):
    broken = PAPER.replace('<State name="C" type="normal"/>', '<State name="C" type="normal"')
    assert broken != PAPER
    path = tmp_path / "broken.xml"
    path.write_text(broken, encoding="utf-8")
    from fsmbt.cli.hints import cli_message
    from fsmbt.model.errors import InputError

    with pytest.raises(InputError) as caught:
        api.load(path)
    expected = cli_message(caught.value).replace(str(path), "broken.xml")
    answer = client.post("/api/convert", files={"file": ("broken.xml", broken)})
    assert answer.status_code == 400
    body = answer.json()
    assert body["error"] == expected
    assert body["where"]["file"] == "broken.xml"
    assert body["where"]["line"] == caught.value.location.line
