"""The hydraulic mount (fmu_src/hydraulic_model.py): its data sheet against the closed form, and
the default set's data sheet drawn for the docs.

    python benchmarks/bench_hydraulic_mount.py [--figure docs/img/hydraulic_data_sheet.png]

1. Closed form (issue 43's target: ``characterise`` within 1e-4 in |K*| and 0.01 deg of K*(omega)
   over 0.5-100 Hz): the default set without its decoupler and turbulent term (gap = 0, ct = 0),
   1 mm, 25 frequencies from 0.5 to 100 Hz, against the closed form typed in
   ``tests/references/hydraulic_closed_form.py`` (numpy only). Prints the largest differences.
2. The default set's data sheet over 0.05-2 mm x 1-50 Hz: printed (|K*| [N/mm] and loss angle
   [deg] per amplitude) and drawn, with the closed form beside it.
"""
from __future__ import annotations

import argparse
import importlib.util
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from fmu_src.parameter_files import load_parameters  # noqa: E402
from identification.dynamic_stiffness import characterise  # noqa: E402

_spec = importlib.util.spec_from_file_location("hydraulic_closed_form",
                                               REPO / "tests" / "references" / "hydraulic_closed_form.py")
closed_form = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(closed_form)

AMPLITUDES_MM = (0.05, 0.1, 0.3, 1.0, 2.0)
SHEET_FREQUENCIES_HZ = (1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 12.0, 14.0, 17.0, 20.0, 25.0, 30.0,
                        40.0, 50.0)


def closed_form_check(params) -> None:
    linear = dict(params, gap=0.0, ct=0.0)
    frequencies = np.geomspace(0.5, 100.0, 25)
    sheet = characterise(linear, amplitudes_mm=(1.0,), frequencies_hz=frequencies, model="hydraulic")
    expected = closed_form.complex_stiffness(linear, frequencies)
    kdyn = np.max(np.abs(sheet.kdyn_N_per_mm / np.abs(expected) - 1.0))
    angle = np.max(np.abs(sheet.loss_angle_deg - np.degrees(np.angle(expected))))
    print(f"closed form (gap = 0, ct = 0; 1 mm, {frequencies.size} frequencies 0.5-100 Hz, 256 steps a cycle): "
          f"largest |K*| difference {kdyn:.1e} (target 1e-4), loss angle {angle:.1e} deg (target 0.01 deg)")


def data_sheet(params, figure: Path | None) -> None:
    frequencies = np.array(SHEET_FREQUENCIES_HZ)
    sheet = characterise(params, amplitudes_mm=AMPLITUDES_MM, frequencies_hz=frequencies, model="hydraulic")
    print("default set's data sheet (|K*| N/mm / loss angle deg):")
    print("  f [Hz]   " + "".join(f"{a:>16g} mm" for a in AMPLITUDES_MM))
    for j, f in enumerate(frequencies):
        cells = []
        for a in AMPLITUDES_MM:
            row = np.flatnonzero((sheet.amplitude_mm == a) & (sheet.frequency_hz == f))[0]
            cells.append(f"{sheet.kdyn_N_per_mm[row]:10.1f} / {sheet.loss_angle_deg[row]:5.1f}")
        print(f"  {f:6g}   " + "".join(f"{c:>19s}" for c in cells))
    if figure is None:
        return
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fine = np.geomspace(1.0, 50.0, 200)
    linear = closed_form.complex_stiffness(dict(params, gap=0.0, ct=0.0), fine)
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7.0, 6.0), sharex=True)
    for a, colour in zip(AMPLITUDES_MM, plt.cm.viridis(np.linspace(0.0, 0.9, len(AMPLITUDES_MM)))):
        rows = sheet.amplitude_mm == a
        top.plot(frequencies, sheet.kdyn_N_per_mm[rows], "o-", color=colour, ms=3, label=f"{a:g} mm")
        bottom.plot(frequencies, sheet.loss_angle_deg[rows], "o-", color=colour, ms=3)
    top.plot(fine, np.abs(linear), "k--", lw=1, label="closed form (no decoupler, no turbulence)")
    bottom.plot(fine, np.degrees(np.angle(linear)), "k--", lw=1)
    top.set_ylabel("dynamic stiffness |K*| [N/mm]")
    bottom.set_ylabel("loss angle [deg]")
    bottom.set_xlabel("frequency [Hz]")
    bottom.set_xscale("log")
    top.legend(fontsize=8, ncol=2)
    top.set_title("hydraulic mount (data/params_hydraulic_mount.json): characterise")
    for axis in (top, bottom):
        axis.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    figure.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(figure, dpi=110)
    print(f"wrote {figure}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--figure", type=Path, default=REPO / "docs" / "img" / "hydraulic_data_sheet.png")
    args = parser.parse_args()
    commit = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    print(f"machine: {platform.machine()}, Python {platform.python_version()}; commit {commit}; "
          f"{time.strftime('%Y-%m-%d %H:%M')}")
    params = load_parameters(REPO / "data" / "params_hydraulic_mount.json", "hydraulic")
    closed_form_check(params)
    data_sheet(params, args.figure)


if __name__ == "__main__":
    main()
