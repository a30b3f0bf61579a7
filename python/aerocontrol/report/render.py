"""The blocks a report is made of, and how they are written: Markdown, one self-contained HTML
page, and the figures as PNG.

The blocks are plain records (a heading, a paragraph, a table of strings, a matplotlib figure
with its caption); :class:`~aerocontrol.report.Report` collects them and calls
:func:`markdown` and :func:`html`. Every cell and caption is text: the Markdown escapes the
table separator ``|`` in cells, the HTML escapes everything, and embeds each figure as a
base64 PNG so that the page needs no other file.
"""

from __future__ import annotations

import html as html_text
import io
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from .._results import html_table, markdown_table, png_data_uri

__all__ = [
    "Figure",
    "Heading",
    "Paragraph",
    "Table",
    "html",
    "html_body",
    "markdown",
    "png_images",
]


@dataclass
class Heading:
    text: str
    level: int


@dataclass
class Paragraph:
    text: str


@dataclass
class Table:
    header: tuple[str, ...]
    rows: list[tuple[str, ...]]


@dataclass
class Figure:
    name: str
    caption: str
    figure: Any = field(compare=False)
    """The matplotlib figure (not compared: a report is equal to its unpickled copy, whose
    figures are new objects, when its names and captions are)."""


def markdown(
    title: str,
    blocks: Sequence[Any],
    figure_folder: str,
    images: dict[str, bytes] | None = None,
) -> str:
    """The blocks in Markdown under the title, the figures linked from ``figure_folder``, or
    embedded when ``images`` maps their file names to PNG bytes."""
    lines = [f"# {title}", ""]
    for block in blocks:
        if isinstance(block, Heading):
            lines += ["#" * block.level + " " + block.text, ""]
        elif isinstance(block, Paragraph):
            lines += [block.text, ""]
        elif isinstance(block, Table):
            lines += [markdown_table(block.header, block.rows), ""]
        else:
            target = (
                png_data_uri(images[f"{block.name}.png"])
                if images is not None
                else f"{figure_folder}/{block.name}.png"
            )
            lines += [f"![{block.caption}]({target})", ""]
            lines += [f"*{block.caption}*", ""]
    return "\n".join(lines)


def html_body(title: str, blocks: Sequence[Any], images: dict[str, bytes]) -> str:
    """The blocks as HTML elements (a fragment, as a notebook shows it); ``images`` maps file
    names to PNG bytes, embedded."""
    escape = html_text.escape
    body = [f"<h1>{escape(title)}</h1>"]
    for block in blocks:
        if isinstance(block, Heading):
            body.append(f"<h{block.level}>{escape(block.text)}</h{block.level}>")
        elif isinstance(block, Paragraph):
            body.append(f"<p>{escape(block.text)}</p>")
        elif isinstance(block, Table):
            body.append(html_table(block.header, block.rows))
        else:
            caption = escape(block.caption)
            body.append(
                f'<figure><img alt="{caption}" src="{png_data_uri(images[f"{block.name}.png"])}">'
                f"<figcaption>{caption}</figcaption></figure>"
            )
    return "\n".join(body)


def html(title: str, blocks: Sequence[Any], images: dict[str, bytes]) -> str:
    """The blocks as one HTML page; ``images`` maps file names to PNG bytes, embedded."""
    return _HTML_PAGE.format(title=html_text.escape(title), body=html_body(title, blocks, images))


_HTML_PAGE = """<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>{title}</title>
<style>
body {{ font-family: system-ui, sans-serif; max-width: 1100px; margin: 2em auto;
        padding: 0 1em; line-height: 1.45; color: #1a1a1a; }}
table {{ border-collapse: collapse; margin: 0.8em 0 1.4em; font-size: 0.92em; }}
th, td {{ border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; }}
th {{ background: #f2f2f2; }}
td {{ font-variant-numeric: tabular-nums; }}
figure {{ margin: 1em 0 2em; }}
img {{ max-width: 100%; }}
figcaption {{ font-size: 0.9em; color: #444; }}
</style>
</head>
<body>
{body}
</body>
</html>
"""


def png_images(figures: Sequence[tuple[str, Any]], say: Callable[[str], None]) -> dict[str, bytes]:
    """The PNG bytes of each (file name, matplotlib figure), at 100 dpi.

    A figure that matplotlib cannot draw (the responses of an aircraft whose numbers are each
    plausible but together absurd can overflow to values no axis can hold) is replaced by a
    picture that says so, and ``say`` gets one line about it; the other figures are drawn."""
    images = {}
    for name, figure in figures:
        buffer = io.BytesIO()
        try:
            figure.savefig(buffer, format="png", dpi=100)
        except (ArithmeticError, ValueError, RuntimeError) as error:
            reason = " ".join(f"{type(error).__name__}: {error}".split())
            say(f"figure {name} could not be drawn ({reason})")
            buffer = io.BytesIO()
            _undrawable(name, reason).savefig(buffer, format="png", dpi=100)
        images[name] = buffer.getvalue()
    return images


def _undrawable(name: str, reason: str) -> Any:
    """A small figure that says why the figure ``name`` could not be drawn."""
    from matplotlib.figure import Figure as PlotFigure

    figure = PlotFigure(figsize=(6.0, 1.5))
    text = f"{name}: this figure could not be drawn\n({reason[:200]})"
    figure.text(0.5, 0.5, text, ha="center", va="center", wrap=True, fontsize=9)
    return figure
