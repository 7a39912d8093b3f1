"""A record at its own low rate (issue 63): every model's fit of the real friction damper's sines
resampled to 100 Hz, as a device tested on a 100 Hz rig gives them, timed warm.

    python benchmarks/bench_low_rate_fit.py [--models LIST] [--file NAME ...] [--workers N]

The shipped 0.5 Hz and 0.25 Hz, 1 in sines of ``data/brfd/`` (14 s and 28 s at 1024 Hz) are
interpolated linearly onto a 100 Hz grid (1400 and 2800 samples, 200 and 400 samples a cycle) and
written to a temporary folder. Each model is fitted twice in this process with the default preset and
no ensemble (``fit(..., ensemble=False)``): the first run compiles or loads its modules, the second
is the warm figure (the issue's target: <= 20 s each). Prints the model, the samples, both wall
times and the training NRMSE.
"""
from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

import harness  # noqa: F401  (the repository on the path)

REPO = Path(__file__).resolve().parents[1]
FILES = ("sine_0.5Hz30lbtension1amplitude", "sine_0.25Hz30lbtension1amplitude")
RATE_HZ = 100.0


def resampled(name: str, folder: Path) -> Path:
    from identification.measured.measurements import load_measurement, write_measurement
    m = load_measurement(REPO / "data" / "brfd" / f"{name}.csv.gz")
    t = np.arange(0.0, m.time_s[-1], 1.0 / RATE_HZ)
    path = folder / f"{name}_100Hz.csv"
    write_measurement(path, t, np.interp(t, m.time_s, m.displacement_mm), np.interp(t, m.time_s, m.force_N),
                      comments=[f"data/brfd/{name}.csv.gz interpolated linearly onto a {RATE_HZ:g} Hz grid"])
    return path


def main() -> None:
    from fmu_src.model.registry import MODEL_NAMES
    from identification import fit
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--models", default=",".join(MODEL_NAMES))
    parser.add_argument("--file", action="append", choices=FILES)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    import warnings
    warnings.simplefilter("ignore")
    with tempfile.TemporaryDirectory() as folder:
        for name in args.file or FILES:
            path = resampled(name, Path(folder))
            for model in args.models.split(","):
                walls = []
                for _ in range(2):
                    began = time.perf_counter()
                    result = fit([path], model=model, ensemble=False, progress=False, workers=args.workers)
                    walls.append(time.perf_counter() - began)
                nrmse = result.tests[0].nrmse
                print(f"{name} at 100 Hz ({result.residuals} samples), {model:26s}: first {walls[0]:6.1f} s, "
                      f"warm {walls[1]:6.1f} s, training NRMSE {nrmse:.2%}", flush=True)


if __name__ == "__main__":
    main()
