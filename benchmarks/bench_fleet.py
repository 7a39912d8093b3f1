"""Fleet throughput: bushings fitted per minute by ``fit-many`` on this machine.

    python benchmarks/bench_fleet.py [--bushings 6] [--workers N]

Makes a fleet of synthetic bushings (the paper's Tables 2, 4, 5, then Table 5 with four
parameters moved by 10-30 %, seeded), each with the paper's two training tests (sine
2 mm/10 Hz, step 2 mm/0.4 s held to 10 s) at 1 kHz with 1 % force noise and a tests.json, in a
temporary folder; fits them with ``identification.fitting.fleet.fit_many`` (default preset, one
bushing per worker) and prints the time, the bushings per minute and each bushing's verdict.
"""
from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]

from fmu_src.parameter_files import load_parameters  # noqa: E402
from identification.measured.measurements import write_measurement  # noqa: E402
from identification.measured.signals import Sine, Step, sample_times  # noqa: E402
from identification.forward.simulate import simulate  # noqa: E402
import harness  # noqa: E402


def bushings(count: int):
    files = ["params_table2_sine.json", "params_table4_step.json", "params_table5_combined.json"]
    out = [(Path(f).stem, load_parameters(REPO / "data" / f)) for f in files][:count]
    rng = np.random.default_rng(3)
    base = out[-1][1] if out else load_parameters(REPO / "data" / files[2])
    while len(out) < count:
        params = dict(base)
        for name in rng.choice(["k0", "k1", "c1", "c0", "A1", "A2", "n2", "k2"], 4, replace=False):
            params[name] *= 1.0 + rng.choice([-1.0, 1.0]) * rng.uniform(0.1, 0.3)
        out.append((f"table5_moved_{len(out) - 2}", params))
    return out


def write_fleet(folder: Path, count: int) -> None:
    rng = np.random.default_rng(11)
    for name, params in bushings(count):
        bushing = folder / name
        bushing.mkdir(parents=True)
        for kind, protocol in (("sine", Sine(2.0, 10.0, 1.0)), ("step", Step(2.0, 0.4, 10.0))):
            t = sample_times(protocol.duration_s, 1000.0)
            x, v = protocol.signals(t)
            force = simulate(params, t, x, v, steps_per_sample=16)
            force = force + rng.normal(0.0, 0.01 * np.sqrt(np.mean(force ** 2)), t.size)
            write_measurement(bushing / f"{kind}.csv", t, x, force, [f"SYNTHETIC: {name}, 1 % force noise"])
        (bushing / "tests.json").write_text(json.dumps({"sine": ["sine.csv"],
                                                       "step": [{"file": "step.csv", "rise_time_s": 0.4}]}))


def main() -> None:
    from identification.fitting.fleet import fit_many
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bushings", type=int, default=6)
    parser.add_argument("--workers", type=int, default=os.cpu_count())
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        fleet = Path(tmp) / "fleet"
        write_fleet(fleet, args.bushings)
        started = time.perf_counter()
        rows = fit_many(fleet, Path(tmp) / "out", workers=args.workers)
        seconds = time.perf_counter() - started
    print(f"{harness.provenance()}; {args.workers} workers")
    for row in rows:
        print(f"  {row.name:22s} misfit {row.misfit:.4f} {'converged' if row.converged else 'NOT converged'} "
              f"{row.seconds:6.1f} s{'  ' + row.error if row.error else ''}")
    print(f"{len(rows)} bushings in {seconds:.0f} s: {60 * len(rows) / seconds:.2f} bushings per minute")


if __name__ == "__main__":
    main()
