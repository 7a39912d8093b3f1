"""The hydraulic mount (fmu_src/models/hydraulic_model.py): its data sheet against the closed form, and
the default set's data sheet drawn for the docs.

    python benchmarks/bench_hydraulic_mount.py [--figure docs/img/hydraulic_data_sheet.png]
                                              [--recovery membrane|free ...] [--speed] [--workers N]

1. Closed form (issue 43's target: ``characterise`` within 1e-4 in |K*| and 0.01 deg of K*(omega)
   over 0.5-100 Hz): the default set without its decoupler and turbulent term (gap = 0, ct = 0),
   1 mm, 25 frequencies from 0.5 to 100 Hz, against the closed form typed in
   ``tests/references/hydraulic_closed_form.py`` (numpy only). Prints the largest differences.
2. The default set's data sheet over 0.05-2 mm x 1-50 Hz: printed (|K*| [N/mm] and loss angle
   [deg] per amplitude) and drawn, with the closed form beside it.
3. ``--recovery membrane`` and ``--recovery free`` (issue 49's targets: the recommended model
   predicts the unseen amplitudes within 3 % in |K*| and 2 deg): ``compare --kdyn`` every model
   on a synthetic mount's training sheet (0.1, 0.5, 2 mm x 1-50 Hz, 1 % and 0.2 deg noise) with its
   1 mm / 8 Hz sine (3 N noise), then each fitted model's sheet at the unseen 0.3 and 1 mm against
   the truth's (``kdyn_synthetic_*_unseen.csv``): the largest |K*| and loss-angle errors per model.
   The membrane mount is data/generate_hydraulic.py's, the free-play mount
   data/generate_hydraulic_free_decoupler.py's. Also the fit of the mount's own model alone from
   the table alone and from the table with the sine, timed (target: <= 90 s on 2 cores).
4. ``--speed`` (target: the native step <= 1 us): the native FMU of the default set in the plain C
   master of ``bench_fmu_step.py`` (2 mm / 10 Hz sine, 1 ms steps; a larger amplitude than the
   target's 1 mm, so a harder case for the track's substeps), against the trivial native FMU.
"""
from __future__ import annotations

import argparse
import importlib.util
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]

from fmu_src.parameter_files import load_parameters  # noqa: E402
from identification.forward.dynamic_stiffness import characterise  # noqa: E402
import harness  # noqa: E402

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


MOUNTS = {
    # --recovery NAME: (the data's prefix, the model that describes it)
    "membrane": ("hydraulic", "hydraulic"),
    "free": ("free_decoupler", "hydraulic_free_decoupler"),
}
"""The synthetic mounts: data/generate_hydraulic.py's membrane mount (the hydraulic model's own
data) and data/generate_hydraulic_free_decoupler.py's free-play mount (scipy's, not a model's)."""


def recovery(workers: int, mount: str) -> None:
    import json
    import tempfile
    data = REPO / "data"
    prefix, own_model = MOUNTS[mount]
    train, sine = data / f"kdyn_synthetic_{prefix}_train.csv", data / f"synthetic_{prefix}_sine_1mm_8Hz.csv"
    from identification.measured.kdyn_table import load_kdyn_table
    unseen = load_kdyn_table(data / f"kdyn_synthetic_{prefix}_unseen.csv")
    print(f"recovery on the synthetic {mount} mount ({train.name}, {sine.name})")
    with tempfile.TemporaryDirectory() as work:
        work = Path(work)
        for name, extra in (("table alone", []), ("table and the sine", ["--sine", str(sine)])):
            started = time.perf_counter()
            subprocess.run([sys.executable, "-m", "identification", "fit", "--model", own_model, "--kdyn", str(train),
                            *extra, "--workers", str(workers), "--quiet", "--out", str(work / "fit.json")],
                           check=True, cwd=REPO, capture_output=True)
            print(f"fit of the {own_model} model from the {name}: {time.perf_counter() - started:.0f} s wall "
                  f"({workers} workers; target from a table and a sine <= 90 s)")
        started = time.perf_counter()
        run = subprocess.run([sys.executable, "-m", "identification", "compare", "--kdyn", str(train), "--sine",
                              str(sine), "--workers", str(workers), "--out", str(work / "compare")],
                             cwd=REPO, capture_output=True, text=True, check=True)
        recommended = run.stdout.strip().splitlines()[-1].split()[-1]
        print(f"compare --kdyn (every model, {time.perf_counter() - started:.0f} s): recommended {recommended}")
        print("  model             unseen 0.3 and 1 mm: largest |K*| error   loss angle error   training at floor")
        rows = []
        for params_file in sorted((work / "compare").glob("params_*.json")):
            saved = json.loads(params_file.read_text())
            model = params_file.stem[len("params_"):]
            sheet = characterise(saved["parameters"], amplitudes_mm=(0.3, 1.0),
                                 frequencies_hz=np.unique(unseen.frequency_hz), model=model)
            order = np.lexsort((sheet.frequency_hz, sheet.amplitude_mm))
            truth = np.lexsort((unseen.frequency_hz, unseen.amplitude_mm))
            kdyn = np.max(np.abs(sheet.kdyn_N_per_mm[order] / unseen.kdyn_N_per_mm[truth] - 1.0))
            angle = np.max(np.abs(sheet.loss_angle_deg[order] - unseen.loss_angle_deg[truth]))
            rows.append((model, kdyn, angle))
        floors = {}
        with open(work / "compare" / "comparison.csv") as handle:
            import csv
            for row in csv.DictReader(handle):
                floors[row["model"]] = row["at_floor"]
        for model, kdyn, angle in sorted(rows, key=lambda r: r[1]):
            mark = "  <- recommended" if model == recommended else ""
            print(f"  {model:17s} {kdyn:36.2%} {angle:15.2f} deg {floors.get(model, '?'):>12s}{mark}")
        print("  target for the recommended model: 3 % and 2 deg (issue 49)")


def speed() -> None:
    import statistics
    import tempfile

    import build_fmu
    from bench_fmu_step import _c_master
    from fmu_src.fmi.native.build import fmi_header_directory
    from fmu_src.parameter_files import save_parameters
    with tempfile.TemporaryDirectory() as work:
        work = Path(work)
        gain = save_parameters(work / "gain.json", {"k": 0.002, "c": 0.0, "preload": 0.0}, "kelvin_voigt")
        fmus = {"trivial": build_fmu.build_native_fmu(gain, work / "a", "kelvin_voigt").path,
                "hydraulic": build_fmu.build_native_fmu(out_dir=work / "b", model="hydraulic").path}
        master = work / "c_master_timing"
        subprocess.run(["cc", "-O2", "-std=c99", "-I", str(fmi_header_directory()), "-o", str(master),
                        str(REPO / "benchmarks" / "c_master_timing.c"), "-ldl", "-lm"], check=True)
        times = {key: [] for key in fmus}
        for _ in range(5):
            for key, fmu in fmus.items():
                times[key] += _c_master(master, fmu, work / key, 100000, 1)
        median = {key: statistics.median(values) for key, values in times.items()}
        print(f"native step in the C master (2 mm / 10 Hz, 1 ms steps, median of 5 runs of 1e5 steps): hydraulic "
              f"{median['hydraulic'] * 1e6:.3f} us, trivial native FMU {median['trivial'] * 1e6:.3f} us (target <= 1 us)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--figure", type=Path, default=REPO / "docs" / "img" / "hydraulic_data_sheet.png")
    parser.add_argument("--recovery", choices=sorted(MOUNTS), action="append", default=[],
                        help="compare --kdyn on a synthetic mount, membrane or free (minutes; repeatable)")
    parser.add_argument("--speed", action="store_true", help="the native FMU's step in a C master")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    print(harness.provenance())
    params = load_parameters(REPO / "data" / "params_hydraulic_mount.json", "hydraulic")
    closed_form_check(params)
    data_sheet(params, args.figure)
    if args.speed:
        speed()
    for mount in args.recovery:
        recovery(args.workers, mount)


if __name__ == "__main__":
    main()
