"""The request bodies of the JSON API: their validation and their OpenAPI text (``/docs``).

The routes read a body as JSON or as a multipart upload (``fsmbt.web.bodies``) and parse it into
one of these models, which *are* the validation: a field of the wrong type is a 400 naming it.
The pipeline options then become the library's typed request (``fsmbt.api_types``) in
``fsmbt.web.service``, so the web page converts with the same options, checked the same way,
as the command line.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field


class ModelText(BaseModel):
    """One model as text."""

    model_config = ConfigDict(extra="ignore")

    text: str = Field(description="the model's text (multipart: the uploaded `file`)")
    filename: str | None = Field(default=None, description="a file name, for format detection only")
    format: str | None = Field(default=None, description="the format's name; detected when omitted")


class Options(BaseModel):
    """Conversion options."""

    model_config = ConfigDict(extra="ignore")

    loop: bool = Field(
        default=False, description="BT -> FSM: the root is ticked again after it returns"
    )
    hierarchy: str = Field(default="subtrees", description="FSM -> BT: `subtrees` or `flatten`")
    style: str = Field(
        default="auto",
        description="FSM -> BT: `auto` (structured for outcome-driven machines, else dispatch), "
        "`structured`, `dispatch` or `lebt`",
    )


class ConvertBody(ModelText):
    """A conversion."""

    engine: str = Field(
        default="rules", description="rules, bsd, chds (LLM engines when configured)"
    )
    options: Options = Options()
    to: str | None = Field(default=None, description="the result's format (default: btcpp / scxml)")


class VerifyBody(BaseModel):
    """Two models to compare, in either order."""

    model_config = ConfigDict(extra="ignore")

    first: ModelText
    second: ModelText
    options: Options = Options()


class PictureBody(ModelText):
    """One model's picture with a fold opened (the page's click on a fold box)."""

    focus: str | None = Field(
        default=None,
        description="BT: draw the subtree under this node, a child-index path from the main "
        "root with SubTrees expanded (`0/2/1`, `root`): what a `fold@PATH` box opens",
    )
    composite: str | None = Field(
        default=None,
        description="FSM: draw this composite state alone (`A/B`): what a closed "
        "composite's box (class `fold`, id `s@A/B`) opens",
    )


class ExportBody(ModelText):
    """A model to download in another format."""

    to: str = Field(description="a format name from /api/formats (svg and png: pictures)")
    name: str | None = Field(default=None, description="the download's file name stem")
