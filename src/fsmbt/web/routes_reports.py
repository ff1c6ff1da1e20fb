"""Read-only report browsing (with ``--reports DIR``): the evaluation reports and batch stores
found under the folder, their files, a batch store's tables. Paths are resolved inside the
folder and refused outside it; stores are opened read-only (docs/web.md)."""

from __future__ import annotations

import sqlite3
from pathlib import Path
from typing import Any

from fastapi import APIRouter, Request
from fastapi.responses import FileResponse, Response

from fsmbt.web.errors import ApiError
from fsmbt.web.settings import WebSettings

#: Most rows of one table shown from a batch store.
MAX_BATCH_ROWS = 500
#: How deep report browsing looks for report folders and batch stores.
MAX_REPORT_DEPTH = 4

router = APIRouter()


@router.get("/api/reports", summary="Evaluation reports and batch stores under --reports")
async def reports(request: Request) -> dict[str, list[str]]:
    root = _reports_root(request.app.state.settings)
    found: dict[str, list[str]] = {"reports": [], "batches": []}
    stack: list[tuple[Path, int]] = [(root, 0)]
    while stack:
        folder, depth = stack.pop()
        if (folder / "index.html").is_file():
            found["reports"].append(_relative(folder / "index.html", root))
        if (folder / "results.sqlite").is_file():
            found["batches"].append(_relative(folder / "results.sqlite", root))
        if depth < MAX_REPORT_DEPTH:
            stack.extend(
                (child, depth + 1)
                for child in sorted(folder.iterdir(), reverse=True)
                if child.is_dir() and not child.is_symlink()
            )
    return found


@router.get("/reports/{path:path}", include_in_schema=False)
async def report_file(request: Request, path: str) -> Response:
    return FileResponse(_inside(_reports_root(request.app.state.settings), path))


@router.get("/api/batch/{path:path}", summary="A batch store's tables (read-only)")
async def batch(request: Request, path: str) -> dict[str, Any]:
    target = _inside(_reports_root(request.app.state.settings), path)
    if target.name != "results.sqlite":
        raise ApiError(400, "not a batch store (results.sqlite)", path)
    return _read_store(target)


def _reports_root(settings: WebSettings) -> Path:
    if settings.reports_dir is None:
        raise ApiError(404, "report browsing is off (start the server with --reports DIR)")
    return settings.reports_dir.resolve()


def _inside(root: Path, path: str) -> Path:
    """``path`` resolved under ``root``; refused when it leaves it or is not a file."""
    if "\x00" in path or path.startswith(("/", "\\")):
        raise ApiError(400, "not a path inside the reports folder", path)
    target = (root / path).resolve()
    if not target.is_relative_to(root):
        raise ApiError(400, "not a path inside the reports folder", path)
    if not target.is_file():
        raise ApiError(404, "no such file in the reports folder", path)
    return target


def _relative(path: Path, root: Path) -> str:
    return path.relative_to(root).as_posix()


def _read_store(path: Path) -> dict[str, Any]:
    """Every table of a batch store, opened read-only (``mode=ro``), at most
    ``MAX_BATCH_ROWS`` rows each."""
    try:
        connection = sqlite3.connect(f"{path.as_uri()}?mode=ro", uri=True)
    except sqlite3.Error as exc:
        raise ApiError(400, f"cannot open the batch store: {exc}") from None
    try:
        names = [
            row[0]
            for row in connection.execute(
                "SELECT name FROM sqlite_master WHERE type='table' ORDER BY name"
            )
        ]
        tables = {}
        for name in names:
            cursor = connection.execute(
                f'SELECT * FROM "{name.replace(chr(34), "")}" LIMIT ?', (MAX_BATCH_ROWS,)
            )
            columns = [c[0] for c in cursor.description or ()]
            tables[name] = {
                "columns": columns,
                "rows": [[_cell(v) for v in row] for row in cursor.fetchall()],
            }
        return {"store": path.name, "tables": tables}
    except sqlite3.Error as exc:
        raise ApiError(400, f"cannot read the batch store: {exc}") from None
    finally:
        connection.close()


def _cell(value: Any) -> Any:
    return value if isinstance(value, (int, float, str)) or value is None else repr(value)[:200]
