"""A new device's first contact (issue 63): `compare` with no option named on the shipped Table 5
sine and step as they are and read through a one-sided stroke (+2 mm) and a load cell off by
+100 N, side by side.

    python benchmarks/bench_first_contact.py [--models LIST] [--workers N] [--keep DIR]

The shifted copies keep the files' names (in a folder of their own), so the two comparisons' rows
pair up. Each comparison is `bushing-identify compare --sine SINE --step STEP --rise-time 0.4
--no-ensemble` with the default models and preset. Prints what the shifted comparison assumed,
both recommendations, and each model's training NRMSE on each file in both (the model of the
shifted files named with the options it assumed beside it; the issue's target: the same
recommendation, each within 0.5 points), and both wall times.
"""
from __future__ import annotations

import argparse
import contextlib
import csv
import io
import tempfile
import time
from pathlib import Path

import harness  # noqa: F401  (the repository on the path)

REPO = Path(__file__).resolve().parents[1]
SINE = REPO / "data" / "synthetic_table5_sine_2mm_10Hz.csv"
STEP = REPO / "data" / "synthetic_table5_step_2mm_rise0.4s.csv"
STROKE_MM, LOAD_CELL_N = 2.0, 100.0


def shifted(path: Path, folder: Path) -> Path:
    from identification.measured.measurements import load_measurement, write_measurement
    m = load_measurement(path)
    out = folder / path.name
    write_measurement(out, m.time_s, m.displacement_mm + STROKE_MM, m.force_N + LOAD_CELL_N,
                      comments=[f"data/{path.name} with +{STROKE_MM:g} mm of stroke and +{LOAD_CELL_N:g} N of load "
                                "cell zero (bench_first_contact.py)"])
    return out


def compare(sine: Path, step: Path, out: Path, models: str | None, workers: int) -> tuple[float, str]:
    from identification.cli.arguments import main
    argv = ["compare", "--sine", str(sine), "--step", str(step), "--rise-time", "0.4", "--no-ensemble", "--quiet",
            "--workers", str(workers), "--out", str(out)] + (["--models", models] if models else [])
    printed = io.StringIO()
    began = time.perf_counter()
    with contextlib.redirect_stdout(printed):
        assert main(argv) == 0
    return time.perf_counter() - began, printed.getvalue()


def rows(out: Path) -> tuple[dict, str]:
    """({(file, model): training NRMSE}, the recommended model) of a comparison's folder."""
    with open(out / "validation.csv") as handle:
        errors = {(row["file"], row["model"]): float(row["nrmse"]) for row in csv.DictReader(handle)}
    with open(out / "comparison.csv") as handle:
        recommended = next(row["model"] for row in csv.DictReader(handle) if row["recommended"] == "True")
    return errors, recommended


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--models", default=None, help="compare's --models (default: its own)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--keep", type=Path, default=None, help="write both comparisons here (default: a temporary folder)")
    args = parser.parse_args()
    import warnings
    warnings.simplefilter("ignore")
    with tempfile.TemporaryDirectory() as scratch:
        root = args.keep or Path(scratch)
        (root / "shifted_files").mkdir(parents=True, exist_ok=True)
        moved = [shifted(path, root / "shifted_files") for path in (SINE, STEP)]
        original_s, _ = compare(SINE, STEP, root / "original", args.models, args.workers)
        shifted_s, said = compare(*moved, root / "shifted", args.models, args.workers)
        print("\n".join(line for line in said.splitlines() if line.startswith("assumed")))
        original, original_pick = rows(root / "original")
        moved_errors, moved_pick = rows(root / "shifted")
        print(f"recommended: {original_pick} on the files as shipped, {moved_pick} on the shifted ones")
        for name in (SINE.name, STEP.name):
            print(f"\n{name}: training NRMSE as shipped / shifted (the shifted comparison's model), difference")
            for (file, model), error in sorted(original.items()):
                if file != name:
                    continue
                candidates = {m: e for (f, m), e in moved_errors.items() if f == name and m.split("+")[0] == model}
                for moved_model, moved_error in sorted(candidates.items()):
                    print(f"  {model:26s} {error:7.2%} / {moved_error:7.2%} ({moved_model}), "
                          f"{(moved_error - error) * 100:+.2f} points")
        print(f"\nwall time: {original_s:.0f} s as shipped, {shifted_s:.0f} s shifted")


if __name__ == "__main__":
    main()
