"""Building a report and writing it into its folder: :func:`build_report` runs the sections
in order on one aircraft, :func:`write_report` renders the result and hands the files to
:class:`~aerocontrol.report.folder.ReportFolder`, which changes the folder only where the
report's own files are and undoes the run on any failure or interrupt."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

from .._validation import optional_callable
from ..aircraft.model import Aircraft, load
from ..exceptions import InvalidArgumentError, OutputFolderError
from . import (
    chapter_check,
    damper,
    digital,
    envelope,
    levels,
    models,
    modes,
    regulator,
    responses,
    sas,
)
from .context import Context
from .document import Report
from .folder import ReportFolder
from .render import png_images
from .signals import termination_exits

__all__ = ["build_report", "write_document", "write_report"]


def build_report(
    plane: Aircraft | str = "b747-approach", progress: Callable[[str], None] | None = None
) -> Report:
    """Run the analyses on an aircraft (an :class:`~aerocontrol.aircraft.Aircraft`, a shipped
    identifier or a TOML path) and collect them as a :class:`Report`. ``progress`` receives
    one line per step.

    Parameters
    ----------
    plane : Aircraft or str, optional
        The aircraft (default "b747-approach", the chapter's 747).
    progress : callable, optional
        ``progress(line)`` after each section.

    Returns
    -------
    Report
        The sections' headings, paragraphs, tables and figures, in order.

    Raises
    ------
    AircraftDataError
        The aircraft cannot be loaded. A design that does not apply to the aircraft is
        reported in the document, not raised.
    InvalidArgumentError
        ``progress`` is neither callable nor None (before anything is built).

    Examples
    --------
    >>> from aerocontrol.report import build_report
    >>> lines = []
    >>> document = build_report(progress=lines.append)     # the 747: a few seconds
    >>> lines[0][:36]
    'models: Boeing 747, powered approach'
    """
    optional_callable(progress, "progress")
    aircraft = plane if isinstance(plane, Aircraft) else load(plane)
    say = progress if progress is not None else (lambda line: None)
    report = Report(f"aerocontrol {_version()}: {aircraft.name}")
    ctx = Context(aircraft, report)
    # In the order of the report: each section may use what the earlier ones left in ctx.
    steps: list[Callable[[Context], str]] = [
        models.section,
        modes.section,
        responses.section,
        damper.section,
        regulator.section,
        digital.section,
        sas.section,
        levels.section,
        envelope.section,
    ]
    if aircraft.identifier == "b747-approach":
        steps.append(chapter_check.section)
    for step in steps:
        for line in step(ctx).splitlines():
            say(line)
    return report


def write_report(
    plane: Aircraft | str = "b747-approach",
    out: str | Path = "aerocontrol-report",
    progress: Callable[[str], None] | None = None,
    force: bool = False,
) -> Path:
    """Build the report of an aircraft and write it into the folder ``out``: ``report.html``
    (self-contained), ``report.md``, ``figures/*.png`` and the manifest
    ``.aerocontrol-report.json`` (each file with its size and SHA-256). Returns the path of
    ``report.html``.

    The report never deletes, renames or overwrites a file it did not write itself:

    - a new or empty ``out`` is used (missing parent folders are created);
    - an ``out`` holding an earlier report (its manifest) is replaced if every file the
      manifest lists is unchanged or deleted: only those files are replaced or removed, and
      files it does not list (your notes, your images in ``figures/``) are never touched;
      a listed file changed since stops the run, named (it is yours now);
    - an ``out`` that is not empty and holds no manifest is refused, unless ``force``: then
      the report is written beside the files there, and a file in its way (your own
      ``report.md``, say) stops the run, named;
    - a symbolic link inside ``out`` (``report.md``, ``figures``) is never written through;
      ``out`` itself may be a link to a folder;
    - a manifest that is not one this function wrote (not JSON, entries other than the
      report's own file names, such as ``../x`` or absolute paths) refuses the run.

    The aircraft is loaded and the folder checked before anything is built, so a refusal is
    immediate. The files are rendered into a staging folder inside ``out`` and moved into
    place at the end, with SIGINT, SIGTERM and SIGHUP held back for those moves. On any
    failure, and on KeyboardInterrupt or SIGTERM (in the main thread, while SIGTERM has its
    default action, it raises SystemExit(143) for the duration of the call), the run undoes
    exactly what it did: the staging folder, its files, the folders it created (if empty);
    the earlier report's files, kept as backups until the end, are put back. Another run
    writing into the same folder at the same time is refused.

    Parameters
    ----------
    plane : Aircraft or str, optional
        The aircraft (default "b747-approach", the chapter's 747).
    out : str or Path, optional
        The folder (default "aerocontrol-report").
    progress : callable, optional
        ``progress(line)`` after each section.
    force : bool, optional
        Write beside the files of a folder that holds no earlier report (default False).

    Returns
    -------
    Path
        The path of ``report.html``.

    Raises
    ------
    AircraftDataError
        The aircraft cannot be loaded (nothing is written).
    InvalidArgumentError
        ``progress`` is neither callable nor None, or ``out`` is not a str or Path (nothing
        is written).
    OutputFolderError
        An ``OSError``: ``out`` cannot be used (not empty and no earlier report, a changed
        or unlisted file in the way, a bad manifest, another run, not a folder, not
        writable, out of space); one line naming the folder and the file.

    Examples
    --------
    ``write_report("navion", "navion-report")`` writes the Navion's report into
    ./navion-report; ``aerocontrol report navion --out navion-report`` does the same, and
    running either again replaces that report.
    """
    optional_callable(progress, "progress")
    aircraft = plane if isinstance(plane, Aircraft) else load(plane)
    return write_document(lambda say: build_report(aircraft, say), out, progress, force)


def write_document(
    build: Callable[[Callable[[str], None]], Report],
    out: str | Path,
    progress: Callable[[str], None] | None = None,
    force: bool = False,
) -> Path:
    """Build a report (``build(say)``) and write it into the folder ``out`` under the rules
    of :func:`write_report` (the folder is checked before anything is built). Returns the
    path of ``report.html``."""
    optional_callable(progress, "progress")
    if not isinstance(out, (str, os.PathLike)) or isinstance(out, bytes):
        raise InvalidArgumentError(f"out must be a folder's path (str or Path), got {out!r:.80}")
    say = progress if progress is not None else (lambda line: None)
    folder = ReportFolder(Path(out), force=force)
    with termination_exits():
        folder.prepare()
        try:
            report = build(say)
            earlier = " (replacing the earlier report)" if folder.replacing else ""
            say(f"writing {len(report.figures)} figures and the report{earlier}")
            folder.write(_render(report, say))
        except BaseException as error:
            problems = folder.rollback()
            if problems and isinstance(error, Exception):
                raise OutputFolderError(f"{error}; moreover {'; '.join(problems)}") from error
            raise
        finally:
            folder.release()
    return Path(out) / "report.html"


def _render(report: Report, say: Callable[[str], None]) -> dict[str, bytes]:
    """The report's files by name: ``figures/*.png``, ``report.md``, ``report.html`` (a
    figure that cannot be drawn is replaced by one that says why: see
    :func:`~aerocontrol.report.render.png_images`)."""
    images = png_images(report.figures, say)
    files = {f"figures/{name}": data for name, data in images.items()}
    files["report.md"] = report.markdown().encode("utf-8")
    files["report.html"] = report.html(images).encode("utf-8")
    return files


def _version() -> str:
    from .. import __version__

    return __version__
