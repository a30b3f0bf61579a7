"""Section 6 of the report, first part: the MIL-F-8785C Levels open loop and with each design
of the lateral motion (the dampers and the regulator at each weight)."""

from __future__ import annotations

from .. import handling
from ..exceptions import InvalidArgumentError
from .context import Context, assess

__all__ = ["section"]


def _level(assessment: handling.HandlingQualities, mode: str) -> str:
    return str(assessment.levels.get(mode, "-"))


def section(ctx: Context) -> str:
    """Write the Levels open loop and with each design in ``ctx.augmented``; the progress
    line (the Levels that changed)."""
    report = ctx.report
    report.heading("Levels after augmentation")
    if ctx.open_loop is None:  # pragma: no cover - the modes section always runs first
        raise InvalidArgumentError("the modes must be assessed before the augmented designs")
    longitudinal = {
        key: value
        for key, value in ctx.open_loop_named.items()
        if key in ("short period", "phugoid")
    }
    columns = {"open loop": (ctx.open_loop, ctx.open_loop_named)}
    for label, lateral in ctx.augmented.items():
        named = {**longitudinal, **lateral}
        columns[label] = (assess(ctx, named), named)
    rows = [
        (mode, *(_level(hq, mode) for hq, _ in columns.values()))
        for mode in handling.MODES
        if any(mode in named for _, named in columns.values())
    ]
    rows.append(("all modes", *(str(max(hq.levels.values())) for hq, _ in columns.values())))
    report.paragraph(
        f"MIL-F-8785C Levels, Class {ctx.plane.aircraft_class}, Flight Phase Category "
        f"{ctx.plane.category}, open loop and with each design of the lateral motion (the "
        "longitudinal modes are not changed); a roll and spiral coupled into one oscillation "
        "are judged as the roll-spiral mode (3.3.1.4)."
    )
    report.table(("mode", *columns), rows)
    changed = [
        f"{row[0]} {row[1]} -> "
        + ", ".join(
            f"{label} {cell}" for label, cell in zip(list(columns)[1:], row[2:], strict=True)
        )
        for row in rows[:-1]
        if any(cell != row[1] for cell in row[2:])
    ]
    return "levels after augmentation: " + ("; ".join(changed) or "no Level changes")
