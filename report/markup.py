"""Small HTML builders shared by the report's sections and page: escaping, inline pictures, numbers with
units, tables, notices, tiles and verdict badges. Strings in, HTML strings out.
"""
from __future__ import annotations

import base64
import html
import math
from typing import Any

from swiftfin.report.assets import VERDICT_CLASS


def esc(x: Any) -> str:
    return html.escape(str(x), quote=True)


def data_uri(png: bytes) -> str:
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


def img(png: bytes, alt: str, cls: str = "") -> str:
    c = f' class="{cls}"' if cls else ""
    return f'<img{c} src="{data_uri(png)}" alt="{esc(alt)}">'


def num(v, fmt: str = ".4g", unit: str = "") -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "&ndash;"
    s = format(v, fmt)
    return f"{s}&nbsp;{esc(unit)}" if unit and unit != "-" else s


def table(headers: list[str], rows: list[list[str]], cls: str = "", row_classes: list[str] | None = None,
          numeric: set[int] | None = None) -> str:
    """An HTML table; cells are HTML already (escape text before)."""
    numeric = numeric or set()
    th = "".join(f'<th{" class=num" if i in numeric else ""}>{h}</th>' for i, h in enumerate(headers))
    body = []
    for k, r in enumerate(rows):
        rc = f' class="{row_classes[k]}"' if row_classes and row_classes[k] else ""
        tds = "".join(f'<td{" class=num" if i in numeric else ""}>{c}</td>' for i, c in enumerate(r))
        body.append(f"<tr{rc}>{tds}</tr>")
    return f'<div class="tablewrap"><table class="{cls}"><thead><tr>{th}</tr></thead><tbody>{"".join(body)}</tbody></table></div>'


def notice(text: str, kind: str = "missing") -> str:
    return f'<p class="notice {kind}">{text}</p>'


def tile(label: str, value: str, sub: str = "", kind: str = "") -> str:
    return (f'<div class="tile {kind}"><div class="tlabel">{esc(label)}</div><div class="tvalue">{value}</div>'
            f'<div class="tsub">{sub}</div></div>')


def badge(name: str) -> str:
    cls = VERDICT_CLASS.get(name, "na")
    text = {"NOT_EVALUATED": "not evaluated"}.get(name, name.lower())
    return f'<span class="badge {cls}">{esc(text)}</span>'

