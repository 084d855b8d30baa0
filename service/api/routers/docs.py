"""The OpenAPI document and its Swagger UI page, served from this machine: the Swagger UI files
come from the `swagger-ui-py` package (its `static/` folder, mounted at /docs/assets), following
FastAPI's "self-hosting JavaScript and CSS for docs" recipe, so /docs works without a CDN or
a network. The routes are included like the other reads (with the token when reads need it)."""

from __future__ import annotations

from pathlib import Path

from fastapi import APIRouter, FastAPI, Request
from fastapi.openapi.docs import get_swagger_ui_html
from fastapi.responses import HTMLResponse, JSONResponse
from fastapi.staticfiles import StaticFiles

ASSETS = "/docs/assets"

read = APIRouter(include_in_schema=False)


def swagger_ui_dir() -> Path:
    """The Swagger UI distribution shipped by the swagger-ui-py package."""
    import swagger_ui

    return Path(swagger_ui.__file__).resolve().parent / "static"


def mount_assets(app: FastAPI) -> None:
    app.mount(ASSETS, StaticFiles(directory=swagger_ui_dir()), name="swagger-ui-assets")


@read.get("/openapi.json")
def openapi(request: Request) -> JSONResponse:
    return JSONResponse(request.app.openapi())


@read.get("/docs")
def docs(request: Request) -> HTMLResponse:
    return get_swagger_ui_html(
        openapi_url="/openapi.json",
        title=f"{request.app.title} - API",
        swagger_js_url=f"{ASSETS}/swagger-ui-bundle.js",
        swagger_css_url=f"{ASSETS}/swagger-ui.css",
        swagger_favicon_url=f"{ASSETS}/favicon-32x32.png",
    )
