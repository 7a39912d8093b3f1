"""Command line: ``python -m identification fit ...`` (see ``--help`` of each command)."""
from __future__ import annotations

import argparse
import os
import sys
import warnings
from pathlib import Path

import numpy as np

from fmu_src import __version__
from fmu_src.bushing_models import MODEL_NAMES
from fmu_src.bushing_params import ParameterError
from fmu_src.parameter_files import read_parameter_set
from identification.dynamic_stiffness import DEFAULT_AMPLITUDES_MM, DEFAULT_FREQUENCIES_HZ
from identification.engine import EngineError
from identification.errors import IdentificationError
from identification.measurements import load_measurement
from identification.rig_tests import load_manifest, training_tests


class UsageError(Exception):
    """A command-line option with a value that cannot be used."""


def positive_int(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value} is not allowed: give an integer >= 1")
    return value


def non_negative_int(text: str) -> int:
    value = int(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"{value} is not allowed: give an integer >= 0")
    return value


def positive_float(text: str) -> float:
    value = float(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"{value} is not allowed: give a number > 0")
    return value


def fraction(text: str) -> float:
    value = float(text)
    if not 0.0 < value < 1.0:
        raise argparse.ArgumentTypeError(f"{value} is not allowed: give a number between 0 and 1")
    return value


def number_list(text: str) -> list[float]:
    """'0.1,0.5,1' -> [0.1, 0.5, 1.0]."""
    try:
        return [float(part) for part in text.split(",") if part.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: give numbers separated by commas, e.g. 0.5,1,2") from None


def main(argv: list[str] | None = None) -> int:
    program = "bushing-identify" if Path(sys.argv[0]).name.startswith("bushing-identify") else "python -m identification"
    parser = argparse.ArgumentParser(prog=program,
                                     description="Identify the bushing model's parameters from measured tests.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    commands = parser.add_subparsers(dest="command", required=True)

    fit_parser = commands.add_parser("fit", help="fit a model's parameters to rig tests, with convergence evidence")
    fit_parser.add_argument("--model", choices=MODEL_NAMES,
                            help="proposed (the paper's 16 parameters, default), spencer, bouc_wen or "
                                 "kelvin_voigt (linear least squares); default: the manifest's, else proposed")
    _add_training_arguments(fit_parser)
    _add_search_arguments(fit_parser)
    fit_parser.add_argument("--out", type=Path, required=True, help="parameter file to write (JSON)")
    fit_parser.add_argument("--ssv", type=Path, help="also write an SSP 1.0 ParameterValues file")
    fit_parser.add_argument("--ensemble", type=Path,
                            help="also write the ensemble: every parameter set within the 95 %% confidence threshold")
    fit_parser.add_argument("--plots", type=Path, help="directory for the waterfall and the training tests' plots")

    sensitivity_parser = commands.add_parser(
        "sensitivity", help="rank the 16 parameters by local sensitivity (paper Tables 1 and 3)")
    sensitivity_parser.add_argument("--params", type=Path, required=True, help="parameter file (.json or .ssv)")
    sensitivity_parser.add_argument("--delta", type=fraction, default=0.1,
                                    help="relative change, 0 < delta < 1 (default 0.1)")
    sensitivity_parser.add_argument("--csv", type=Path, help="also write the table as CSV")

    report_parser = commands.add_parser("report", help="verification report: error tables and plots (paper §5)")
    report_parser.add_argument("--params", type=Path, required=True,
                               help="parameter file (.json or .ssv) or ensemble (then with its band)")
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
    _add_search_arguments(compare_parser)
    compare_parser.add_argument("--validate", action="append", type=Path, default=[], metavar="FILE",
                                help="validation test CSV; repeatable (default: the training files)")
    compare_parser.add_argument("--models", default=",".join(MODEL_NAMES),
                                help=f"comma-separated models (default: {','.join(MODEL_NAMES)})")
    compare_parser.add_argument("--out", type=Path, required=True,
                                help="directory for the fitted parameter files, the table (CSV) and the plots")

    predict_parser = commands.add_parser(
        "predict", help="simulate a parameter file or an ensemble on a test's displacement")
    predict_parser.add_argument("--params", type=Path, required=True,
                                help="parameter file (.json, .ssv) or ensemble file (fit --ensemble)")
    predict_parser.add_argument("--data", type=Path, required=True,
                                help="CSV with time_s and displacement_* columns (a force column is not needed)")
    predict_parser.add_argument("--out", type=Path, required=True,
                                help="CSV to write: time_s,displacement_mm,force_N[,force_min_N,force_max_N]")
    predict_parser.add_argument("--plot", type=Path, help="also plot the prediction (PNG)")

    design_parser = commands.add_parser("design", help="rank candidate next tests by how much the ensemble disagrees")
    design_parser.add_argument("--ensemble", type=Path, required=True, help="ensemble file (fit --ensemble)")
    design_parser.add_argument("--noise", type=positive_float, metavar="N",
                               help="noise level [N] to compare with (default: the training tests')")
    design_parser.add_argument("--top", type=positive_int, default=3, help="how many to recommend (default 3)")
    design_parser.add_argument("--json", action="store_true", help="print the ranking as JSON")

    fleet_parser = commands.add_parser("fit-many", help="fit a fleet: every sub-folder of DIR with a tests.json")
    fleet_parser.add_argument("folder", type=Path, metavar="DIR")
    fleet_parser.add_argument("--out", type=Path, required=True, help="directory for <name>.json and summary.csv")
    _add_search_arguments(fleet_parser)

    assemble_parser = commands.add_parser(
        "assemble", help="build a six-axis parameter file (SixAxisBushing) from one fit per axis")
    assemble_parser.add_argument("--axis", action="append", default=[], metavar="NAME=FILE",
                                 help="an axis (x, y, z, rx, ry, rz) and its one-axis parameter or fit file; "
                                      "repeat for each axis. Rotational axes (rx, ry, rz) read in N.mm, rad, s")
    assemble_parser.add_argument("--out", type=Path, required=True, help="six-axis file to write (.json or .ssv)")
    missing = assemble_parser.add_mutually_exclusive_group()
    missing.add_argument("--rigid-missing", action="store_true",
                         help="an axis without a file becomes a stiff Kelvin-Voigt spring")
    missing.add_argument("--default", type=Path, metavar="SIX.json",
                         help="an axis without a file takes its set from this six-axis file")

    characterise_parser = commands.add_parser(
        "characterise", help="dynamic stiffness |K*| and loss angle over amplitudes and frequencies (data sheet)")
    characterise_parser.add_argument("--params", type=Path, required=True,
                                     help="parameter file (.json, .ssv) or ensemble file (then with min/max columns)")
    characterise_parser.add_argument("--model", choices=MODEL_NAMES, help="check the file is for this model")
    characterise_parser.add_argument("--amplitudes-mm", type=number_list, metavar="LIST",
                                     default=",".join(map(str, DEFAULT_AMPLITUDES_MM)),
                                     help="sine amplitudes [mm], comma-separated (default %(default)s)")
    characterise_parser.add_argument("--frequencies-hz", type=number_list, metavar="LIST",
                                     default=",".join(map(str, DEFAULT_FREQUENCIES_HZ)),
                                     help="frequencies [Hz], comma-separated (default %(default)s)")
    characterise_parser.add_argument("--preload-mm", type=float, default=0.0, metavar="P",
                                     help="static displacement the sines are about [mm] (default 0)")
    characterise_parser.add_argument("--out", type=Path, required=True, help="table to write (CSV)")
    characterise_parser.add_argument("--plots", type=Path, help="directory for the data-sheet plots (PNG)")
    characterise_parser.add_argument("--json", action="store_true", help="print a summary as JSON")

    args = parser.parse_args(argv)
    with warnings.catch_warnings():
        # A user reads the warning, not where in our code it was raised.
        warnings.showwarning = lambda message, category, *rest, **keywords: print(f"WARNING: {message}",
                                                                                  file=sys.stderr)
        try:
            handler = {"sensitivity": _sensitivity, "report": _report, "compare": _compare, "predict": _predict,
                       "design": _design, "fit-many": _fit_many, "assemble": _assemble,
                       "characterise": _characterise}.get(args.command, _fit)
            return handler(args)
        except (IdentificationError, ParameterError, EngineError, UsageError) as exc:
            print(f"error: {exc}", file=sys.stderr)
            return 2


def _add_training_arguments(parser) -> None:
    group = parser.add_argument_group("training tests (CSV time_s,displacement_mm,force_N[,velocity_mm_s])")
    group.add_argument("--sine", action="append", type=Path, default=[], metavar="FILE",
                       help="sine test; repeatable")
    group.add_argument("--step", action="append", type=Path, default=[], metavar="FILE",
                       help="step test (a ramp, then held as long as the file says); repeatable")
    group.add_argument("--rise-time", action="append", type=positive_float, default=[], metavar="S",
                       help="rise time [s] of each --step, in the same order; repeatable")
    group.add_argument("--random", action="append", type=Path, default=[], metavar="FILE",
                       help="random-input test; repeatable")
    group.add_argument("--tests", type=Path, metavar="MANIFEST",
                       help='tests.json: {"sine": [...], "step": [{"file": ..., "rise_time_s": ...}], '
                            '"random": [...], "model": ...}, paths relative to it')
    group.add_argument("--kdyn", type=Path, metavar="TABLE",
                       help="dynamic-stiffness table (CSV amplitude_mm,frequency_hz,kdyn_N_per_mm,loss_angle_deg"
                            "[,preload_mm][,weight], as `characterise` writes), alone or with time series")


def _add_search_arguments(parser) -> None:
    group = parser.add_argument_group("search")
    group.add_argument("--preset", default="default", choices=["default", "paper"],
                       help="default: screened Sobol starts + successive halving of trust-region least squares; "
                            "paper: the paper's GA (300 x 200) instead of the screening")
    group.add_argument("--seed", type=non_negative_int, default=0, help="root seed of the search (default 0)")
    group.add_argument("--screening", type=positive_int, metavar="N",
                       help="Sobol points screened (default preset: 8192)")
    group.add_argument("--starts", type=positive_int, metavar="N",
                       help="least-squares starts of the first stage (default 128; later stages shrink in proportion)")
    where = group.add_mutually_exclusive_group()
    where.add_argument("--workers", type=positive_int, metavar="N",
                       help=f"local worker processes (default: all {os.cpu_count()} cores)")
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="run on a Dask cluster instead, e.g. tcp://10.0.0.5:8786 (workers started with "
                            "`dask worker ADDRESS --nthreads 1`)")
    group.add_argument("--no-ensemble", action="store_true",
                       help="skip the ensemble (prediction profiles and posterior sampling): faster, with the "
                            "convergence evidence but no band (fit: no --ensemble file)")
    group.add_argument("--quiet", action="store_true", help="no progress bars")


def _training_tests(args):
    """The tests of --sine/--step/--rise-time/--random or --tests, and the manifest's model
    (no tests at all where a --kdyn table is given alone)."""
    given = args.sine or args.step or args.random or args.rise_time
    if not given and args.tests is None and getattr(args, "kdyn", None) is not None:
        return [], None
    if args.tests is not None:
        if given:
            raise UsageError("give the tests either in --tests MANIFEST or as --sine/--step/--random, not both")
        manifest = load_manifest(args.tests)
        return manifest.tests, manifest.model
    return training_tests(args.sine, args.step, args.rise_time, args.random), None


def check_output(path: Path | None, option: str, directory: bool = False, suffixes: tuple[str, ...] = ()) -> None:
    """Refuse, before any work, an output that cannot be written (exit 2, nothing lost)."""
    if path is None:
        return
    if suffixes and path.suffix.lower() not in suffixes:
        raise UsageError(f"{option} {path}: give a file name ending in {' or '.join(suffixes)}")
    folder = path if directory and path.exists() else path.parent
    if path.exists() and directory != path.is_dir():
        raise UsageError(f"{option} {path}: is {'a file' if directory else 'a directory'}, "
                         f"expected {'a directory' if directory else 'a file'}")
    if not (folder.resolve().is_dir() or (directory and folder.parent.resolve().is_dir())):
        raise UsageError(f"{option} {path}: the directory {folder} does not exist")
    check = folder if folder.exists() else folder.parent
    if not os.access(check, os.W_OK) or (path.exists() and not os.access(path, os.W_OK)):
        raise UsageError(f"{option} {path}: not writable")


def _fit(args) -> int:
    from identification.fitting import FitNotConvergedWarning, fit
    from identification.plots import plot_comparison, plot_waterfall
    from identification.simulate import simulate

    # the parameter file and the ensemble carry the fit's provenance: JSON; SSP holds values only
    for path, option, suffix in ((args.out, "--out", ".json"), (args.ssv, "--ssv", ".ssv"),
                                 (args.ensemble, "--ensemble", ".json")):
        check_output(path, option, suffixes=(suffix,))
    check_output(args.plots, "--plots", directory=True)
    if args.no_ensemble and args.ensemble is not None:
        raise UsageError(f"--ensemble {args.ensemble} needs the ensemble that --no-ensemble skips: give one of them")
    tests, manifest_model = _training_tests(args)
    model = args.model or manifest_model or "proposed"
    if model not in MODEL_NAMES:
        raise UsageError(f"the manifest's model {model!r} is not one of {', '.join(MODEL_NAMES)}")
    table = None
    if args.kdyn is not None:
        from identification.kdyn_table import load_kdyn_table
        table = load_kdyn_table(args.kdyn)
    counts = {kind: sum(t.kind == kind for t in tests) for kind in ("sine", "step", "random")}
    print(f"fitting the {model} model to {counts['sine']} sine, {counts['step']} step and {counts['random']} "
          "random test(s)" + (f" and a dynamic-stiffness table of {len(table)} rows" if table else ""),
          file=sys.stderr)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FitNotConvergedWarning)   # printed below as WARNING
        result = fit(tests, model=model, preset=args.preset, seed=args.seed, workers=args.workers,
                     scheduler=args.scheduler, progress=not args.quiet, screening=args.screening,
                     starts=args.starts, kdyn=table, ensemble=not args.no_ensemble)
    written = _save_or_rescue(result, args, [t.measurement.source for t in tests]
                              + ([str(args.kdyn)] if args.kdyn else []))
    print(result.summary())
    if args.plots:
        if result.records:
            written.append(plot_waterfall([r.misfit for r in result.records], [r.stage for r in result.records],
                                          result.misfit, result.threshold, args.plots / "waterfall.png"))
        for test in tests:
            m = test.measurement
            predicted = simulate(result.parameters, m.time_s, m.displacement_mm, m.measured_velocity_mm_s)
            written.append(plot_comparison(m, {model: predicted}, args.plots / f"fit_{Path(m.source).stem}.png"))
        if table is not None:
            written += _plot_table_fit(result, table, args.plots)
    print("wrote " + ", ".join(str(path) for path in written))
    if not result.converged:
        print(f"WARNING: {result.warning}", file=sys.stderr)
    return 0


def _plot_table_fit(result, table, folder: Path) -> list[Path]:
    """The fitted set's (and ensemble's) data sheet on the table's amplitudes and frequencies,
    the table's rows as crosses; in ``folder``/kdyn (one plot set per preload: the first's)."""
    from identification.dynamic_stiffness import characterise
    from identification.plots import plot_dynamic_stiffness
    rows = table.subset(table.preload_mm == table.preload_mm[0])
    sheet = characterise(result, np.unique(rows.amplitude_mm), np.unique(rows.frequency_hz),
                         preload_mm=float(rows.preload_mm[0]))
    (folder / "kdyn").mkdir(parents=True, exist_ok=True)
    return plot_dynamic_stiffness(sheet, folder / "kdyn", measured=rows)


def _save_or_rescue(result, args, data) -> list[Path]:
    """Write the fit's files; if that fails after all (a disk filled up, a folder removed during
    the fit), write them into the working directory, or the temporary one, and say where: a
    finished fit is never lost."""
    import tempfile
    import time
    try:
        return result.save(args.out, args.ssv, args.ensemble, data=data)
    except OSError as exc:
        stamp = time.strftime("%Y%m%d-%H%M%S")
        for folder in (Path.cwd(), Path(tempfile.gettempdir())):
            rescue = {"out": folder / f"rescued_fit_{stamp}.json",
                      "ssv": folder / f"rescued_fit_{stamp}.ssv" if args.ssv else None,
                      "ensemble": folder / f"rescued_fit_{stamp}_ensemble.json" if args.ensemble else None}
            try:
                written = result.save(rescue["out"], rescue["ssv"], rescue["ensemble"], data=data)
            except OSError:
                continue
            print(f"WARNING: could not write the fit's files ({exc}); wrote them instead to "
                  + ", ".join(map(str, written)), file=sys.stderr)
            return written
        raise


def _sensitivity(args) -> int:
    from fmu_src.parameter_files import load_parameters
    from identification.sensitivity import sensitivity
    check_output(args.csv, "--csv", suffixes=(".csv",))
    table = sensitivity(load_parameters(args.params, model="proposed"), delta=args.delta)
    print(table.format())
    if args.csv:
        table.write_csv(args.csv)
        print(f"wrote {args.csv}")
    return 0


def _report(args) -> int:
    from identification.report import data_errors, format_data_errors, format_errors, grid_errors, plot_measurement
    from identification.search_space import KelvinVoigtFit
    from fmu_src.parameter_files import read_ensemble
    params = read_ensemble(args.params)
    model = params.model.name
    if not (args.data or args.truth):
        raise UsageError("give --data files and/or --truth to report on")
    check_output(args.plots, "--plots", directory=True)
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


def _predict(args) -> int:
    from fmu_src.parameter_files import read_ensemble
    from identification.predict import predict
    check_output(args.out, "--out", suffixes=(".csv",))
    check_output(args.plot, "--plot", suffixes=(".png",))
    ensemble = read_ensemble(args.params)
    m = load_measurement(args.data, force_optional=True)
    prediction = predict(ensemble, m.time_s, m.displacement_mm, m.measured_velocity_mm_s)
    prediction.write_csv(args.out)
    written = [args.out]
    if args.plot:
        from identification.plots import plot_comparison
        band = (prediction.lower_N, prediction.upper_N) if prediction.members > 1 else None
        written.append(plot_comparison(m, {ensemble.model.name: prediction.force_N}, args.plot, band,
                                       measured=m.has_force))
    width = prediction.band_width_N
    print(f"{prediction.members} parameter set(s); rms force {np.sqrt(np.mean(prediction.force_N ** 2)):.1f} N"
          + (f"; band width: mean {np.mean(width):.1f} N, largest {np.max(width):.1f} N" if prediction.members > 1
             else ""))
    print("wrote " + ", ".join(map(str, written)))
    return 0


def _characterise(args) -> int:
    import json
    from fmu_src.parameter_files import read_ensemble
    from identification.dynamic_stiffness import characterise
    check_output(args.out, "--out", suffixes=(".csv",))
    check_output(args.plots, "--plots", directory=True)
    ensemble = read_ensemble(args.params, args.model)
    table = characterise(ensemble, args.amplitudes_mm, args.frequencies_hz, preload_mm=args.preload_mm)
    written = [table.to_csv(args.out)]
    if args.plots:
        from identification.plots import plot_dynamic_stiffness
        args.plots.mkdir(exist_ok=True)
        written += plot_dynamic_stiffness(table, args.plots)
    if args.json:
        summary = table.summary()
        summary["written"] = [str(path) for path in written]
        print(json.dumps(summary, indent=1))
        return 0
    print(f"{ensemble.model.name} model, {table.members} parameter set(s), preload {args.preload_mm:g} mm:")
    print(table.format())
    summary = table.summary()
    print(f"loop area against pi*K''*X^2: largest difference {100 * summary['largest_energy_difference_relative']:.2g} % "
          "(only the first harmonic does work under a sine: the difference is quadrature error)")
    print("wrote " + ", ".join(map(str, written)))
    return 0


def _design(args) -> int:
    import json
    from fmu_src.parameter_files import read_ensemble
    from identification.design import design
    result = design(read_ensemble(args.ensemble), noise_N=args.noise, progress=not args.json)
    print(json.dumps(result.as_json(args.top), indent=2) if args.json else result.format(args.top))
    return 0


def _assemble(args) -> int:
    from identification.six_axis import assemble
    check_output(args.out, "--out", suffixes=(".json", ".ssv"))
    files = {}
    for item in args.axis:
        name, separator, file = item.partition("=")
        if not separator or not file:
            raise UsageError(f"--axis {item}: give NAME=FILE, e.g. --axis rz=fit_torsion.json")
        if name in files:
            raise UsageError(f"--axis {name} is given twice")
        files[name] = Path(file)
    path = assemble(files, args.out, rigid_missing=args.rigid_missing, default=args.default)
    print(f"wrote {path}")
    return 0


def _fit_many(args) -> int:
    from identification.fleet import fit_many
    check_output(args.out, "--out", directory=True)
    rows = fit_many(args.folder, args.out, workers=args.workers, scheduler=args.scheduler, preset=args.preset,
                    seed=args.seed, screening=args.screening, starts=args.starts, progress=not args.quiet,
                    ensemble=not args.no_ensemble)
    for row in rows:
        state = f"error: {row.error}" if row.error else (f"misfit {row.misfit:.4f}, "
                                                          + ("converged" if row.converged else "NOT converged"))
        print(f"{row.name:30s} {state}")
    print(f"wrote {args.out}/summary.csv and {sum(not r.error for r in rows)} parameter file(s)")
    failed = [r.name for r in rows if r.error or not r.converged]
    if failed:
        print(f"WARNING: not converged or failed: {', '.join(failed)}", file=sys.stderr)
    return 0


def _compare(args) -> int:
    from identification.compare import compare_models
    if args.kdyn is not None:
        raise UsageError("--kdyn: compare fits and validates on time series; fit a table with `fit --kdyn`")
    tests, _ = _training_tests(args)
    models = [name.strip() for name in args.models.split(",") if name.strip()]
    unknown = [name for name in models if name not in MODEL_NAMES]
    if unknown:
        raise UsageError(f"unknown models {unknown}; choose from {', '.join(MODEL_NAMES)}")
    check_output(args.out, "--out", directory=True)
    validation = args.validate or [Path(t.measurement.source) for t in tests]
    compare_models(models, tests, validation, args.out, preset=args.preset, seed=args.seed, workers=args.workers,
                   scheduler=args.scheduler, screening=args.screening, starts=args.starts,
                   ensemble=not args.no_ensemble)
    return 0


if __name__ == "__main__":
    sys.exit(main())
