"""Command line: ``python -m identification fit ...`` (see ``--help``)."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from fmu_src.bushing_models import MODEL_NAMES
from fmu_src.bushing_params import ParameterError
from fmu_src.parameter_files import read_parameter_set, save_parameters
from identification.measurements import MeasurementError, load_measurement


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m identification",
                                     description="Identify the bushing model's parameters from measured tests.")
    commands = parser.add_subparsers(dest="command", required=True)
    fit_parser = commands.add_parser("fit", help="fit a model's parameters to sine (and step, random) tests")
    fit_parser.add_argument("--model", default="proposed", choices=MODEL_NAMES,
                            help="proposed (the paper's 16 parameters, default), spencer, bouc_wen or "
                                 "kelvin_voigt (linear least squares)")
    _add_training_arguments(fit_parser)
    fit_parser.add_argument("--random", action="append", type=Path, default=[], metavar="FILE",
                            help="random-input test CSV; repeatable")
    fit_parser.add_argument("--preset", default="default", choices=["default", "paper"],
                            help="default: differential evolution (about 21,000 evaluations); paper: the "
                                 "paper's GA, population 300 x 200 generations")
    fit_parser.add_argument("--seed", type=int, default=0)
    fit_parser.add_argument("--popsize", type=int,
                            help="override the preset's population (default preset: a multiplier of 14)")
    fit_parser.add_argument("--maxiter", type=int, help="override the preset's number of generations")
    fit_parser.add_argument("--out", type=Path, required=True, help="parameter file to write (JSON)")
    fit_parser.add_argument("--ssv", type=Path, help="also write an SSP 1.0 ParameterValues file")

    sensitivity_parser = commands.add_parser(
        "sensitivity", help="rank the 16 parameters by local sensitivity (paper Tables 1 and 3)")
    sensitivity_parser.add_argument("--params", type=Path, required=True, help="parameter file (.json or .ssv)")
    sensitivity_parser.add_argument("--delta", type=float, default=0.1, help="relative change (default 0.1)")
    sensitivity_parser.add_argument("--csv", type=Path, help="also write the table as CSV")

    report_parser = commands.add_parser("report", help="verification report: error tables and plots (paper §5)")
    report_parser.add_argument("--params", type=Path, required=True, help="parameter file (.json or .ssv)")
    report_parser.add_argument("--data", action="append", type=Path, default=[], metavar="FILE",
                               help="measured test CSV to compare with; repeatable")
    report_parser.add_argument("--truth", type=Path,
                               help="parameter file of the true model: adds the §5 grid of synthetic cases")
    report_parser.add_argument("--kelvin-voigt-train", action="append", type=Path, default=[], metavar="FILE",
                               help="fit F = k*x + c*v on these files and show it beside the model")
    report_parser.add_argument("--plots", type=Path, help="directory for force-time/force-displacement PNGs")

    compare_parser = commands.add_parser(
        "compare", help="fit several models on training tests and compare them on validation files")
    _add_training_arguments(compare_parser)
    compare_parser.add_argument("--validate", action="append", type=Path, default=[], metavar="FILE",
                                help="validation test CSV; repeatable")
    compare_parser.add_argument("--models", default=",".join(MODEL_NAMES),
                                help=f"comma-separated models (default: {','.join(MODEL_NAMES)})")
    compare_parser.add_argument("--preset", default="default", choices=["default", "paper"])
    compare_parser.add_argument("--seed", type=int, default=0)
    compare_parser.add_argument("--maxiter", type=int, help="override the preset's number of generations")
    compare_parser.add_argument("--out", type=Path, required=True,
                                help="directory for the fitted parameter files, the table (CSV) and the plots")

    args = parser.parse_args(argv)
    try:
        if args.command == "sensitivity":
            return _sensitivity(args)
        if args.command == "report":
            return _report(args)
        if args.command == "compare":
            return _compare(args)
        return _fit(args)
    except (MeasurementError, ParameterError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


def _add_training_arguments(parser) -> None:
    parser.add_argument("--sine", action="append", type=Path, required=True, metavar="FILE",
                        help="training sine test CSV (time_s,displacement_mm,force_N[,velocity_mm_s]); repeatable")
    parser.add_argument("--step", type=Path, metavar="FILE", help="training step test CSV")
    parser.add_argument("--rise-time", type=float, metavar="S", help="rise time of the step test [s]")


def _fit(args) -> int:
    from identification.fit import fit
    from identification.objectives import Objective, StepTest
    from identification.report import data_errors, format_data_errors

    if (args.step is None) != (args.rise_time is None):
        raise ValueError("--step and --rise-time go together")
    sines = [load_measurement(path) for path in args.sine]
    step = StepTest(load_measurement(args.step), args.rise_time) if args.step else None
    randoms = [load_measurement(path) for path in args.random]
    objective = Objective(sines, step, randoms)
    print(f"fitting the {args.model} model to {len(sines)} sine, {int(step is not None)} step and "
          f"{len(randoms)} random test(s) (numba compiles the model on first use)", file=sys.stderr)
    result = fit(objective, preset=args.preset, seed=args.seed, popsize=args.popsize, maxiter=args.maxiter,
                 model=args.model)

    provenance = result.provenance()
    provenance["data"] = [str(path) for path in [*args.sine, *([args.step] if args.step else []), *args.random]]
    save_parameters(args.out, result.parameters, args.model, provenance)
    if args.ssv:
        save_parameters(args.ssv, result.parameters, args.model)

    print(f"objective E3 = {result.objective:.4e}   ({', '.join(f'{k} {v:.3e}' for k, v in result.terms.items())})")
    tests = [*sines, *randoms, *([step.measurement] if step else [])]
    print(format_data_errors(data_errors(result.parameters, tests, model=args.model)))
    print(f"{result.evaluations} evaluations in {result.seconds:.1f} s; wrote {args.out}"
          + (f" and {args.ssv}" if args.ssv else ""))
    return 0


def _sensitivity(args) -> int:
    from fmu_src.parameter_files import load_parameters
    from identification.sensitivity import sensitivity
    table = sensitivity(load_parameters(args.params, model="proposed"), delta=args.delta)
    print(table.format())
    if args.csv:
        table.write_csv(args.csv)
        print(f"wrote {args.csv}")
    return 0


def _report(args) -> int:
    from identification.report import data_errors, format_data_errors, format_errors, grid_errors, plot_measurement
    from identification.search_space import KelvinVoigtFit
    parameter_set = read_parameter_set(args.params)
    params, model = parameter_set.parameters, parameter_set.model.name
    if not (args.data or args.truth):
        raise ValueError("give --data files and/or --truth to report on")
    kelvin_voigt = None
    if args.kelvin_voigt_train:
        kelvin_voigt = KelvinVoigtFit.fit([load_measurement(path) for path in args.kelvin_voigt_train])
        print(f"Kelvin-Voigt fit: k = {kelvin_voigt.k:.4g} N/mm, c = {kelvin_voigt.c:.4g} N*s/mm")
    if args.truth:
        print(f"Against the noise-free model of {args.truth} (paper §5 grid):")
        truth = read_parameter_set(args.truth)
        print(format_errors(grid_errors(params, truth.parameters, model, truth.model.name)))
    if args.data:
        measurements = [load_measurement(path) for path in args.data]
        print(format_data_errors(data_errors(params, measurements, kelvin_voigt, model)))
        if args.plots:
            for m in measurements:
                path = plot_measurement(params, m, args.plots / (Path(m.source).stem + ".png"), kelvin_voigt, model)
                print(f"wrote {path}")
    return 0


def _compare(args) -> int:
    from identification.compare import compare_models
    if (args.step is None) != (args.rise_time is None):
        raise ValueError("--step and --rise-time go together")
    models = [name.strip() for name in args.models.split(",") if name.strip()]
    unknown = [name for name in models if name not in MODEL_NAMES]
    if unknown:
        raise ValueError(f"unknown models {unknown}; choose from {', '.join(MODEL_NAMES)}")
    compare_models(models, args.sine, args.step, args.rise_time, args.validate or [*args.sine], args.out,
                   preset=args.preset, seed=args.seed, maxiter=args.maxiter)
    return 0


if __name__ == "__main__":
    sys.exit(main())
