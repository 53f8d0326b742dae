"""The report's words: Markdown templates in ``fleet/paper/templates/``, filled with values.

A template file holds one section. Its text up to the first marker line is the part
``body``; a line ``<!-- name -->`` starts the part ``name`` (a caption, a claim, a note
written only when a measurement calls for it). Parts are ``string.Template`` text:
``$name`` is replaced by a value, and a placeholder without a value is an error, never
left in the report. A note that is left out leaves an empty line; runs of empty lines
are closed up.
"""

from __future__ import annotations

import re
from functools import cache
from importlib import resources
from string import Template

_MARKER = re.compile(r"^<!-- ([a-z0-9_]+) -->$", re.M)
_BLANK_LINES = re.compile(r"\n{3,}")


@cache
def parts(section: str) -> dict[str, Template]:
    """The parts of template ``section`` (``templates/<section>.md``), by name."""
    text = resources.files("fleet.paper").joinpath("templates", f"{section}.md").read_text("utf-8")
    pieces = _MARKER.split(text)
    named = {"body": pieces[0], **dict(zip(pieces[1::2], pieces[2::2]))}
    return {name: Template(piece.strip()) for name, piece in named.items()}


class Prose:
    """The filled parts of one section's template."""

    def __init__(self, section: str):
        self.section = section
        self.parts = parts(section)

    def __call__(self, part: str = "body", **values) -> str:
        template = self.parts[part]
        try:
            text = template.substitute(values)
        except KeyError as err:
            raise KeyError(f"template {self.section}.md, part {part}: no value for {err}") from None
        return _BLANK_LINES.sub("\n\n", text)
