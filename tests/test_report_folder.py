"""The folder the report is written into: the report never deletes, renames or overwrites a
file it did not write itself, refuses what it cannot do safely with one line, and a failure or
an interrupt (SIGINT, SIGTERM) at any moment leaves the folder as it was.

Most tests replace the analyses by a tiny report (a few small figures) so that they run in
milliseconds; the signal tests run the real ``python -m aerocontrol report`` in a child process.
"""

from __future__ import annotations

import fcntl
import hashlib
import itertools
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import pytest
from matplotlib.figure import Figure

import aerocontrol
from aerocontrol.report import Report, write_report
from aerocontrol.report import build as report_module
from aerocontrol.report import folder as _report_folder

MANIFEST = ".aerocontrol-report.json"


def _tiny_builder(figures: tuple[str, ...] = ("one",), text: str = "v1") -> Callable[..., Report]:
    """A stand-in for build_report: a small report with the given figures and a paragraph."""

    def build(*args: object, **kwargs: object) -> Report:
        tiny = Report(f"tiny {text}")
        tiny.paragraph(text)
        for name in figures:
            figure = Figure(figsize=(1, 1))
            figure.suptitle(f"{name} {text}")
            tiny.figure(name, f"figure {name}", figure)
        return tiny

    return build


@pytest.fixture
def tiny(monkeypatch: pytest.MonkeyPatch) -> Callable[..., None]:
    """Switch the report to a tiny one: ``tiny(figures, text)``."""

    def use(figures: tuple[str, ...] = ("one",), text: str = "v1") -> None:
        monkeypatch.setattr(report_module, "build_report", _tiny_builder(figures, text))

    use()
    return use


def _snapshot(folder: Path) -> dict[str, object]:
    """Everything under ``folder`` (hidden files included), links not followed: the bytes of
    each file, "folder" for folders, ("link", target) for symbolic links."""
    found: dict[str, object] = {}
    for root, folders, files in os.walk(folder):
        for name in folders + files:
            path = Path(root) / name
            key = str(path.relative_to(folder))
            if path.is_symlink():
                found[key] = ("link", os.readlink(path))
            elif path.is_dir():
                found[key] = "folder"
            elif path.is_file():
                found[key] = path.read_bytes()
            else:  # a FIFO: never opened
                found[key] = "special"
        folders[:] = [name for name in folders if not (Path(root) / name).is_symlink()]
    return found


def _assert_complete_report(folder: Path) -> dict[str, dict[str, object]]:
    """The manifest lists every file of the report with its true size and hash; returns the
    listing. No staging folder is left."""
    manifest = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
    assert manifest["format"] == "aerocontrol-report" and manifest["version"] == 1
    files: dict[str, dict[str, object]] = manifest["files"]
    assert {"report.html", "report.md"} <= set(files)
    for name, entry in files.items():
        data = (folder / name).read_bytes()
        assert entry == {"size": len(data), "sha256": hashlib.sha256(data).hexdigest()}, name
    assert not [p for p in folder.iterdir() if p.name.startswith(".aerocontrol-staging-")]
    return files


def _refusal(out: Path, *, force: bool = False) -> str:
    """The one-line message of the OutputFolderError that writing into ``out`` raises."""
    with pytest.raises(aerocontrol.OutputFolderError) as caught:
        write_report(out=out, force=force)
    message = str(caught.value)
    assert "\n" not in message
    assert message.startswith(f"cannot write the report into {str(out)!r}: ")
    return message


# --- Where the report may be written ------------------------------------------------------------


def test_a_new_nested_folder_gets_the_report_and_its_manifest(
    tiny: Callable[..., None], tmp_path: Path
) -> None:
    tiny(("one", "two"))
    out = tmp_path / "a" / "b" / "c"
    assert write_report(out=out) == out / "report.html"
    files = _assert_complete_report(out)
    assert set(files) == {"report.html", "report.md", "figures/one.png", "figures/two.png"}
    assert sorted(p.name for p in out.iterdir()) == [
        MANIFEST,
        "figures",
        "report.html",
        "report.md",
    ]


def test_an_empty_folder_is_used(tiny: Callable[..., None], tmp_path: Path) -> None:
    out = tmp_path / "empty"
    out.mkdir()
    write_report(out=out)
    _assert_complete_report(out)


def test_running_again_replaces_an_untouched_earlier_report_and_nothing_else(
    tiny: Callable[..., None], tmp_path: Path
) -> None:
    """The common case needs no option: the earlier report's files are replaced (and those the
    new report does not write removed); the user's own files are untouched byte for byte."""
    out = tmp_path / "out"
    tiny(("one", "stale"), "v1")
    write_report(out=out)
    (out / "notes.txt").write_text("my notes")
    (out / "figures" / "mine.png").write_bytes(b"my own image")
    (out / "drafts").mkdir()
    (out / "drafts" / "report.md").write_text("a draft")
    tiny(("one", "new"), "v2")
    lines: list[str] = []
    write_report(out=out, progress=lines.append)
    assert lines[-1] == "writing 2 figures and the report (replacing the earlier report)"
    files = _assert_complete_report(out)
    assert set(files) == {"report.html", "report.md", "figures/one.png", "figures/new.png"}
    assert "v2" in (out / "report.md").read_text(encoding="utf-8")
    assert not (out / "figures" / "stale.png").exists()  # the earlier report's own, unchanged
    assert (out / "notes.txt").read_text() == "my notes"
    assert (out / "figures" / "mine.png").read_bytes() == b"my own image"
    assert (out / "drafts" / "report.md").read_text() == "a draft"


def test_a_folder_with_the_users_files_and_no_manifest_is_refused(
    tiny: Callable[..., None], tmp_path: Path
) -> None:
    """The issue's case: DIR/figures/ holds the user's images and DIR/report.md the user's
    notes. Without --force: refused; with it: report.md is in the way, refused by name. Either
    way every file survives byte for byte."""
    out = tmp_path / "out"
    (out / "figures").mkdir(parents=True)
    (out / "figures" / "one.png").write_bytes(b"\x89PNG the user's image")
    (out / "figures" / "photo.jpg").write_bytes(b"a photo")
    (out / "report.md").write_text("my notes")
    before = _snapshot(out)
    assert _refusal(out).endswith(
        f"it is not empty and holds no earlier report (no {MANIFEST}); choose a new or empty "
        "folder, or add --force to write the report beside its files (none of them is replaced)"
    )
    assert _snapshot(out) == before
    assert _refusal(out, force=True).endswith(
        "report.md is a file the report did not write; it is not replaced: move it away or "
        "choose another --out"
    )
    assert _snapshot(out) == before
    # Once report.md is moved away, --force writes beside the user's files, but not over the
    # user's figures/one.png, which the report also wants to write: named, nothing changed.
    (out / "report.md").rename(tmp_path / "notes.md")
    before = _snapshot(out)
    assert _refusal(out, force=True).endswith(
        "figures/one.png is a file the report did not write; it is not replaced: move it away "
        "or choose another --out"
    )
    assert _snapshot(out) == before


def test_force_writes_beside_the_users_files_and_only_its_own_are_replaced_later(
    tiny: Callable[..., None], tmp_path: Path
) -> None:
    out = tmp_path / "project"
    (out / "figures").mkdir(parents=True)
    (out / "figures" / "photo.png").write_bytes(b"the user's")
    (out / "README").write_text("the user's readme")
    user_files = _snapshot(out)
    write_report(out=out, force=True)
    files = _assert_complete_report(out)
    assert set(files) == {"report.html", "report.md", "figures/one.png"}
    tiny(("two",), "v2")
    write_report(out=out)  # an earlier report now: replaced without --force
    assert set(_assert_complete_report(out)) == {"report.html", "report.md", "figures/two.png"}
    after = _snapshot(out)
    for name, content in user_files.items():
        assert after[name] == content, name


def test_a_changed_file_of_the_earlier_report_is_never_replaced(
    tiny: Callable[..., None], tmp_path: Path
) -> None:
    out = tmp_path / "out"
    tiny(("one", "two"))
    write_report(out=out)
    for changed in ("report.md", "figures/two.png"):
        with open(out / changed, "ab") as file:
            file.write(b" edited")
        before = _snapshot(out)
        for force in (False, True):
            assert _refusal(out, force=force).endswith(
                f"{changed} was changed after aerocontrol wrote it, so it is yours now and is not "
                "replaced: move it away (or choose another --out) and run again"
            )
            assert _snapshot(out) == before
        (out / changed).unlink()  # moved away: a deleted file of the earlier report is fine
    write_report(out=out)
    _assert_complete_report(out)


def test_a_leftover_staging_folder_is_named(tiny: Callable[..., None], tmp_path: Path) -> None:
    out = tmp_path / "out"
    (out / ".aerocontrol-staging-0123456789ab").mkdir(parents=True)
    assert "(it holds .aerocontrol-staging-0123456789ab, left by a run that was killed" in (
        _refusal(out)
    )


# --- Hostile manifests, symbolic links, odd folders ---------------------------------------------


def _manifest_for(entries: dict[str, bytes]) -> dict[str, object]:
    return {
        "format": "aerocontrol-report",
        "version": 1,
        "files": {
            name: {"size": len(data), "sha256": hashlib.sha256(data).hexdigest()}
            for name, data in entries.items()
        },
    }


VICTIM = b"a file outside the report folder"


@pytest.mark.parametrize(
    ("manifest", "reason"),
    [
        (b"{not json", "not JSON"),
        (b"\xff\xfe", "not JSON"),
        (b"[" * 100_000 + b"]" * 100_000, "not JSON"),
        (b"[]", "not a JSON object"),
        (json.dumps({"format": "other", "version": 1, "files": {}}).encode(), "not format"),
        (json.dumps(_manifest_for({"../victim.txt": VICTIM})).encode(), "'../victim.txt'"),
        (json.dumps(_manifest_for({"figures/../../victim.txt": VICTIM})).encode(), "'figures/"),
        (json.dumps(_manifest_for({"/tmp/victim.txt": VICTIM})).encode(), "'/tmp/victim.txt'"),
        (json.dumps(_manifest_for({"notes.txt": VICTIM})).encode(), "'notes.txt'"),
        (json.dumps(_manifest_for({"figures/sub/x.png": VICTIM})).encode(), "'figures/sub/x.png'"),
        (
            json.dumps(
                {"format": "aerocontrol-report", "version": 1, "files": {"report.md": 1}}
            ).encode(),
            "the entry 'report.md' has no size and hash",
        ),
        (
            json.dumps(
                {
                    "format": "aerocontrol-report",
                    "version": 1,
                    "files": {"report.md": {"size": -1, "sha256": "0"}},
                }
            ).encode(),
            "has no valid size",
        ),
        (
            b'{"format": "aerocontrol-report", "version": 1, "files": {"report.md": {"size": '
            + b"9" * 5000
            + b', "sha256": "x"}}}',
            "not JSON",
        ),
        (b" " * (2 << 20), "not a regular file of at most 1 MiB"),
    ],
    ids=[
        "not-json",
        "not-utf8",
        "deep",
        "array",
        "format",
        "dotdot",
        "figures-dotdot",
        "absolute",
        "other-name",
        "subfolder",
        "entry",
        "size",
        "huge-int",
        "2-MiB",
    ],
)
def test_a_hostile_manifest_is_refused_and_nothing_is_touched(
    tiny: Callable[..., None], tmp_path: Path, manifest: bytes, reason: str
) -> None:
    victim = tmp_path / "victim.txt"
    victim.write_bytes(VICTIM)
    out = tmp_path / "out"
    out.mkdir()
    (out / MANIFEST).write_bytes(manifest)
    (out / "notes.txt").write_bytes(VICTIM)
    before = _snapshot(tmp_path)
    message = _refusal(out, force=True)
    assert f"{MANIFEST} is not a manifest written by aerocontrol (" in message
    assert reason in message
    assert message.endswith("nothing was changed: move it away or choose another --out")
    assert _snapshot(tmp_path) == before


def test_a_manifest_cannot_reach_through_a_linked_figures_folder(
    tiny: Callable[..., None], tmp_path: Path
) -> None:
    """A well-formed manifest naming figures/one.png, with figures/ a link to another folder
    whose one.png matches the hash: refused, the other folder untouched."""
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "one.png").write_bytes(VICTIM)
    out = tmp_path / "out"
    out.mkdir()
    (out / "figures").symlink_to(elsewhere)
    (out / MANIFEST).write_text(json.dumps(_manifest_for({"figures/one.png": VICTIM})))
    before = _snapshot(tmp_path)
    assert _refusal(out).endswith(
        "figures is a symbolic link (the report never writes through one); it is not replaced: "
        "move it away or choose another --out"
    )
    assert _snapshot(tmp_path) == before


def test_a_linked_report_file_is_never_written_through(
    tiny: Callable[..., None], tmp_path: Path
) -> None:
    """DIR/report.md a link to the user's file: refused, with or without a manifest that
    lists report.md with the hash of the link's target."""
    target = tmp_path / "thesis.md"
    target.write_bytes(VICTIM)
    out = tmp_path / "out"
    out.mkdir()
    (out / "report.md").symlink_to(target)
    before = _snapshot(tmp_path)
    expected = (
        "report.md is a symbolic link (the report never writes through one); it is not "
        "replaced: move it away or choose another --out"
    )
    assert _refusal(out, force=True).endswith(expected)
    (out / MANIFEST).write_text(json.dumps(_manifest_for({"report.md": VICTIM})))
    before = _snapshot(tmp_path)
    assert _refusal(out).endswith(
        "report.md was changed after aerocontrol wrote it, so it is yours now and is not "
        "replaced: move it away (or choose another --out) and run again"
    )
    assert _snapshot(tmp_path) == before
    assert target.read_bytes() == VICTIM


def test_a_linked_manifest_is_not_read_through(tiny: Callable[..., None], tmp_path: Path) -> None:
    elsewhere = tmp_path / "elsewhere.json"
    elsewhere.write_text(json.dumps(_manifest_for({})))
    out = tmp_path / "out"
    out.mkdir()
    (out / MANIFEST).symlink_to(elsewhere)
    assert "(not a regular file of at most 1 MiB)" in _refusal(out)


def test_the_folder_itself_may_be_a_link_to_a_folder(
    tiny: Callable[..., None], tmp_path: Path
) -> None:
    real = tmp_path / "real"
    real.mkdir()
    link = tmp_path / "link"
    link.symlink_to(real)
    write_report(out=link)
    assert link.is_symlink()
    _assert_complete_report(real)
    write_report(out=link)  # and again, replacing
    _assert_complete_report(real)


@pytest.mark.parametrize("kind", ["file", "broken-link", "file-parent", "fifo", "link-to-file"])
def test_a_folder_that_is_not_one_is_one_clear_error(
    tiny: Callable[..., None], tmp_path: Path, kind: str
) -> None:
    out = tmp_path / "out"
    if kind == "file":
        out.write_text("a file")
        expected = "it exists and is not a folder"
    elif kind == "broken-link":
        out.symlink_to(tmp_path / "absent")
        expected = "it is a symbolic link to nothing (a broken link)"
    elif kind == "fifo":
        os.mkfifo(out)
        expected = "it exists and is not a folder"
    elif kind == "link-to-file":
        (tmp_path / "file").write_text("a file")
        out.symlink_to(tmp_path / "file")
        expected = "it exists and is not a folder"
    else:
        (tmp_path / "file").write_text("a file")
        out = tmp_path / "file" / "out"
        expected = f"{str(tmp_path / 'file')!r} is not a folder"
    before = _snapshot(tmp_path)
    assert _refusal(out) == f"cannot write the report into {str(out)!r}: {expected}"
    assert _snapshot(tmp_path) == before


@pytest.mark.parametrize(
    ("arguments", "match"),
    [
        ({"progress": 3}, "progress must be callable or None, got 3"),
        ({"progress": "print"}, "progress must be callable or None"),
        ({"out": 3}, "out must be a folder's path"),
        ({"out": b"bytes"}, "out must be a folder's path"),
    ],
)
def test_a_bad_progress_or_out_is_refused_before_anything_is_written(
    tiny: Callable[..., None],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    arguments: dict[str, object],
    match: str,
) -> None:
    """A progress that is not callable was a TypeError at the first section's line (after
    the folder was prepared), an int ``out`` a TypeError from pathlib: both are named
    InvalidArgumentErrors now, before the folder is touched."""
    monkeypatch.chdir(tmp_path)  # a bad ``out`` must not leave a folder in the working directory
    before = _snapshot(tmp_path)
    with pytest.raises(aerocontrol.InvalidArgumentError, match=match):
        write_report(**{"out": tmp_path / "out", **arguments})  # type: ignore[arg-type]
    assert _snapshot(tmp_path) == before


@pytest.mark.skipif(os.geteuid() == 0, reason="root may write into any folder")
def test_an_unwritable_folder_is_refused_before_the_analyses(
    tiny: Callable[..., None], tmp_path: Path
) -> None:  # pragma: no cover - the suite runs as root in some containers
    out = tmp_path / "locked"
    out.mkdir()
    out.chmod(0o500)
    try:
        assert _refusal(out).endswith(": Permission denied")
        assert list(out.iterdir()) == []
    finally:
        out.chmod(0o700)


def test_a_second_run_into_the_same_folder_at_the_same_time_is_refused(
    tiny: Callable[..., None], tmp_path: Path
) -> None:
    out = tmp_path / "out"
    write_report(out=out)
    before = _snapshot(out)
    holder = os.open(out, os.O_RDONLY)
    try:
        fcntl.flock(holder, fcntl.LOCK_EX | fcntl.LOCK_NB)  # as a running report does
        assert _refusal(out).endswith(
            "another 'aerocontrol report' is writing into it; try again when it has finished"
        )
        assert _snapshot(out) == before
    finally:
        os.close(holder)
    write_report(out=out)  # the lock went with the other run


# --- Failures: everything the run did is undone -------------------------------------------------


@pytest.mark.parametrize("earlier", [False, True])
def test_a_failure_while_building_leaves_no_trace(
    tiny: Callable[..., None], monkeypatch: pytest.MonkeyPatch, tmp_path: Path, earlier: bool
) -> None:
    out = tmp_path / "a" / "b" / "c"
    if earlier:
        write_report(out=out)
        (out / "notes.txt").write_text("mine")
    before = _snapshot(tmp_path)

    def fail(*args: object, **kwargs: object) -> Report:
        assert any(p.name.startswith(".aerocontrol-staging-") for p in out.iterdir())
        raise aerocontrol.ConvergenceError("the regulator failed")

    monkeypatch.setattr(report_module, "build_report", fail)
    with pytest.raises(aerocontrol.ConvergenceError, match="the regulator failed"):
        write_report(out=out)
    assert _snapshot(tmp_path) == before
    if not earlier:
        assert list(tmp_path.iterdir()) == []  # no a/ left behind


def _count_moves(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    calls = [0]
    real = _report_folder.link_new

    def counting(*args: object) -> None:
        calls[0] += 1
        real(*args)  # type: ignore[arg-type]

    monkeypatch.setattr(_report_folder, "link_new", counting)
    return calls


@pytest.mark.parametrize("error", [OSError(28, "No space left on device"), KeyboardInterrupt()])
@pytest.mark.parametrize("earlier", [False, True])
def test_a_failure_at_any_of_the_final_moves_is_undone(
    tiny: Callable[..., None],
    monkeypatch: pytest.MonkeyPatch,
    tmp_path: Path,
    error: BaseException,
    earlier: bool,
) -> None:
    """Each move of the commit fails in turn (a full disk, Ctrl-C): the folder is then exactly
    as before, byte for byte: the earlier report and the user's files back, the new files and
    the staging folder gone, no folder left that the run created."""
    out = tmp_path / "out"
    if earlier:
        tiny(("one", "stale"), "v1")
        write_report(out=out)
        (out / "figures" / "mine.png").write_bytes(b"mine")
        (out / "notes.txt").write_text("mine")
    tiny(("one", "two", "three"), "v2")
    probe = tmp_path.parent / f"{tmp_path.name}-probe"
    if earlier:
        shutil.copytree(out, probe)
    with monkeypatch.context() as patch:
        moves = _count_moves(patch)
        write_report(out=probe)
        total = moves[0]
    shutil.rmtree(probe)
    # The earlier report's 4 files and manifest out of the way; the 5 new files and manifest in.
    assert total == (5 if earlier else 0) + 6
    before = _snapshot(tmp_path)
    real = _report_folder.link_new
    for failing in range(1, total + 1):
        count = itertools.count(1)

        def failing_move(
            *args: object, failing: int = failing, count: Iterator[int] = count
        ) -> None:
            if next(count) == failing:
                raise error
            real(*args)  # type: ignore[arg-type]

        with monkeypatch.context() as patch:
            patch.setattr(_report_folder, "link_new", failing_move)
            with pytest.raises(type(error)):
                write_report(out=out)
        assert _snapshot(tmp_path) == before, failing
    write_report(out=out)  # and the next run goes through
    _assert_complete_report(out)


def test_a_file_put_in_the_way_during_the_build_stops_the_run(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    out = tmp_path / "out"
    build = _tiny_builder(("one",))

    def build_while_the_user_writes(*args: object, **kwargs: object) -> Report:
        (out / "figures").mkdir()
        (out / "figures" / "one.png").write_bytes(b"the user's")
        return build()

    monkeypatch.setattr(report_module, "build_report", build_while_the_user_writes)
    assert _refusal(out).endswith("figures/one.png is a file the report did not write; it is not "
                                  "replaced: move it away or choose another --out")  # fmt: skip
    assert _snapshot(out) == {"figures": "folder", "figures/one.png": b"the user's"}


def test_an_earlier_file_changed_during_the_build_is_kept(
    tiny: Callable[..., None], monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    out = tmp_path / "out"
    write_report(out=out)
    build = _tiny_builder(("one",), "v2")

    def build_while_the_user_edits(*args: object, **kwargs: object) -> Report:
        (out / "report.md").write_text("edited meanwhile")
        return build()

    monkeypatch.setattr(report_module, "build_report", build_while_the_user_edits)
    assert "report.md was changed after aerocontrol wrote it" in _refusal(out)
    assert (out / "report.md").read_text() == "edited meanwhile"
    assert not [p for p in out.iterdir() if p.name.startswith(".aerocontrol-staging-")]


# --- Interrupts of the real command -------------------------------------------------------------


@pytest.fixture(scope="module")
def earlier_report(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """A real earlier report (the Navion's, so that the 747's run would differ from it) with
    the user's files beside it."""
    folder = tmp_path_factory.mktemp("earlier") / "report"
    write_report("navion", out=folder)
    (folder / "notes.txt").write_text("my notes")
    (folder / "figures" / "mine.png").write_bytes(b"my image")
    yield folder


def _interrupt(out: Path, signum: int, moment: str, delay: float) -> tuple[int, str, str]:
    """Run ``python -m aerocontrol report --out out``, send ``signum`` ``delay`` seconds after
    the progress line that starts with ``moment``; the status, standard output and error."""
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    child = subprocess.Popen(
        [sys.executable, "-m", "aerocontrol", "report", "--out", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    try:
        assert child.stdout is not None
        lines = []
        for line in child.stdout:
            lines.append(line)
            if line.startswith(moment):
                time.sleep(delay)
                child.send_signal(signum)
                break
        out_rest, err = child.communicate(timeout=60)
    finally:
        if child.poll() is None:  # pragma: no cover - only if the test fails
            child.kill()
            child.wait()
    return child.returncode, "".join(lines) + out_rest, err


@pytest.mark.parametrize(
    ("moment", "delay"),
    # "late-rendering": 1 s into the rendering of the figures, which takes about 3.5 s here
    # (2 s raced the end of a rendering that had become faster, and the report finished).
    [("models", 0.0), ("writing", 0.0), ("writing", 1.0)],
    ids=["analyses", "rendering", "late-rendering"],
)
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_an_interrupt_leaves_the_earlier_report_as_it_was(
    earlier_report: Path, tmp_path: Path, signum: int, moment: str, delay: float
) -> None:
    out = tmp_path / "report"
    shutil.copytree(earlier_report, out, symlinks=True)
    before = _snapshot(out)
    status, _, err = _interrupt(out, signum, moment, delay)
    if signum == signal.SIGINT:
        assert (status, err) == (130, "aerocontrol: interrupted\n")
    else:
        assert (status, err) == (143, "aerocontrol: terminated\n")
    assert _snapshot(out) == before


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_an_interrupt_into_a_new_nested_folder_leaves_nothing(tmp_path: Path, signum: int) -> None:
    status, _, err = _interrupt(tmp_path / "a" / "b" / "c", signum, "modes", 0.0)
    assert status in (130, 143) and err.count("\n") == 1
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("at_move", [1, 4, 6])
def test_a_signal_during_the_final_moves_waits_until_they_are_done(
    tiny: Callable[..., None], monkeypatch: pytest.MonkeyPatch, tmp_path: Path, at_move: int
) -> None:
    """SIGINT arriving in the middle of the moves is held back until the new report is wholly
    in place, then raises KeyboardInterrupt: never a mix of the earlier and the new report."""
    out = tmp_path / "out"
    tiny(("one", "stale"), "v1")
    write_report(out=out)
    tiny(("one", "two"), "v2")
    real = _report_folder.link_new
    count = itertools.count(1)

    def interrupted_move(*args: object) -> None:
        if next(count) == at_move:
            os.kill(os.getpid(), signal.SIGINT)
        real(*args)  # type: ignore[arg-type]

    monkeypatch.setattr(_report_folder, "link_new", interrupted_move)
    with pytest.raises(KeyboardInterrupt):
        write_report(out=out)
    assert next(count) == 5 + 5 + 1  # every move was made (4 out, 5 in), then the signal
    files = _assert_complete_report(out)
    assert set(files) == {"report.html", "report.md", "figures/one.png", "figures/two.png"}
    assert "v2" in (out / "report.md").read_text(encoding="utf-8")


def test_the_readme_documents_the_rules_and_the_promises() -> None:
    readme = Path(__file__).resolve().parents[1] / "README.md"
    if not readme.is_file():  # pragma: no cover - tests run from an sdist without README
        pytest.skip("README.md not found beside the tests")
    text = " ".join(readme.read_text(encoding="utf-8").split())
    report = text.split("## The report", 1)[1].split("## What aerocontrol promises", 1)[0]
    for rule in (
        "never deletes, renames or overwrites a file it did not write itself",
        "`DIR/.aerocontrol-report.json`",
        "running the same command twice, as in the setup above, just works",
        "is never touched",
        "`--force`",
        "symbolic links inside `DIR` are never written through",
        "no staging folder, no half-written report",
    ):
        assert rule in report, rule
    promises = Path(__file__).resolve().parents[1] / "docs" / "promises.md"
    text = " ".join(promises.read_text(encoding="utf-8").split())
    assert (
        text.split("## Files and input files", 1)[1]
        .lstrip()
        .startswith("- A command never deletes")
    )
