"""The comparison study (paper §3.1, §4.3, Figs. 15-17): fit several models on the same
training tests, compare them on validation files.

Writes into the output directory: ``params_<model>.json`` per model (with provenance),
``comparison.csv`` (NRMSE and the paper's eq. 10 error per validation file and model) and
one PNG per validation file overlaying the measured and predicted force over time and the
force-displacement loops. Prints the table.
"""
from __future__ import annotations

import csv
import sys
import warnings
from pathlib import Path
from typing import Sequence

from fmu_src.bushing_models import get_model
from identification.engine import make_engine
from identification.fitting import FitNotConvergedWarning, fit
from identification.measurements import load_measurement
from identification.objectives import nrmse, rms_level_error
from identification.rig_tests import RigTest
from identification.plots import plot_comparison
from identification.simulate import simulate


def compare_models(models: Sequence[str], tests: Sequence[RigTest], validation_files: Sequence[Path], out_dir: Path,
                   preset: str = "default", seed: int = 0, workers: int | None = None, scheduler=None,
                   screening: int | None = None, starts: int | None = None, ensemble: bool = True) -> dict:
    """Fit every model on ``tests``, evaluate it on every validation file; returns
    ``{"parameters": {model: params}, "errors": {(file, model): (nrmse, eq10)}}``."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    validation = [load_measurement(path) for path in validation_files]
    parameters = {}
    with make_engine(workers, scheduler) as engine, warnings.catch_warnings():
        warnings.simplefilter("ignore", FitNotConvergedWarning)   # reported below, per model
        for model in models:
            print(f"fitting {get_model(model).title} ...", file=sys.stderr)
            result = fit(tests, model=model, preset=preset, seed=seed, engine=engine, screening=screening,
                         starts=starts, ensemble=ensemble)
            result.save(out_dir / f"params_{model}.json", data=[t.measurement.source for t in tests])
            parameters[model] = result.parameters.parameters
            state = "converged" if result.converged else f"WARNING: {result.warning}"
            print(f"  misfit {result.misfit:.4f} in {result.seconds:.0f} s; {state}", file=sys.stderr)

    errors = {}
    for m in validation:
        name = Path(m.source).name
        predictions = {model: simulate(parameters[model], m.time_s, m.displacement_mm, m.measured_velocity_mm_s,
                                       model=model)
                       for model in models}
        for model, predicted in predictions.items():
            errors[name, model] = (nrmse(predicted, m.force_N), rms_level_error(predicted, m.force_N))
        plot_comparison(m, predictions, out_dir / f"compare_{Path(m.source).stem}.png")

    print(format_comparison(errors, models, [Path(m.source).name for m in validation]))
    with open(out_dir / "comparison.csv", "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(["file", "model", "nrmse", "eq10_rms_level_error"])
        for (name, model), (error, eq10) in errors.items():
            writer.writerow([name, model, f"{error:.6g}", f"{eq10:.6g}"])
    print(f"wrote {out_dir}/comparison.csv, params_<model>.json and compare_*.png", file=sys.stderr)
    return {"parameters": parameters, "errors": errors}


def format_comparison(errors: dict, models: Sequence[str], files: Sequence[str]) -> str:
    """NRMSE per file (rows) and model (columns), the eq. 10 error in brackets."""
    width = max(len(name) for name in files) + 2
    lines = [f"{'file':{width}s}" + "".join(f"{model:>22s}" for model in models)]
    for name in files:
        cells = "".join(f"{errors[name, model][0]:>12.2%} ({errors[name, model][1]:+6.1%})" for model in models)
        lines.append(f"{name:{width}s}{cells}")
    lines.append("NRMSE = rms(F_pre - F_exp)/rms(F_exp); (eq. 10) = (rms F_exp - rms F_pre)/rms F_exp")
    return "\n".join(lines)
