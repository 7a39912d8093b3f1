"""What every benchmark prints before its figures, and how it times them: one harness.

- :func:`provenance`: one line saying where a figure comes from: the date and time (UTC), the
  machine (CPU, cores), Python, the commit (and whether the tree had uncommitted changes) and
  the command as typed, so that a figure pasted into ``docs/benchmarks.md`` carries it;
- :func:`timed`: a function's result and the wall time of each of its calls [s];
- ``REPO``: the repository the benchmarks belong to.

A benchmark imports the project as installed (``pip install -e .``) and this module beside it.
"""
from __future__ import annotations

import os
import platform
import subprocess
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def commit() -> str:
    """The short commit of the repository, '+ changes' where the tree differs from it ('unknown'
    outside a git checkout)."""
    run = lambda *arguments: subprocess.run(["git", "-C", str(REPO), *arguments], capture_output=True,  # noqa: E731
                                            text=True, check=False)
    head = run("rev-parse", "--short", "HEAD")
    if head.returncode != 0:
        return "unknown"
    dirty = run("status", "--porcelain", "--untracked-files=no").stdout.strip()
    return head.stdout.strip() + (" + changes" if dirty else "")


def provenance() -> str:
    """'2026-11-28 21:30 UTC, x86_64, 2 cores, Python 3.11.7, commit abc1234: python
    benchmarks/bench_x.py --seed 0'."""
    script = Path(sys.argv[0]).resolve()
    shown = script.relative_to(REPO) if script.is_relative_to(REPO) else script
    command = " ".join(["python", str(shown), *sys.argv[1:]])
    return (f"{datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC, {platform.machine()}, {os.cpu_count()} cores, "
            f"Python {platform.python_version()}, commit {commit()}: {command}")


def timed(function, repeats: int = 1):
    """(the last call's result, [the wall time of each of ``repeats`` calls, s])."""
    times, result = [], None
    for _ in range(repeats):
        started = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - started)
    return result, times
