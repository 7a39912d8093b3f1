"""What each command of ``bushing-identify`` (``python -m identification``) does, once its
arguments are parsed (``identification.cli.arguments``): one function per command, taking the parsed
arguments and returning the exit status.

Outputs are checked before any work (``check_output``, ``prepare_directory``): a fit is never
lost to a path that cannot be written; a fit whose files cannot be written after all is
rescued into the working or the temporary directory (``_save_or_rescue``).
"""
from __future__ import annotations

import math
import os
import sys
import tempfile
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

from fmu_src.model.parameter_specs import ParameterError
from fmu_src.model.registry import DEFAULT_MODEL, MODEL_NAMES
from identification.cli.model_options import build_model_options, fixed_values, model_options_of
from fmu_src.parameter_files import read_parameter_set
from identification.errors import FitNotConvergedWarning, UsageError
from identification.measured.measurements import load_measurement, measurement_name
from identification.measured.rig_tests import load_manifest, training_tests


def training_tests_of(args):
    """The tests of --sine/--step/--rise-time/--random or --tests, and the manifest's model
    (no tests at all where a --kdyn table or --multiaxis tests are given alone)."""
    given = args.sine or args.step or args.random or args.rise_time
    if not given and args.tests is None and (getattr(args, "kdyn", None) is not None
                                             or getattr(args, "multiaxis", None)):
        return [], None
    if args.tests is not None:
        if given:
            raise UsageError("give the tests either in --tests MANIFEST or as --sine/--step/--random, not both")
        manifest = load_manifest(args.tests)
        return manifest.tests, manifest.model
    return training_tests(args.sine, args.step, args.rise_time, args.random), None


def multiaxis_tests_of(args) -> list:
    """The --multiaxis tests, read before any work (a bad file: one error line naming its line or
    column), each checked against --coupling (required with them)."""
    from identification.measured.multiaxis import COUPLED_AXES, coupled_axes, load_multiaxis
    multiaxis = [load_multiaxis(path) for path in getattr(args, "multiaxis", [])]
    if multiaxis and args.coupling is None:
        raise UsageError(f"--multiaxis needs --coupling: how the model runs on them, one of {', '.join(COUPLED_AXES)}")
    if args.coupling is not None and not multiaxis:
        raise UsageError(f"--coupling {args.coupling} says how the model runs on multi-axis tests: give --multiaxis FILE")
    for m in multiaxis:
        coupled_axes(args.coupling, m)
    return multiaxis


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
    if check.is_dir():
        # os.access says yes to root and on special file systems (/proc): try it
        try_writing_in(check, f"{option} {path}: cannot write in {check}")


def try_writing_in(directory: Path, refusal: str) -> None:
    """Write and remove a temporary file in ``directory``; if that fails, raise
    :class:`UsageError` with ``refusal`` and the system's reason."""
    try:
        with tempfile.TemporaryFile(dir=directory):
            pass
    except OSError as exc:
        raise UsageError(f"{refusal} ({exc.strerror or exc})") from None


def prepare_directory(path: Path | None, option: str) -> None:
    """Create the output directory ``path`` now and write a file into it, so that one that
    cannot be written is refused before any work (exit 2) instead of after a long fit."""
    if path is None:
        return
    check_output(path, option, directory=True)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UsageError(f"{option} {path}: cannot write there ({exc.strerror or exc})") from None
    try_writing_in(path, f"{option} {path}: cannot write there")


def print_warning(message: str) -> None:
    """``WARNING: message`` on stderr, on a line of its own."""
    sys.stderr.flush()
    print(f"WARNING: {message}", file=sys.stderr)


def fit_command(args) -> int:
    from identification.fitting.fit import fit
    from identification.analysis.plots import plot_comparison, plot_multiaxis, plot_waterfall

    # the parameter file and the ensemble carry the fit's provenance: JSON; SSP holds values only
    for path, option, suffix in ((args.out, "--out", ".json"), (args.ssv, "--ssv", ".ssv"),
                                 (args.ensemble, "--ensemble", ".json")):
        check_output(path, option, suffixes=(suffix,))
    prepare_directory(args.plots, "--plots")
    if args.no_ensemble and args.ensemble is not None:
        raise UsageError(f"--ensemble {args.ensemble} needs the ensemble that --no-ensemble skips: give one of them")
    tests, manifest_model = training_tests_of(args)
    model = args.model or manifest_model or DEFAULT_MODEL
    options = model_options_of(args)
    try:
        bushing = options.model(model)          # resolved once; an alias (bouc_wen) under its name
    except ParameterError:
        raise UsageError(f"the manifest's model {model!r} is not one of {', '.join(MODEL_NAMES)}") from None
    model = bushing.name
    tests = options.training(tests)
    fixed = options.fixed_for(bushing)
    if options.curve is not None:
        print(options.describe(), file=sys.stderr)
    table = None
    if args.kdyn is not None:
        from identification.measured.kdyn_table import load_kdyn_table
        table = load_kdyn_table(args.kdyn)
    multiaxis = multiaxis_tests_of(args)
    counts = {kind: sum(t.kind == kind for t in tests) for kind in ("sine", "step", "random")}
    print(f"fitting the {model} model to {counts['sine']} sine, {counts['step']} step and {counts['random']} "
          "random test(s)" + (f", {len(multiaxis)} multi-axis test(s) ({args.coupling} coupling)" if multiaxis else "")
          + (f" and a dynamic-stiffness table of {len(table)} rows" if table else ""),
          file=sys.stderr)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FitNotConvergedWarning)   # printed below as WARNING
        result = fit(tests, bushing, kdyn=table, multiaxis=multiaxis, coupling=args.coupling, fixed=fixed,
                     **search_settings(args))
    written = _save_or_rescue(result, args, [t.measurement.source for t in tests] + [m.source for m in multiaxis]
                              + ([str(args.kdyn)] if args.kdyn else []))
    print(result.summary())
    if args.plots:
        if result.records:
            written.append(plot_waterfall([r.misfit for r in result.records], [r.stage for r in result.records],
                                          result.misfit, result.threshold, args.plots / "waterfall.png"))
        # each test's force as the fit computed it (the one-axis tests' fits first, then the multi-axis ones)
        for test, fitted in zip(tests, result.tests):
            m = test.measurement
            written.append(plot_comparison(m, {bushing: fitted.predicted_N},
                                           args.plots / f"fit_{measurement_name(m.source)}.png"))
        for m, fitted in zip(multiaxis, result.tests[len(tests):]):
            written.append(plot_multiaxis(m, {f"{bushing.title}, {args.coupling}": fitted.predicted_N},
                                          args.plots / f"fit_{measurement_name(m.source)}.png"))
        if table is not None:
            written += _plot_table_fit(result, table, args.plots)
    print("wrote " + ", ".join(str(path) for path in written))
    if not result.converged:
        print_warning(result.warning)
    return 0


def _plot_table_fit(result, table, folder: Path) -> list[Path]:
    """The fitted set's (and ensemble's) data sheet on the table's amplitudes and frequencies,
    the table's rows as crosses; in ``folder``/kdyn (one plot set per preload: the first's)."""
    from identification.forward.dynamic_stiffness import SteadyStateLoop, data_sheet
    from identification.analysis.plots import plot_dynamic_stiffness
    rows = table.subset(table.preload_mm == table.preload_mm[0])
    # the fit's model and its checked sets, carried on: nothing to read or resolve again
    sheet = data_sheet(result.parameters.model, result.ensemble, np.unique(rows.amplitude_mm),
                       np.unique(rows.frequency_hz), float(rows.preload_mm[0]), SteadyStateLoop())
    (folder / "kdyn").mkdir(parents=True, exist_ok=True)
    return plot_dynamic_stiffness(sheet, folder / "kdyn", measured=rows)


def _save_or_rescue(result, args, data) -> list[Path]:
    """Write the fit's files; if that fails after all (a disk filled up, a folder removed during
    the fit), write them into the working directory, or the temporary one, and say where: a
    finished fit is never lost."""
    import time
    try:
        return result.save(args.out, args.ssv, args.ensemble, data=data, rig_into_fmu=args.rig_offsets_in_fmu)
    except OSError as exc:
        stamp = time.strftime("%Y%m%d-%H%M%S")
        for folder in (Path.cwd(), Path(tempfile.gettempdir())):
            rescue = {"out": folder / f"rescued_fit_{stamp}.json",
                      "ssv": folder / f"rescued_fit_{stamp}.ssv" if args.ssv else None,
                      "ensemble": folder / f"rescued_fit_{stamp}_ensemble.json" if args.ensemble else None}
            try:
                written = result.save(rescue["out"], rescue["ssv"], rescue["ensemble"], data=data,
                                      rig_into_fmu=args.rig_offsets_in_fmu)
            except OSError:
                continue
            print_warning(f"could not write the fit's files ({exc}); wrote them instead to "
                          + ", ".join(map(str, written)))
            return written
        raise


def sensitivity_command(args) -> int:
    from fmu_src.parameter_files import load_parameters
    from identification.analysis.parameter_sensitivity import sensitivity
    check_output(args.csv, "--csv", suffixes=(".csv",))
    table = sensitivity(load_parameters(args.params, model=DEFAULT_MODEL), delta=args.delta)
    print(table.format())
    if args.csv:
        table.write_csv(args.csv)
        print(f"wrote {args.csv}")
    return 0


def report_command(args) -> int:
    from identification.analysis.paper_verification import data_errors, format_data_errors, format_errors, grid_errors, plot_measurement
    from identification.fitting.search_space import KelvinVoigtFit
    from fmu_src.parameter_files import read_ensemble
    params = read_ensemble(args.params)     # read once: its model and sets go on as they are
    if not (args.data or args.truth):
        raise UsageError("give --data files and/or --truth to report on")
    prepare_directory(args.plots, "--plots")
    kelvin_voigt = None
    if args.kelvin_voigt_train:
        kelvin_voigt = KelvinVoigtFit.fit([load_measurement(path) for path in args.kelvin_voigt_train])
        print(f"Kelvin-Voigt fit: k = {kelvin_voigt.k:.4g} N/mm, c = {kelvin_voigt.c:.4g} N*s/mm")
    if args.truth:
        print(f"Against the noise-free model of {args.truth} (paper §5 grid):")
        truth = read_parameter_set(args.truth)
        print(format_errors(grid_errors(params, truth)))
    if args.data:
        measurements = [load_measurement(path) for path in args.data]
        print(format_data_errors(data_errors(params, measurements, kelvin_voigt)))
        if args.plots:
            for m in measurements:
                path = plot_measurement(params, m, args.plots / (measurement_name(m.source) + ".png"), kelvin_voigt)
                print(f"wrote {path}")
    return 0


def predict_command(args) -> int:
    from fmu_src.parameter_files import read_ensemble
    from identification.measured.multiaxis import is_multiaxis_file
    from identification.analysis.predict import predict
    check_output(args.out, "--out", suffixes=(".csv",))
    check_output(args.plot, "--plot", suffixes=(".png",))
    ensemble = read_ensemble(args.params)
    if is_multiaxis_file(args.data):
        return _predict_multiaxis(args, ensemble)
    if args.coupling is not None:
        raise UsageError(f"--coupling {args.coupling}: {args.data} is a one-axis test (time_s, displacement_*); a "
                         "coupling says how the model runs on a multi-axis path (dx_mm, dy_mm[, dz_mm])")
    m = load_measurement(args.data, force_optional=True)
    from identification.measured.offsets import held_force
    prediction = predict(ensemble, m.time_s, m.displacement_mm, m.measured_velocity_mm_s,
                         rest_force_N=held_force(m) if m.has_force else math.nan, temperature_K=m.mean_temperature_K)
    prediction.write_csv(args.out)
    written = [args.out]
    if args.plot:
        from identification.analysis.plots import plot_comparison
        band = (prediction.lower_N, prediction.upper_N) if prediction.members > 1 else None
        written.append(plot_comparison(m, {ensemble.model: prediction.force_N}, args.plot, band,
                                       measured=m.has_force))
    _print_prediction(prediction, written)
    return 0


def _predict_multiaxis(args, ensemble) -> int:
    """``predict`` on a multi-axis path: force vectors with --coupling (required there)."""
    from identification.measured.multiaxis import COUPLED_AXES, load_multiaxis, vector_nrmse
    from identification.analysis.predict import predict_multiaxis
    if args.coupling is None:
        raise UsageError(f"{args.data} is a multi-axis path: give --coupling, how the model runs on it "
                         f"({', '.join(COUPLED_AXES)})")
    m = load_multiaxis(args.data, force_optional=True)
    prediction = predict_multiaxis(ensemble, m.time_s, m.displacement_mm, args.coupling, m.velocity_mm_s)
    prediction.write_csv(args.out)
    written = [args.out]
    if args.plot:
        from identification.analysis.plots import plot_multiaxis
        written.append(plot_multiaxis(m, {f"{ensemble.model.title}, {args.coupling}": prediction.force_N},
                                      args.plot, measured=m.has_force))
    if m.has_force:
        print(f"NRMSE of the force vector against {m.name}: {vector_nrmse(prediction.force_N, m.force_N):.2%}")
    _print_prediction(prediction, written)
    return 0


def _print_prediction(prediction, written) -> None:
    force = prediction.force_N.reshape(prediction.force_N.shape[0], -1)
    width = prediction.band_width_N
    print(f"{prediction.members} parameter set(s); rms force {np.sqrt(np.mean(np.sum(force ** 2, axis=1))):.1f} N"
          + (f"; band width: mean {np.mean(width):.1f} N, largest {np.max(width):.1f} N" if prediction.members > 1
             else ""))
    misfit = getattr(prediction, "misfit_N", math.nan)     # a multi-axis prediction has none
    if misfit == misfit:
        from identification.analysis.predict import MISFIT_WIDENING
        print(f"the fit misses its own training tests by {misfit:.1f} N rms: a measurement likely falls within the "
              f"band widened by {MISFIT_WIDENING * misfit:.1f} N (likely_min_N, likely_max_N)")
    print("wrote " + ", ".join(map(str, written)))


def characterise_command(args) -> int:
    import json
    from fmu_src.parameter_files import read_ensemble
    from identification.forward.dynamic_stiffness import characterise
    check_output(args.out, "--out", suffixes=(".csv",))
    prepare_directory(args.plots, "--plots")
    ensemble = read_ensemble(args.params, args.model)
    if args.temperatures_c:
        return _characterise_at_temperatures(args, ensemble)
    table = characterise(ensemble, args.amplitudes_mm, args.frequencies_hz, preload_mm=args.preload_mm)
    written = [table.to_csv(args.out)]
    if args.plots:
        from identification.analysis.plots import plot_dynamic_stiffness
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


def _characterise_at_temperatures(args, ensemble) -> int:
    """``characterise --temperatures-c``: the table at each temperature, one CSV with a
    temperature_K column, the sheets and the sheet over temperature as plots."""
    import json
    from identification.forward.dynamic_stiffness import characterise_at_temperatures, write_temperature_sheet
    kelvin = [celsius + 273.15 for celsius in args.temperatures_c]
    tables = characterise_at_temperatures(ensemble, kelvin, args.amplitudes_mm, args.frequencies_hz, args.preload_mm)
    written = [write_temperature_sheet(args.out, tables, [f"{ensemble.model.name} model at "
                                                          f"{', '.join(f'{c:g}' for c in args.temperatures_c)} degC"])]
    if args.plots:
        from identification.analysis.plots import plot_temperature_sheet
        args.plots.mkdir(exist_ok=True)
        written.append(plot_temperature_sheet(tables, args.plots))
    if args.json:
        print(json.dumps({"temperatures_K": kelvin, "tables": [table.summary() for _, table in tables],
                          "written": [str(path) for path in written]}, indent=1))
        return 0
    for temperature, table in tables:
        print(f"{ensemble.model.name} model, {table.members} parameter set(s), preload {args.preload_mm:g} mm, "
              f"{temperature - 273.15:g} degC:")
        print(table.format())
    print("wrote " + ", ".join(map(str, written)))
    return 0


def design_command(args) -> int:
    import json
    from fmu_src.parameter_files import read_ensemble
    from identification.analysis.design import design
    result = design(read_ensemble(args.ensemble), noise_N=args.noise, progress=not args.json)
    print(json.dumps(result.as_json(args.top), indent=2) if args.json else result.format(args.top))
    return 0


def import_command(args) -> int:
    from fmu_src.parameter_files import save_six_axis
    from identification.property_files.chrono_json import read_chrono_bushing
    from identification.property_files.bus import read_bus
    from identification.property_files.gbs import read_gbs
    check_output(args.out, "--out", suffixes=(".json",))
    suffix = args.file.suffix.lower()
    readers = {".gbs": read_gbs, ".bus": read_bus}
    if suffix not in (".json", *readers):
        raise UsageError(f"{args.file}: the property files this version reads are Chrono's vehicle JSON (.json), "
                         "Altair's bushing files (.gbs) and Adams' nonlinear bushing files (.bus)")
    if suffix in readers and (args.bushing or args.joint):
        raise UsageError(f"{args.file}: --bushing and --joint are for Chrono's files; a {suffix} holds one bushing "
                         "with all six directions")
    imported = (readers[suffix](args.file) if suffix in readers
                else read_chrono_bushing(args.file, args.bushing, args.joint))
    path = save_six_axis(args.out, imported.axes, imported.provenance)
    name = imported.provenance.get("bushing", args.file.name)
    print(f"{name}: " + ", ".join(f"{axis} {model}" for axis, (model, _) in imported.axes.items())
          + (f"; the {args.joint} joint's free rotations the file's DOF values" if args.joint else ""))
    print(f"wrote {path}")
    return 0


def export_command(args) -> int:
    from identification.property_files.export import OperatingPoint, export_gbs
    check_output(args.out, "--out", suffixes=(".gbs",))
    point = OperatingPoint(args.range_mm, args.range_rad, args.points, args.amplitude_mm, args.amplitude_rad,
                           args.frequency_hz)
    print(f"wrote {export_gbs(args.params, args.out, point, args.direction)}")
    return 0


def assemble_command(args) -> int:
    from identification.fitting.six_axis_assembly import assemble
    check_output(args.out, "--out", suffixes=(".json", ".ssv"))
    files = {}
    for item in args.axis:
        name, separator, file = item.partition("=")
        if not separator or not file:
            raise UsageError(f"--axis {item}: give NAME=FILE, e.g. --axis rz=fit_torsion.json")
        if name in files:
            raise UsageError(f"--axis {name} is given twice")
        files[name] = Path(file)
    path = assemble(files, args.out, rigid_missing=args.rigid_missing, default=args.default,
                    coupling=coupling_of(args.coupling))
    print(f"wrote {path}")
    return 0


def coupling_of(text: str | None):
    """``axes.Coupling`` of --coupling: a group's name, or two (a translation's and a rotation's)
    separated by a comma; UsageError naming what is allowed."""
    from fmu_src.fmi.axes import GROUPS, Coupling
    if text is None:
        return Coupling()
    chosen = {}
    for name in (part.strip() for part in text.split(",") if part.strip()):
        kind = next((kind for kind, names in GROUPS.items() if name in names and name != "none"), None)
        if kind is None or kind in chosen:
            allowed = ", ".join(name for names in GROUPS.values() for name in names if name != "none")
            raise UsageError(f"--coupling {text}: " + (f"{name!r} is not a group" if kind is None else
                                                        f"two {kind} groups") + f"; allowed: {allowed}, or a "
                             "translation group and conical separated by a comma (radial,conical)")
        chosen[kind] = name
    return Coupling(**chosen)


def search_settings(args) -> dict:
    """The search's settings every fitting command takes (``arguments._add_search_arguments``),
    as the keywords of ``fit``, ``fit_many`` and ``compare_models``."""
    return dict(preset=args.preset, seed=args.seed, workers=args.workers, scheduler=args.scheduler,
                screening=args.screening, starts=args.starts, progress=not args.quiet, ensemble=not args.no_ensemble)


def fit_many_command(args) -> int:
    from identification.fitting.fleet import fit_many
    prepare_directory(args.out, "--out")
    rows = fit_many(args.folder, args.out, **search_settings(args))
    for row in rows:
        state = f"error: {row.error}" if row.error else (f"misfit {row.misfit:.4f}, "
                                                          + ("converged" if row.converged else "NOT converged"))
        print(f"{row.name:30s} {state}")
    print(f"wrote {args.out}/summary.csv and {sum(not r.error for r in rows)} parameter file(s)")
    failed = [r.name for r in rows if r.error or not r.converged]
    if failed:
        print_warning(f"not converged or failed: {', '.join(failed)}")
    return 0


def compare_command(args) -> int:
    from fmu_src.model.options import Options
    from identification.analysis.compare import compare_models
    from identification.analysis.first_contact import Assumption, first_contact
    if args.multiaxis:
        raise UsageError("--multiaxis: compare fits on one-axis tests and weighs the couplings on held-out multi-axis "
                         "files (--coupling none,radial --validate-multiaxis FILE); fit a model to multi-axis tests "
                         "with `fit --multiaxis FILE --coupling radial`")
    from identification.measured.kdyn_table import load_kdyn_table
    table = load_kdyn_table(args.validate_kdyn) if args.validate_kdyn is not None else None
    if args.kdyn is not None and args.validate_kdyn is not None and args.kdyn.resolve() == args.validate_kdyn.resolve():
        raise UsageError(f"--kdyn and --validate-kdyn are the same table ({args.kdyn}): a table the models are fitted "
                         "on is not held out; give another table to --validate-kdyn, or leave it out")
    training_table = load_kdyn_table(args.kdyn) if args.kdyn is not None else None
    tried = _tried_options(args)         # refused before any work; None: what the first contact tries
    tests, _ = training_tests_of(args)
    options = model_options_of(args)
    contact, variants = None, []
    if args.options is None:        # a new device's first contact: the options its tests ask for
        contact = first_contact(tests, options.static_test, training_table)
        static = contact.static_test.measurement if contact.static_test is not None else None

        def options_of(tokens):
            tokens = [t for t in tokens if not (args.backbone_knots and t.startswith("backbone"))]
            return build_model_options(Options.parse(tokens), fixed_values(args.fix), static, args.backbone_knots)
        options = options_of(contact.tokens)
        variants = [options_of([t for t in contact.tokens if t != token]) for token in contact.tokens]
        if tried is None:
            tried = list(contact.tried)
        else:       # named: those are tried, whatever the records would have asked for
            contact = replace(contact, trials=tuple(Assumption(token, "named with --try-options") for token in tried))
        print(contact.format(), file=sys.stderr)
    variants += [variant for variant in (_with_option(options, token, args) for token in tried or ()) if variant]
    tests = options.training(tests)
    models = [name.strip() for name in args.models.split(",") if name.strip()]
    unknown, resolved = [], []
    for name in models:
        try:
            resolved.append(options.model(name))          # resolved once, passed on
        except ParameterError:
            unknown.append(name)
    if unknown:
        raise UsageError(f"unknown models {unknown}; choose from {', '.join(MODEL_NAMES)}, with options where wanted "
                         "(berg+limits)")
    named, models = models, resolved
    fixed = {bushing.name: options.fixed_for(bushing) for bushing in models}
    alternatives = {bushing.name: [(variant.model(name), variant.fixed_for(variant.model(name)))
                                   for variant in variants] for name, bushing in zip(named, models)}
    if options.curve is not None:
        print(options.describe(), file=sys.stderr)
    couplings = couplings_of(args.coupling, args.validate_multiaxis)
    from identification.measured.multiaxis import load_multiaxis
    multiaxis = [load_multiaxis(path) for path in args.validate_multiaxis]    # a bad file: refused before any fit
    planar = [m.name for m in multiaxis if m.displacement_mm.shape[1] != 3]
    if "spherical" in couplings and planar:
        raise UsageError(f"--coupling spherical needs multi-axis files of three axes (dz_mm, Fz_N); "
                         f"{', '.join(planar)} {'has' if len(planar) == 1 else 'have'} two")
    if args.no_ensemble and args.every_ensemble:
        raise UsageError("--every-ensemble samples the ensembles that --no-ensemble skips: give one of them")
    prepare_directory(args.out, "--out")
    validation = args.validate or [Path(t.measurement.source) for t in tests]
    compare_models(models, tests, validation, args.out, table=table, multiaxis=multiaxis, couplings=couplings,
                   training_table=training_table, race=not args.no_race, every_ensemble=args.every_ensemble,
                   fixed_by_model=fixed, alternatives=alternatives, first_contact=contact,
                   leave_one_out=args.leave_one_out, **search_settings(args))
    return 0


def _tried_options(args) -> list[str] | None:
    """The tokens of compare's ``--try-options``, each checked; [] for ``none``; None where it is
    not given (the first contact then says what is tried)."""
    from fmu_src.model.options import Options
    text = (getattr(args, "try_options", None) or "").strip()
    if not text:
        return None
    if text.lower() == "none":
        return []
    try:
        return list(Options.parse(part for part in text.split(",") if part.strip()).tokens)
    except ParameterError as exc:
        raise UsageError(f"--try-options {args.try_options}: {exc}") from None


def _with_option(options, token: str, args):
    """``options`` (``ModelOptions``) with the option ``token`` added: a variant compare weighs (None
    where the options have it already)."""
    from fmu_src.model.options import Options
    try:
        added = options.options.union(Options.parse([token]))
    except ParameterError as exc:
        raise UsageError(f"--try-options {token}: {exc}") from None
    if added == options.options:        # already there: no variant
        return None
    static = options.static_test.measurement if options.static_test is not None else None
    return build_model_options(added, fixed_values(args.fix), static, args.backbone_knots)


COMPARED_COUPLINGS = ("none", "radial", "spherical")


def couplings_of(text: str | None, multiaxis_files) -> tuple[str, ...]:
    """The couplings of compare's --coupling (none, radial, spherical), each checked against the
    multi-axis files it needs; UsageError naming what is allowed."""
    if text is None:
        if multiaxis_files:
            raise UsageError("--validate-multiaxis needs --coupling: the couplings to weigh, e.g. --coupling none,radial")
        return ()
    couplings = tuple(part.strip() for part in text.split(",") if part.strip())
    unknown = [name for name in couplings if name not in COMPARED_COUPLINGS]
    if unknown or not couplings:
        raise UsageError(f"--coupling {text}: {', '.join(map(repr, unknown)) or 'nothing'} is not a coupling compare "
                         f"weighs; allowed: {', '.join(COMPARED_COUPLINGS)}, comma-separated")
    if not multiaxis_files:
        raise UsageError(f"--coupling {text} needs held-out multi-axis files to weigh them on: give "
                         "--validate-multiaxis FILE")
    return couplings
