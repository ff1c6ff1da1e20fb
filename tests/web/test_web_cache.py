"""The answer cache (fsmbt.web.answers; docs/web.md, 'Cache'): keyed by the request's content,
bounded by bytes (LRU), optionally on disk, and used by the API so a repeated request is
answered without a worker."""

from __future__ import annotations

from fastapi.testclient import TestClient

from fsmbt.web import WebSettings, create_app
from fsmbt.web.answers import AnswerCache, request_key
from support.web_server import REPO

PAPER = (REPO / "examples" / "paper_fsm.xml").read_text(encoding="utf-8")


def test_the_key_is_the_content_and_every_option_counts():
    body = {"text": PAPER, "engine": "rules", "options": {"loop": False, "style": "auto"}}
    same = {"options": {"style": "auto", "loop": False}, "engine": "rules", "text": PAPER}
    assert request_key("convert", body) == request_key("convert", same)
    for changed in (
        {**body, "text": PAPER + " "},
        {**body, "engine": "bsd"},
        {**body, "options": {"loop": True, "style": "auto"}},
        {**body, "options": {"loop": False, "style": "lebt"}},
    ):
        assert request_key("convert", changed) != request_key("convert", body)
    assert request_key("verify", body) != request_key("convert", body)


def test_lru_by_bytes_and_only_clean_answers():
    cache = AnswerCache(max_bytes=4000)
    for index in range(10):
        cache.put(f"k{index}", ("ok", "x" * 600))
    assert cache.bytes <= 4000
    assert cache.get("k0") is None and cache.get("k9") == ("ok", "x" * 600)
    cache.put("big", ("ok", "y" * 3000))  # over a quarter of the bound: not kept
    assert cache.get("big") is None
    cache.put("crash", ("crash", "boom"))
    assert cache.get("crash") is None


def test_disk_entries_survive_a_new_cache(tmp_path):
    AnswerCache(max_bytes=10_000, directory=tmp_path).put("k", ("error", {"error": "e"}))
    assert AnswerCache(max_bytes=10_000, directory=tmp_path).get("k") == (
        "error",
        {"error": "e"},
    )
    assert not list(tmp_path.glob("*.part"))


def test_disk_entries_are_data_and_a_planted_file_runs_nothing(tmp_path):
    """Bytes (pictures, downloads) survive the disk as data; a pickle planted under an entry's
    name, or any file that is not an answer, is a miss and runs nothing."""
    answer = ("ok", (b"\x00\xffPNG", "tree.png", "image/png"))
    AnswerCache(max_bytes=10_000, directory=tmp_path).put("k", answer)
    status, (data, name, media) = AnswerCache(max_bytes=10_000, directory=tmp_path).get("k")
    assert (status, data, name, media) == answer[:1] + answer[1]
    assert b"PNG" not in (tmp_path / "k.json").read_bytes()  # base64, not raw bytes

    import pickle

    marker = tmp_path / "ran"

    class Plant:
        def __reduce__(self):
            return (marker.write_text, ("code ran",))

    for planted in (pickle.dumps(Plant()), b"[" * 100_000, b'["ok"]', b'{"$bytes": "@@"}'):
        (tmp_path / "p.json").write_bytes(planted)
        assert AnswerCache(max_bytes=10_000, directory=tmp_path).get("p") is None
    (tmp_path / "p.pickle").write_bytes(pickle.dumps(Plant()))
    assert AnswerCache(max_bytes=10_000, directory=tmp_path).get("p") is None
    assert not marker.exists()


def test_a_repeated_request_is_answered_from_the_cache():
    with TestClient(create_app(WebSettings.default(workers=1))) as client:
        cache = client.app.state.cache
        first = client.post("/api/convert", json={"text": PAPER})
        second = client.post("/api/convert", json={"text": PAPER})
        assert first.status_code == second.status_code == 200
        assert first.json() == second.json() and first.json()["verdict"] == "EQUIVALENT"
        assert (cache.hits, cache.misses) == (1, 1)
        looped = client.post("/api/convert", json={"text": PAPER, "options": {"loop": True}})
        assert looped.status_code == 200 and cache.misses == 2


def test_every_answer_carries_the_security_headers():
    from fsmbt.web.headers import SECURITY_HEADERS

    with TestClient(create_app(WebSettings.default(workers=1, max_body_bytes=2048))) as client:
        for answer in (
            client.get("/"),
            client.get("/api/formats"),
            client.post("/api/convert", json={"text": "x" * 4096}),  # the 413
        ):
            for name, value in SECURITY_HEADERS:
                assert answer.headers.get(name.decode()) == value.decode(), answer.status_code
