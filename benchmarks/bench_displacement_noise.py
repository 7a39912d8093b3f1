"""What raw displacement noise does to a Bouc-Wen model: the paper's step test (2 mm, 0.4 s rise,
held to 10 s) with Table 5, fed the commanded displacement, and fed it with white noise added
(rms 0.5, 1 and 2 um at 1 kHz) and the finite-difference velocity of the noisy samples.

    python benchmarks/bench_displacement_noise.py [--seed 0]

Prints the held force's relaxation, (F(0.4 s) - F(10 s)) / F(0.4 s), each force the mean over
the 50 ms after 0.4 s and before 10 s: the noise makes the Bouc-Wen blocks cycle and the held
force shake down (why data/'s synthetic files carry the commanded displacement and put the noise
on the force; docs/data.md).
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]

from fmu_src.parameter_files import load_parameters  # noqa: E402
from identification.measured.signals import Step, sample_times  # noqa: E402
from identification.forward.simulate import simulate  # noqa: E402
import harness  # noqa: E402

RATE_HZ = 1000.0
WINDOW_S = 0.05


def relaxation(t, force):
    held = force[(t >= 0.4) & (t < 0.4 + WINDOW_S)].mean()
    end = force[t >= 10.0 - WINDOW_S].mean()
    return (held - end) / held


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    params = load_parameters(REPO / "data" / "params_table5_combined.json")
    t = sample_times(10.0, RATE_HZ)
    x, v = Step(2.0, 0.4, 10.0).signals(t)
    print(harness.provenance())
    print(f"{'displacement noise (rms)':26s} {'relaxation over 10 s':>22s}")
    print(f"{'none (commanded x, v)':26s} {relaxation(t, simulate(params, t, x, v)):22.1%}")
    rng = np.random.default_rng(args.seed)
    for rms_um in (0.5, 1.0, 2.0):
        noisy = x + rng.normal(0.0, rms_um * 1e-3, size=x.size)
        velocity = np.gradient(noisy, t)
        print(f"{f'{rms_um:g} um, finite-difference v':26s} {relaxation(t, simulate(params, t, noisy, velocity)):22.1%}")


if __name__ == "__main__":
    main()
