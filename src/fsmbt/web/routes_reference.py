"""The page and the reference data it shows: formats, engines, examples (docs/web.md)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from fastapi import APIRouter, Request
from fastapi.responses import HTMLResponse, Response
from fastapi.templating import Jinja2Templates

from fsmbt.formats import detect_format
from fsmbt.model.errors import FsmbtError
from fsmbt.web import service
from fsmbt.web.errors import ApiError
from fsmbt.web.settings import WebSettings

HERE = Path(__file__).parent
#: Files in the examples folder that are not models.
NOT_EXAMPLES = ("README.md",)
TEMPLATES = Jinja2Templates(directory=str(HERE / "templates"))

router = APIRouter()


@router.get("/", response_class=HTMLResponse, include_in_schema=False)
async def page(request: Request) -> Response:
    settings: WebSettings = request.app.state.settings
    return TEMPLATES.TemplateResponse(
        request, "index.html", {"reports": settings.reports_dir is not None}
    )


@router.get("/api/formats", summary="Every format fsmbt reads or writes")
async def get_formats() -> list[dict[str, Any]]:
    return service.format_list()


@router.get("/api/engines", summary="The conversion engines this server offers")
async def get_engines() -> dict[str, Any]:
    return {
        "engines": list(service.PLAIN_ENGINES) + llm_engines(),
        "hierarchies": list(service.HIERARCHIES),
        "styles": list(service.STYLES),
        "runtimes": service.runtime_kinds(),
    }


@router.get("/api/examples", summary="The example models (by name)")
async def get_examples(request: Request) -> list[dict[str, str]]:
    listing = _examples(request.app.state.settings)
    return [{"name": name, "format": fmt} for name, fmt in listing.items()]


@router.get("/api/examples/{name}", summary="One example model's text")
async def get_example(request: Request, name: str) -> dict[str, str]:
    settings: WebSettings = request.app.state.settings
    listing = _examples(settings)
    if name not in listing or settings.examples_dir is None:
        raise ApiError(404, f"no example named '{name}'", "name")
    text = (settings.examples_dir / name).read_text(encoding="utf-8")
    return {"name": name, "format": listing[name], "text": text}


def llm_engines() -> list[str]:
    """The LLM engines, offered only when the server's environment configures an endpoint."""
    from fsmbt.api import LLM_ENGINES
    from fsmbt.llm.config import resolve_settings

    try:
        resolve_settings()
    except FsmbtError:
        return []
    return list(LLM_ENGINES)


def _examples(settings: WebSettings) -> dict[str, str]:
    folder = settings.examples_dir
    if folder is None or not folder.is_dir():
        return {}
    found: dict[str, str] = {}
    for path in sorted(folder.iterdir()):
        if not path.is_file() or path.name in NOT_EXAMPLES or path.stat().st_size > 1_000_000:
            continue
        try:
            text = path.read_text(encoding="utf-8")
            found[path.name] = detect_format(text, path).name
        except (FsmbtError, UnicodeDecodeError, OSError):
            continue
    return found
