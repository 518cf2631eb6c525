"""Progress bars for the long commands (tqdm), on stderr.

A bar is drawn only where someone watches: when stderr is a terminal, never into a log file, a pipe or CI's
output, where the commands print their usual lines instead (``SWIFTFIN_PROGRESS=1`` draws them anyway, ``=0``
never). Lines printed while a bar runs go above it (``say``), so nothing is lost either way.

    from swiftfin.progress import bar, say
    with bar(len(todo), "designs") as b:
        for r in results:
            say(f"{r}: ok")
            b.update()
"""
from __future__ import annotations

import os
import sys

ENV = "SWIFTFIN_PROGRESS"


def enabled(stream=None) -> bool:
    """Whether bars are drawn: ``SWIFTFIN_PROGRESS`` if set (1 or 0), else whether ``stream`` (stderr) is a
    terminal."""
    forced = os.environ.get(ENV, "").strip()
    if forced in ("0", "1"):
        return forced == "1"
    stream = sys.stderr if stream is None else stream
    return bool(getattr(stream, "isatty", lambda: False)())


def bar(total: int | None, desc: str, unit: str = "it", show: bool = True):
    """A tqdm bar of ``total`` steps on stderr (a disabled one, which does nothing, where bars are off or ``show``
    is false: a library call that asked for no progress)."""
    from tqdm import tqdm

    return tqdm(total=total, desc=desc, unit=f" {unit}", file=sys.stderr, disable=not (show and enabled()), dynamic_ncols=True,
                leave=True, mininterval=0.2)


def say(text: str) -> None:
    """One line on stderr, above any bar that is running."""
    from tqdm import tqdm

    tqdm.write(text, file=sys.stderr)
    sys.stderr.flush()


__all__ = ["ENV", "bar", "enabled", "say"]
