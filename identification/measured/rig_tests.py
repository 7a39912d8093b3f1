"""The training tests of a fit: which measurement is which kind of rig test, and the manifest.

A fit compares the model with every sample of every test, so the kind (``sine``, ``step``,
``random``) does not change the objective; it labels the test in reports, and a step test
carries its rise time (the end of its ramp, after which it holds for as long as its file
says), which the report uses for the paper's eq. 7 errors.

Manifest (``tests.json``), paths relative to the manifest's folder::

    {"sine": ["a.csv", ...],
     "step": [{"file": "b.csv", "rise_time_s": 0.4}, ...],
     "random": ["c.csv"],
     "model": "proposed"}                      # optional

Every problem is a ``ManifestError`` (a ``MeasurementError``) naming the file and what is
allowed.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

from identification.errors import ManifestError  # noqa: F401  (also imported from here)
from identification.measured.measurements import Measurement, load_measurement

KINDS = ("sine", "step", "random")


@dataclass(frozen=True)
class RigTest:
    measurement: Measurement
    kind: str = "random"
    rise_time_s: float | None = None   # step tests: the ramp's duration [s]

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ManifestError(f"unknown test kind {self.kind!r} for {self.measurement.source}; "
                                f"allowed: {', '.join(KINDS)}")
        if self.kind == "step":
            check_rise_time(self.rise_time_s, self.measurement)
        elif self.rise_time_s is not None:
            raise ManifestError(f"{self.measurement.source}: only step tests have a rise time")

    @property
    def name(self) -> str:
        return Path(self.measurement.source).name if self.measurement.source else self.kind


def check_rise_time(rise_time_s, measurement: Measurement) -> None:
    t = measurement.time_s
    if not isinstance(rise_time_s, (int, float)) or isinstance(rise_time_s, bool) or not math.isfinite(rise_time_s):
        raise ManifestError(f"{measurement.source}: the step's rise time {rise_time_s!r} must be a number "
                            "of seconds")
    if not 0.0 < rise_time_s < t[-1] - t[0]:
        raise ManifestError(f"{measurement.source}: rise time {rise_time_s:g} s must be > 0 s and shorter than "
                            f"the test ({t[-1] - t[0]:g} s)")


def training_tests(sine: Sequence = (), step: Sequence = (), rise_times_s: Sequence[float] = (),
                   random: Sequence = ()) -> list[RigTest]:
    """The training tests of a fit, from files or measurements of each kind.

    Parameters
    ----------
    sine : sequence of str, Path or Measurement
        Sine tests (CSV ``time_s,displacement_mm,force_N[,velocity_mm_s]``, see ``load_measurement``).
    step : sequence of str, Path or Measurement
        Step tests: a ramp, then held.
    rise_times_s : sequence of float
        The ramp's duration [s] of each step test, in the same order (as the command line's
        repeated ``--step`` and ``--rise-time``).
    random : sequence of str, Path or Measurement
        Random-input tests.

    Returns
    -------
    list of RigTest
        What ``fit`` takes.

    Raises
    ------
    ManifestError
        No tests, a rise time per step missing, or a rise time not shorter than its test.
    MeasurementError
        A file that cannot be read as a measurement.
    """
    if len(step) != len(rise_times_s):
        raise ManifestError(f"{len(step)} step test(s) but {len(rise_times_s)} rise time(s): give one "
                            "--rise-time per --step, in the same order")
    tests = [RigTest(_measurement(item), "sine") for item in sine]
    tests += [RigTest(_measurement(item), "step", rise) for item, rise in zip(step, rise_times_s)]
    tests += [RigTest(_measurement(item), "random") for item in random]
    if not tests:
        raise ManifestError("no training tests: give at least one --sine, --step or --random file (or --tests)")
    return tests


@dataclass(frozen=True)
class Manifest:
    tests: list[RigTest]
    model: str | None
    path: Path


def load_manifest(path: str | Path) -> Manifest:
    """Read a ``tests.json`` (see the module docstring)."""
    path = Path(path)
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ManifestError(f"tests manifest {path} does not exist") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise ManifestError(f"{path}: not valid JSON ({exc})") from None
    except OSError as exc:
        raise ManifestError(f"{path}: cannot be read ({exc.strerror})") from None
    if not isinstance(document, dict):
        raise ManifestError(f"{path}: expected a JSON object with keys {', '.join(KINDS)} and optional model")
    unknown = sorted(set(document) - {*KINDS, "model"})
    if unknown:
        raise ManifestError(f"{path}: unknown keys {unknown}; allowed: {', '.join(KINDS)}, model")
    folder = path.parent
    files = {kind: document.get(kind, []) for kind in KINDS}
    for kind, entries in files.items():
        if not isinstance(entries, list):
            raise ManifestError(f"{path}: {kind!r} must be a list")
    steps, rise_times = [], []
    for entry in files["step"]:
        if not (isinstance(entry, dict) and set(entry) == {"file", "rise_time_s"} and isinstance(entry["file"], str)):
            raise ManifestError(f"{path}: each step must be {{\"file\": ..., \"rise_time_s\": ...}}, got {entry!r}")
        steps.append(folder / entry["file"])
        rise_times.append(entry["rise_time_s"])
    for kind in ("sine", "random"):
        for entry in files[kind]:
            if not isinstance(entry, str):
                raise ManifestError(f"{path}: each {kind} test must be a file name, got {entry!r}")
    model = document.get("model")
    if model is not None and not isinstance(model, str):
        raise ManifestError(f"{path}: model must be a model name, got {model!r}")
    tests = training_tests([folder / f for f in files["sine"]], steps, rise_times,
                           [folder / f for f in files["random"]])
    return Manifest(tests, model, path)


def _measurement(item) -> Measurement:
    return item if isinstance(item, Measurement) else load_measurement(item)
