"""The report as a document: a title and a list of blocks, which the sections append and
:mod:`~aerocontrol.report.render` writes as Markdown and HTML."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from . import render
from .render import Figure, Heading, Paragraph, Table

__all__ = ["Report"]


@dataclass
class Report:
    """A report as a list of blocks, rendered to Markdown and to self-contained HTML.

    Attributes
    ----------
    title : str
        The report's title, its level-1 heading.
    blocks : list
        The headings, paragraphs, tables and figures, in order.
    figures : list of (str, matplotlib.figure.Figure)
        (file name, figure) of every figure, in order.

    Examples
    --------
    >>> from aerocontrol.report import Report
    >>> report = Report("Yaw damper")
    >>> report.heading("Gain")
    >>> report.table(["mode", "Level"], [["dutch roll", "1"]])
    >>> report.markdown().splitlines()
    ['# Yaw damper', '', '## Gain', '', '| mode | Level |', '| --- | --- |', '| dutch roll | 1 |']
    >>> report.figures
    []
    """

    title: str
    blocks: list[Any] = field(default_factory=list)

    def heading(self, text: str, level: int = 2) -> None:
        self.blocks.append(Heading(text, level))

    def paragraph(self, text: str) -> None:
        self.blocks.append(Paragraph(text))

    def table(self, header: Sequence[str], rows: Sequence[Sequence[str]]) -> None:
        self.blocks.append(Table(tuple(header), [tuple(row) for row in rows]))

    def figure(self, name: str, caption: str, figure: Any) -> None:
        self.blocks.append(Figure(name, caption, figure))

    @property
    def figures(self) -> list[tuple[str, Any]]:
        """(file name, matplotlib figure) of every figure, in order."""
        return [(f"{b.name}.png", b.figure) for b in self.blocks if isinstance(b, Figure)]

    def markdown(self, figure_folder: str = "figures") -> str:
        """The report in Markdown, the figures linked from ``figure_folder``."""
        return render.markdown(self.title, self.blocks, figure_folder)

    def html(self, images: dict[str, bytes]) -> str:
        """The report as one HTML page; ``images`` maps file names to PNG bytes, embedded."""
        return render.html(self.title, self.blocks, images)

    def sections(self) -> list[Report]:
        """The report's sections, each a report of its own: a level-2 heading (the title)
        and the blocks up to the next one; blocks before the first heading are left out.

        Returns
        -------
        list of Report
            One per section, in order; a notebook shows each as the whole report is shown.

        Examples
        --------
        >>> from aerocontrol.report import build_report
        >>> sections = build_report("b747-approach").sections()
        >>> [section.title for section in sections[:3]]
        ['Aircraft and flight condition', 'Modes and handling qualities', 'Responses']
        """
        found: list[Report] = []
        for block in self.blocks:
            if isinstance(block, Heading) and block.level <= 2:
                found.append(Report(block.text))
            elif found:
                found[-1].blocks.append(block)
        return found

    def _images(self) -> dict[str, bytes]:
        return render.png_images(self.figures, lambda _: None)

    def _repr_html_(self) -> str:
        """The report as HTML (the page's body, figures embedded), for Jupyter."""
        return render.html_body(self.title, self.blocks, self._images())

    def _repr_markdown_(self) -> str:
        """The report as Markdown (figures embedded as data URIs), for Jupyter."""
        return render.markdown(self.title, self.blocks, "", self._images())
