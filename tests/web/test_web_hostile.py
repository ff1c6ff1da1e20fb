"""Hostile requests: each is a clean 4xx (408 / 422 for the wall / CPU limits) with a one-line cause, and
the server keeps answering afterwards."""

from __future__ import annotations

import json

import pytest
from fastapi.testclient import TestClient

from fsmbt.web import WebSettings, create_app
from support.web_server import REPO

PAPER = (REPO / "examples" / "paper_fsm.xml").read_text(encoding="utf-8")
BOMB = """<?xml version="1.0"?>
<!DOCTYPE lolz [<!ENTITY lol "lol"><!ENTITY lol2 "&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;">
<!ENTITY lol3 "&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;">]>
<root BTCPP_format="4"><BehaviorTree ID="M"><Action name="&lol3;"/></BehaviorTree></root>
"""


@pytest.fixture(scope="module")
def client():
    with TestClient(
        create_app(WebSettings.default(workers=1, max_body_bytes=64 * 1024, timeout_s=20))
    ) as test_client:
        yield test_client


def _refused(answer, status: int, *words: str) -> None:
    assert answer.status_code == status, answer.text
    body = answer.json()
    assert set(body) == {"error", "where"}
    assert "\n" not in body["error"] and "Traceback" not in body["error"]
    for word in words:
        assert word in body["error"], body


def test_oversize_body_declared_or_streamed(client):
    _refused(client.post("/api/convert", json={"text": "x" * 100_000}), 413, "larger than")

    def chunks():
        for _ in range(40):
            yield b"a" * 4096

    _refused(
        client.post("/api/convert", content=chunks(), headers={"content-type": "application/json"}),
        413,
        "larger than",
    )


def test_xml_bomb(client):
    _refused(client.post("/api/convert", json={"text": BOMB}), 400, "entities")


def test_deep_nesting_in_the_model_and_in_the_body(client):
    deep_xml = (
        '<root BTCPP_format="4"><BehaviorTree ID="M">'
        + "<Inverter>" * 12_000
        + '<Action ID="a"/>'
        + "</Inverter>" * 12_000
        + "</BehaviorTree></root>"
    )
    settings = WebSettings.default(workers=1, max_body_bytes=4 * 1024 * 1024)
    with TestClient(create_app(settings)) as big:
        _refused(big.post("/api/convert", json={"text": deep_xml}), 400, "deep")
    deep_json = "[" * 30_000 + "]" * 30_000
    _refused(
        client.post(
            "/api/convert", content=deep_json, headers={"content-type": "application/json"}
        ),
        400,
        "nested too deeply",
    )


def test_wrong_content_type(client):
    _refused(
        client.post("/api/convert", content=PAPER, headers={"content-type": "application/xml"}),
        415,
        "content type",
    )
    _refused(client.post("/api/verify", content=b"x", headers={"content-type": "text/plain"}), 415)


def test_path_like_names(client):
    _refused(
        client.post("/api/convert", json={"text": PAPER, "filename": "../../etc/passwd"}),
        400,
        "not a path",
    )
    _refused(client.post("/api/convert", files={"file": ("/etc/passwd", PAPER)}), 400)
    _refused(client.get("/api/examples/..%2Fpyproject.toml"), 404)
    _refused(client.get("/api/examples/%2Fetc%2Fpasswd"), 404)
    _refused(client.get("/reports/x"), 404, "--reports")


def test_bad_fields(client):
    _refused(client.post("/api/convert", json={"text": 5}), 400, "must be a string")
    _refused(client.post("/api/convert", json=[1]), 400, "object")
    _refused(
        client.post(
            "/api/convert", content=b"{not json", headers={"content-type": "application/json"}
        ),
        400,
        "not valid JSON",
    )
    _refused(client.post("/api/convert", json={"text": ""}), 400, "empty")
    _refused(client.post("/api/convert", json={"text": PAPER, "format": "nope"}), 400)
    _refused(
        client.post("/api/convert", json={"text": PAPER, "engine": "rm -rf"}), 400, "not offered"
    )
    _refused(
        client.post("/api/convert", files={"file": ("x.xml", b"\xff\xfe\x00bad")}), 400, "UTF-8"
    )
    _refused(client.post("/api/verify", json={"first": {"text": PAPER}}), 400, "two models")


@pytest.fixture(scope="module")
def big_model() -> str:
    from fsmbt.formats import dumps
    from fsmbt.generate.generator import random_fsm

    # 20 000 states: about 12 s to read, convert and verify on the 2-core CI machine, 4x the
    # limit, so a faster machine still hits it (3 000 states took 0.6 s: rendering decided)
    return dumps(random_fsm(seed="web-timeout", n_states=20_000, max_states=20_000), "scxml")


def test_time_limit_answers_408_naming_it_and_frees_the_worker(big_model):
    settings = WebSettings.default(
        workers=1, timeout_s=3, cpu_limit_s=600, max_body_bytes=8 * 1024 * 1024
    )
    with TestClient(create_app(settings)) as slow:
        _refused(
            slow.post("/api/convert", json={"text": big_model}),
            408,
            "wall-time limit of 3 s",
            "command line",
        )
        # the stuck worker was replaced: the next request is served within the limit
        answer = slow.post("/api/convert", json={"text": PAPER})
        assert answer.status_code == 200 and answer.json()["verdict"] == "EQUIVALENT"


def test_cpu_limit_answers_422_naming_it_and_the_worker_serves_on(big_model):
    settings = WebSettings.default(
        workers=1, timeout_s=120, cpu_limit_s=1, max_body_bytes=8 * 1024 * 1024
    )
    with TestClient(create_app(settings)) as slow:
        _refused(slow.post("/api/convert", json={"text": big_model}), 422, "CPU-time limit of 1 s")
        answer = slow.post("/api/convert", json={"text": PAPER})
        assert answer.status_code == 200 and answer.json()["verdict"] == "EQUIVALENT"


def test_server_still_answers_after_the_hostile_ones(client):
    assert client.post("/api/convert", json={"text": PAPER}).json()["verdict"] == "EQUIVALENT"


def test_names_from_the_model_cannot_inject_markup_into_the_page(client):
    hostile = '<img src=x onerror="alert(1)">'
    text = (REPO / "examples" / "paper_fsm.json").read_text(encoding="utf-8")
    text = text.replace('"B"', json.dumps(hostile))
    answer = client.post("/api/convert", json={"text": text})
    assert answer.status_code == 200, answer.text
    data = answer.json()
    assert data["verdict"] == "EQUIVALENT"
    for picture in data["svg"].values():
        assert "<img" not in picture and "&lt;img" in picture
