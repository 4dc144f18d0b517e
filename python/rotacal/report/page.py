# SPDX-License-Identifier: BSD-3-Clause
"""The page of a report: self-contained HTML (figures as PNG data URIs, no network needed to
open it), every text from a file escaped, written by the output rule."""

from __future__ import annotations

import base64
import datetime as _dt
import html
import io
from pathlib import Path
from typing import Any, Iterable

import matplotlib

matplotlib.use("Agg")  # files only, never a window
import matplotlib.pyplot as plt  # noqa: E402

from ..version import __version__  # noqa: E402

CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;margin:2em auto;max-width:1100px;color:#222}
h1{font-size:1.6em;border-bottom:2px solid #246;padding-bottom:.3em}
h2{font-size:1.25em;color:#246;margin-top:1.6em}
table{border-collapse:collapse;margin:.6em 0}
td,th{border:1px solid #bbb;padding:.25em .6em;text-align:right}
th{background:#eef2f7} td.l,th.l{text-align:left}
.muted{color:#777}.warn{color:#a40}.ok{color:#270}
figure{display:inline-block;margin:.5em;text-align:center}
figcaption{font-size:.85em;color:#555}
"""


def escape(text: Any) -> str:
    """HTML-escaped text: everything that may come from a file (labels, names, notes)."""
    return html.escape(str(text), quote=True)


def plot_text(text: Any, limit: int = 60) -> str:
    """A label from a file as matplotlib text: cut to ``limit`` characters, and '$' escaped so
    that it is never read as mathtext (an unbalanced '$' would stop the report)."""
    t = str(text)
    t = t if len(t) <= limit else t[: limit - 1] + "\u2026"
    return t.replace("$", r"\$")


def png(fig) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90, bbox_inches="tight")
    plt.close(fig)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def img(src: str, caption: str, section: str) -> str:
    return (
        f'<figure data-section="{escape(section)}"><img src="{src}" alt="{escape(caption)}">'
        f"<figcaption>{escape(caption)}</figcaption></figure>"
    )


def head(title: str, heading: str, source: str) -> list[str]:
    """The start of a page: title, style, heading, and the line naming rotacal's version, the
    time and the source."""
    return [
        f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{escape(title)}</title>"
        f"<style>{CSS}</style></head><body>",
        f"<h1>{escape(heading)}</h1>",
        f"<p class=muted>rotacal {escape(__version__)} &middot; "
        f"{_dt.datetime.now().strftime('%Y-%m-%d %H:%M')} &middot; {escape(source)}</p>",
    ]


# Records on load how many figures decoded, so a browser test can check they render.
_IMAGE_CHECK = (
    "<script>window.addEventListener('load',function(){var im=document.images,ok=0;"
    "for(var i=0;i<im.length;i++){if(im[i].complete&&im[i].naturalWidth>0)ok++;}"
    "document.body.setAttribute('data-images',im.length);"
    "document.body.setAttribute('data-images-rendered',ok);});</script>"
)


def write_page(path: Path, parts: list[str], inputs: Iterable[str] = ()) -> Path:
    """Close the page (with the image check) and write it by the output rule."""
    from ..outputs import write_output

    parts = parts + [_IMAGE_CHECK, "</body></html>"]
    write_output(path, "\n".join(parts), [str(i) for i in inputs])
    return path
