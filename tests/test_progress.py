"""Progress bars on long work (issue 16): drawn on a terminal, never into a pipe or a log, forced by
SWIFTFIN_PROGRESS; the lines the commands print are the same with or without them."""
from __future__ import annotations

import io
import os
import subprocess
import sys
from pathlib import Path

import pytest

from swiftfin.progress import ENV, bar, enabled

ROOT = Path(__file__).resolve().parents[1]


class _Tty(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.mark.parametrize("forced, tty, want", [("", False, False), ("", True, True), ("1", False, True),
                                               ("0", True, False)])
def test_bars_are_drawn_where_someone_watches(monkeypatch, forced, tty, want):
    monkeypatch.setenv(ENV, forced)
    assert enabled(_Tty() if tty else io.StringIO()) is want


def test_a_library_call_without_progress_draws_nothing(monkeypatch, capsys):
    monkeypatch.setenv(ENV, "1")
    with bar(3, "parts", "family", show=False) as b:
        for _ in range(3):
            b.update()
    assert capsys.readouterr().err == ""


def _solve(tmp_path, env_value: str | None) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k != ENV}
    if env_value is not None:
        env[ENV] = env_value
    out = tmp_path / f"solved_{env_value}.toml"
    return subprocess.run([sys.executable, "-m", "swiftfin", "solve", str(ROOT / "swiftfin.toml"), "--out", str(out),
                           "--front-samples", "256"], capture_output=True, text=True, env=env, cwd=tmp_path,
                          timeout=600)


def test_solve_draws_the_fronts_rounds_only_when_asked(tmp_path):
    piped = _solve(tmp_path, None)
    forced = _solve(tmp_path, "1")
    assert piped.returncode == forced.returncode == 0, piped.stderr + forced.stderr
    assert "Pareto front: 100%" in forced.stderr and "8/8" in forced.stderr, forced.stderr
    assert "\r" not in piped.stderr and "%|" not in piped.stderr, piped.stderr
    # the same lines either way: the bar adds, it never replaces
    lines = [ln for ln in piped.stderr.splitlines() if ln.strip()]
    assert lines and all(ln.split("] ", 1)[-1] in forced.stderr for ln in lines)
    def body(out: str, name: str) -> list[str]:          # the first line gives the search's wall time
        return out.replace(str(tmp_path / name), "OUT").splitlines()[1:]
    assert body(piped.stdout, "solved_None.toml") == body(forced.stdout, "solved_1.toml")
