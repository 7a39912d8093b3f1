"""Generate the SYNTHETIC free-play hydraulic-mount files in data/ (not real test-rig data).

    python data/generate_hydraulic_free_decoupler.py [--seed N] [--out-dir DIR] [--workers N]

Truth: a hydraulic engine mount with a free decoupler plate and a hard cage (TRUTH below: a
progressive rubber path with a Maxwell element, a bulge spring, a fluid column with linear and
turbulent track damping tuned to 9.3 Hz, a plate free within +-0.12 mm), solved by scipy's Radau
on the equations typed in ``tests/references/free_decoupler_mount.py`` (numpy and scipy only:
the plate's balance by brentq, not the model's closed form). It is not the project's model: the
hard cage is a corner the model only rounds, and nothing of ``fmu_src`` computes these numbers.

Files (prefix ``synthetic_free_decoupler``), the data of issue 49's recovery test, as issue 43's:

- ``kdyn_synthetic_free_decoupler_train.csv``: the data sheet a supplier would give, over 0.1,
  0.5 and 2 mm x 12 frequencies from 1 to 50 Hz (the steady sine's first harmonic), with seeded
  noise of 1 % on |K*| (relative, normal) and 0.2 deg on the loss angle (normal);
- ``kdyn_synthetic_free_decoupler_unseen.csv``: the truth's sheet at 0.3 and 1 mm, same
  frequencies, no noise: what a fit must predict;
- ``synthetic_free_decoupler_sine_1mm_8Hz.csv``: a 1 mm / 8 Hz sine from rest, 2 s sampled at
  1 kHz, force with 3 N rms seeded white noise.

About six and a half minutes on two cores (2026-11-27).
"""
from __future__ import annotations

import argparse
import importlib.util
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
from identification.measured.kdyn_table import write_kdyn_table  # noqa: E402
from identification.measured.measurements import write_measurement  # noqa: E402

_spec = importlib.util.spec_from_file_location(
    "free_decoupler_mount", HERE.parent / "tests" / "references" / "free_decoupler_mount.py")
mount = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(mount)

TRUTH = {"k0": 180.0, "k3": 25.0, "c0": 0.08, "k1": 50.0, "c1": 0.6, "kb": 280.0, "kc": 30.0, "mf": 0.09,
         "cf": 1.6, "ct": 0.004, "gap": 0.12, "width": 0.0, "kcage": 3000.0, "kd": 6.0}
"""N-mm-s: k [N/mm], k3 [N/mm^3], c [N.s/mm], mf [N.s^2/mm], ct [N.s^2/mm^2], gap and width [mm].
The track's resonance with the plate caged: sqrt((kb + kc)/mf)/(2*pi) = 9.34 Hz."""
TRAINING_AMPLITUDES_MM = (0.1, 0.5, 2.0)
UNSEEN_AMPLITUDES_MM = (0.3, 1.0)
FREQUENCIES_HZ = (1.0, 2.0, 3.0, 5.0, 7.0, 8.0, 9.0, 10.0, 12.0, 15.0, 25.0, 50.0)
KDYN_NOISE = 0.01
ANGLE_NOISE_DEG = 0.2
SINE_MM, SINE_HZ, SINE_S = 1.0, 8.0, 2.0
SAMPLE_RATE_HZ = 1000.0
FORCE_NOISE_N = 3.0
SETTLE_S = 6.0
"""Radau's settling before the cycle that is read: 18 of the column's slowest time constants
inside the gap, cf*K/((kb + kc)*kd) = 0.33 s."""
DESCRIPTION = ("a hydraulic mount with a free decoupler plate (+-0.12 mm, hard cage) and progressive rubber, "
               "solved by scipy Radau on tests/references/free_decoupler_mount.py")


def _stiffness(case):
    amplitude, frequency = case
    return mount.steady_stiffness(TRUTH, amplitude, frequency, settle_s=SETTLE_S)


def _sheet(amplitudes, workers):
    cases = [(a, f) for a in amplitudes for f in FREQUENCIES_HZ]
    with ProcessPoolExecutor(workers) as pool:
        stiffness = np.array(list(pool.map(_stiffness, cases)))
    amplitude, frequency = (np.array(column) for column in zip(*cases))
    return amplitude, frequency, np.abs(stiffness), np.degrees(np.angle(stiffness))


def sine_force(t):
    """The truth's force [N] at times t [s] on SINE_MM * sin(2*pi*SINE_HZ*t) from rest (Radau)."""
    omega = 2.0 * np.pi * SINE_HZ

    def signal(s):
        return SINE_MM * np.sin(omega * s), SINE_MM * omega * np.cos(omega * s)
    solution = solve_ivp(mount.rhs, (0.0, t[-1]), mount.start(TRUTH, 0.0), method="Radau", t_eval=t,
                         args=(TRUTH, signal), rtol=mount.RTOL, atol=np.array(mount.ATOL), max_step=1e-3)
    x, xd = signal(t)
    return x, mount.force(TRUTH, solution.y, x, xd)


def generate(seed: int, out_dir: Path, workers: int) -> list[Path]:
    rng = np.random.default_rng(seed)
    written = []
    amplitude, frequency, kdyn, angle = _sheet(TRAINING_AMPLITUDES_MM, workers)
    noisy_kdyn = kdyn * (1.0 + rng.normal(0.0, KDYN_NOISE, kdyn.size))
    noisy_angle = angle + rng.normal(0.0, ANGLE_NOISE_DEG, angle.size)
    written.append(write_kdyn_table(
        out_dir / "kdyn_synthetic_free_decoupler_train.csv",
        {"amplitude_mm": amplitude, "frequency_hz": frequency, "kdyn_N_per_mm": noisy_kdyn,
         "loss_angle_deg": noisy_angle},
        [f"SYNTHETIC: the data sheet of {DESCRIPTION}, not measured (data/generate_hydraulic_free_decoupler.py).",
         f"Steady sines (first harmonic after {SETTLE_S:g} s); noise (seed {seed}): {KDYN_NOISE:.0%} on |K*|, "
         f"{ANGLE_NOISE_DEG:g} deg on the loss angle, normal."]))
    amplitude, frequency, kdyn, angle = _sheet(UNSEEN_AMPLITUDES_MM, workers)
    written.append(write_kdyn_table(
        out_dir / "kdyn_synthetic_free_decoupler_unseen.csv",
        {"amplitude_mm": amplitude, "frequency_hz": frequency, "kdyn_N_per_mm": kdyn, "loss_angle_deg": angle},
        [f"SYNTHETIC: the data sheet of {DESCRIPTION} at the amplitudes the training table leaves out, not measured "
         "(data/generate_hydraulic_free_decoupler.py).",
         f"Steady sines (first harmonic after {SETTLE_S:g} s); no noise."]))
    t = np.arange(round(SINE_S * SAMPLE_RATE_HZ) + 1) / SAMPLE_RATE_HZ
    x, force = sine_force(t)
    path = out_dir / "synthetic_free_decoupler_sine_1mm_8Hz.csv"
    write_measurement(path, t, x, force + rng.normal(0.0, FORCE_NOISE_N, t.size), comments=[
        "SYNTHETIC DATA - not a measurement of a real bushing.",
        f"Generated by data/generate_hydraulic_free_decoupler.py: {DESCRIPTION}; "
        f"sine {SINE_MM:g} mm, {SINE_HZ:g} Hz, {SINE_S:g} s from rest.",
        f"Displacement: commanded signal. Force noise (seed {seed}): {FORCE_NOISE_N:g} N rms, white.",
    ])
    written.append(path)
    return written


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=2049)
    parser.add_argument("--out-dir", type=Path, default=HERE)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    for path in generate(args.seed, args.out_dir, args.workers):
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
