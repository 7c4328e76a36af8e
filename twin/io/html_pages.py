"""HTML pages from jinja2 templates shipped as package data (`twin/io/templates/`).

Pages are self-contained: images arrive as base64 PNG strings and are embedded as data
URIs by the templates, so a report can be mailed or archived as one file.
"""

from __future__ import annotations

import base64
from typing import Any


def png_data_uri(png: bytes) -> str:
    """A PNG as a `data:` URI for an <img src=...> (the page stays one file)."""
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


def render_page(template: str, **context: Any) -> str:
    """Render `templates/<template>` with autoescaping (values are text, not markup)."""
    import jinja2

    env = jinja2.Environment(
        loader=jinja2.PackageLoader("twin.io", "templates"),
        autoescape=True,
        undefined=jinja2.StrictUndefined,
        keep_trailing_newline=True,
        trim_blocks=True,
        lstrip_blocks=True,
    )
    return env.get_template(template).render(**context)
