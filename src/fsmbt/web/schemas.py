"""The request bodies of the JSON API, for the OpenAPI page (``/docs``).

The routes read bodies by hand (the same fields come as JSON or as a multipart upload), so these
models document the fields; ``fsmbt.web.app`` checks the types of what arrives.
"""

from __future__ import annotations

from pydantic import BaseModel, Field


class ModelText(BaseModel):
    """One model as text."""

    text: str = Field(description="the model's text (multipart: the uploaded `file`)")
    filename: str | None = Field(default=None, description="a file name, for format detection only")
    format: str | None = Field(default=None, description="the format's name; detected when omitted")


class Options(BaseModel):
    """Conversion options."""

    loop: bool = Field(
        default=False, description="BT -> FSM: the root is ticked again after it returns"
    )
    hierarchy: str = Field(default="subtrees", description="FSM -> BT: `subtrees` or `flatten`")
    style: str = Field(
        default="auto",
        description="FSM -> BT: `auto` (structured for outcome-driven machines, else lebt), "
        "`structured` or `lebt`",
    )


class ConvertRequest(ModelText):
    """A conversion."""

    engine: str = Field(
        default="rules", description="rules, bsd, chds (LLM engines when configured)"
    )
    options: Options = Options()
    to: str | None = Field(default=None, description="the result's format (default: btcpp / scxml)")


class VerifyRequest(BaseModel):
    """Two models to compare, in either order."""

    first: ModelText
    second: ModelText
    options: Options = Options()


class ExportRequest(ModelText):
    """A model to download in another format."""

    to: str = Field(description="a format name from /api/formats (svg and png: pictures)")
    name: str | None = Field(default=None, description="the download's file name stem")
