"""Real records in minutes (issue 55, item 6): every model's fit of the real friction damper's
14 s, 1024 Hz sine, and the cost against the record's length.

    python benchmarks/bench_real_records.py [--models LIST] [--length-model NAME] [--no-ensemble]

Fits each model (default preset, seed 0, every core) to data/brfd/sine_0.5Hz30lbtension1amplitude
and prints its time and training NRMSE (target: <= 2 min each). Then fits ``--length-model``
(default asymmetric_bouc_wen) to the same record and to it four times over (its 14 s repeated,
57 s: the same test, four times the samples) and prints the ratio of their times (target: <= 4.5).
"""
from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]

from fmu_src.model.registry import MODEL_NAMES  # noqa: E402
from identification.errors import FitNotConvergedWarning  # noqa: E402
from identification.fitting.fit import fit  # noqa: E402
from identification.measured.measurements import Measurement, load_measurement  # noqa: E402
from identification.measured.rig_tests import RigTest  # noqa: E402
import harness  # noqa: E402

RECORD = REPO / "data" / "brfd" / "sine_0.5Hz30lbtension1amplitude.csv.gz"


def repeated(m: Measurement, times: int) -> Measurement:
    """The record ``times`` over, end to end (its time continued; it starts and ends near rest)."""
    step = float(np.median(np.diff(m.time_s)))
    span = m.time_s[-1] - m.time_s[0] + step
    t = np.concatenate([m.time_s + k * span for k in range(times)])
    tile = lambda a: np.concatenate([a] * times)  # noqa: E731
    return Measurement(t, tile(m.displacement_mm), tile(m.force_N), tile(m.velocity_mm_s), m.velocity_derived,
                       source=f"{Path(m.source).name} x{times}")


def timed_fit(measurement: Measurement, model: str, ensemble: bool):
    started = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FitNotConvergedWarning)
        result = fit([RigTest(measurement, kind="sine")], model=model, progress=False, ensemble=ensemble)
    return time.perf_counter() - started, result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--models", default=",".join(MODEL_NAMES))
    parser.add_argument("--length-model", default="asymmetric_bouc_wen")
    parser.add_argument("--no-ensemble", action="store_true")
    args = parser.parse_args()
    record = load_measurement(RECORD)
    ensemble = not args.no_ensemble
    print(harness.provenance())
    print(f"{RECORD.name}: {len(record)} samples, {record.time_s[-1]:.1f} s")
    print(f"{'model':26s} {'fit [s]':>8s} {'NRMSE':>8s}  (target <= 120 s)")
    for model in [name.strip() for name in args.models.split(",") if name.strip()]:
        seconds, result = timed_fit(record, model, ensemble)
        print(f"{model:26s} {seconds:8.1f} {result.tests[0].nrmse:8.2%}", flush=True)
    single, _ = timed_fit(record, args.length_model, ensemble)
    four, result = timed_fit(repeated(record, 4), args.length_model, ensemble)
    print(f"{args.length_model}: {single:.1f} s on the record, {four:.1f} s on it four times over "
          f"({len(record) * 4} samples): {four / single:.2f}x (target <= 4.5x); NRMSE {result.tests[0].nrmse:.2%}")


if __name__ == "__main__":
    main()
