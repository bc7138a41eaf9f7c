"""``rockyade assess --report``'s page as text: a self-contained HTML page and its Markdown twin.

* :func:`render_html`: one file, readable without rockyade or a network: the style inline, each
  figure embedded as a ``data:`` URI, no script, no external font, style sheet or image (its
  Content-Security-Policy forbids any), printable on A4. Each number of a table carries the key
  and the value of ``assess.json`` it shows (``data-key``, ``data-value``: the value as Python's
  ``repr`` writes it, which reads back to the same float).
* :func:`render_markdown`: the same page in Markdown, the figures as PNG files beside it (relative
  links).
"""

from __future__ import annotations

import base64
import html
from collections.abc import Mapping

from rockyade.assess.report_model import Bullets, Cell, FigureRef, ReportPage, Table

#: The page's style: readable on screen and on paper, nothing loaded from elsewhere.
STYLE = """
body { font-family: "DejaVu Sans", "Liberation Sans", Arial, sans-serif; font-size: 10.5pt; line-height: 1.4;
       color: #1a1a1a; max-width: 62em; margin: 1.5em auto; padding: 0 1em; }
h1 { font-size: 1.5em; margin-bottom: 0.2em; }
h2 { font-size: 1.2em; border-bottom: 1px solid #999; padding-bottom: 0.15em; margin-top: 1.6em; }
p.verdict { font-size: 1.15em; font-weight: bold; padding: 0.4em 0.6em; border-left: 6px solid #b2182b;
            background: #fbeaea; }
p.verdict.verified { border-left-color: #1b7837; background: #e9f5ec; }
table { border-collapse: collapse; margin: 0.6em 0 1em 0; font-size: 0.92em; }
caption { text-align: left; font-weight: bold; padding-bottom: 0.3em; }
th, td { border: 1px solid #bbb; padding: 0.2em 0.45em; vertical-align: top; text-align: left; }
th { background: #eee; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
figure { margin: 0.8em 0 1.2em 0; page-break-inside: avoid; }
figure img { max-width: 100%; height: auto; border: 1px solid #ddd; }
figcaption { font-size: 0.9em; color: #333; }
nav ol { columns: 2; font-size: 0.92em; }
footer { margin-top: 2em; font-size: 0.85em; color: #555; }
@media print { body { max-width: none; margin: 0; font-size: 9.5pt; } nav { display: none; }
               h2 { page-break-after: avoid; } table { page-break-inside: avoid; } }
@page { size: A4; margin: 15mm; }
"""
#: What the page may load: nothing but its own data: images and inline style.
CSP = "default-src 'none'; img-src data:; style-src 'unsafe-inline'"


def _cell_html(cell: Cell, tag: str = "td") -> str:
    text = html.escape(cell.text)
    if cell.key:
        value = "" if cell.value is None else repr(cell.value)
        return f'<{tag} class="num" data-key="{html.escape(cell.key)}" data-value="{html.escape(value)}">{text}</{tag}>'
    return f"<{tag}>{text}</{tag}>"


def _table_html(table: Table) -> str:
    head = "".join(f"<th>{html.escape(h)}</th>" for h in table.header)
    body = "\n".join("<tr>" + "".join(_cell_html(c) for c in row) + "</tr>" for row in table.rows)
    return (
        f'<table id="{html.escape(table.ident)}">\n<caption>{html.escape(table.caption)}</caption>\n'
        f"<thead><tr>{head}</tr></thead>\n<tbody>\n{body}\n</tbody>\n</table>"
    )


def render_html(page: ReportPage, images: Mapping[str, bytes]) -> str:
    """The page as one self-contained HTML file (module docstring).

    Parameters
    ----------
    page
        The page (:func:`rockyade.assess.report_page.report_page`).
    images
        Each figure's PNG bytes by its file name (every figure the page names).

    Raises
    ------
    KeyError
        A figure the page names without its image.
    """
    parts: list[str] = []
    number = 0
    for section in page.sections:
        parts.append(f'<section id="{html.escape(section.ident)}">\n<h2>{html.escape(section.title)}</h2>')
        for block in section.blocks:
            if isinstance(block, str):
                parts.append(f"<p>{html.escape(block)}</p>")
            elif isinstance(block, Table):
                parts.append(_table_html(block))
            elif isinstance(block, Bullets):
                parts.append("<ul>\n" + "\n".join(f"<li>{html.escape(i)}</li>" for i in block.items) + "\n</ul>")
            elif isinstance(block, FigureRef):
                number += 1
                data = base64.b64encode(images[block.name]).decode("ascii")
                caption = html.escape(block.caption)
                parts.append(
                    f'<figure id="fig-{html.escape(block.name.removesuffix(".png"))}">'
                    f'<img src="data:image/png;base64,{data}" alt="{caption}">'
                    f"<figcaption>Figure {number}. {caption}</figcaption></figure>"
                )
        parts.append("</section>")
    toc = "".join(f'<li><a href="#{html.escape(s.ident)}">{html.escape(s.title)}</a></li>' for s in page.sections)
    verdict_class = "verdict verified" if page.verdict == "verified" else "verdict"
    summary = page.summary or page.verdict
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        f'<meta http-equiv="Content-Security-Policy" content="{CSP}">\n'
        '<meta name="viewport" content="width=device-width, initial-scale=1">\n'
        f"<title>{html.escape(page.title)}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n"
        f"<header><h1>{html.escape(page.title)}</h1>\n"
        f'<p class="{verdict_class}" id="verdict-line">{html.escape(summary)}</p></header>\n'
        f"<nav><ol>{toc}</ol></nav>\n" + "\n".join(parts) + "\n"
        "<footer>Written by rockyade assess --report: every number of its tables is the one of assess.json "
        "(each table cell holds its key and value there). Readable without rockyade.</footer>\n"
        "</body>\n</html>\n"
    )


def _md(text: str) -> str:
    """Text safe in Markdown: the characters that would turn into emphasis, code or HTML escaped."""
    out = text.replace("\\", "\\\\")
    for ch in "*_`<>[]#":
        out = out.replace(ch, "\\" + ch)
    return out


def _md_cell(text: str) -> str:
    return _md(text).replace("|", "\\|").replace("\n", " ")


def render_markdown(page: ReportPage) -> str:
    """The page in Markdown (module docstring), the figures linked as the PNG files beside it."""
    lines = [f"# {_md(page.title)}", "", f"**{_md(page.summary or page.verdict)}**", ""]
    number = 0
    for section in page.sections:
        lines += [f"## {_md(section.title)}", ""]
        for block in section.blocks:
            if isinstance(block, str):
                lines += [_md(block), ""]
            elif isinstance(block, Table):
                lines += [f"**{_md(block.caption)}**", ""]
                lines.append("| " + " | ".join(_md_cell(h) for h in block.header) + " |")
                lines.append(
                    "| " + " | ".join("---:" if _numeric(block, k) else "---" for k in range(len(block.header))) + " |"
                )
                lines += ["| " + " | ".join(_md_cell(c.text) for c in row) + " |" for row in block.rows]
                lines.append("")
            elif isinstance(block, Bullets):
                lines += [f"- {_md(item)}" for item in block.items] + [""]
            elif isinstance(block, FigureRef):
                number += 1
                lines += [f"![Figure {number}]({block.name})", "", f"*Figure {number}. {_md(block.caption)}*", ""]
    lines.append(
        "Written by rockyade assess --report: every number of its tables is the one of assess.json. The figures are "
        "the PNG files beside this file."
    )
    return "\n".join(lines) + "\n"


def _numeric(table: Table, column: int) -> bool:
    """Whether a column holds numbers (right-aligned)."""
    cells = [row[column] for row in table.rows if column < len(row)]
    return bool(cells) and all(c.key for c in cells)


__all__ = ["CSP", "STYLE", "render_html", "render_markdown"]
