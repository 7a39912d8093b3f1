"""The command line ``bushing-identify`` (``python -m identification``): its arguments, checked
as they are parsed, and the dispatch to ``identification.cli.commands``.

A command whose extra is not installed, or whose arguments cannot be used, ends with one
``error:`` line and exit status 2, before any work. A command stopped by Ctrl-C or SIGTERM ends
with one ``interrupted:`` line and exit status 130 or 143 (``identification.interrupt``).
"""
from __future__ import annotations

import argparse
import os
import signal
import sys
import warnings
from pathlib import Path

from fmu_src import __version__
from fmu_src.kernels import jit
from fmu_src.model.registry import DEFAULT_MODEL, MODEL_NAMES, MODELS, get_model
from fmu_src.model.parameter_specs import ParameterError
from identification.cli import commands
from identification.forward.dynamic_stiffness import DEFAULT_AMPLITUDES_MM, DEFAULT_FREQUENCIES_HZ
from identification.errors import EngineError, IdentificationError, MissingExtraError, UsageError
from identification.extras import require
from identification.interrupt import Interrupted, interrupted_message, signals_raise
from identification.measured.multiaxis import COUPLED_AXES
from identification.fitting.presets import PRESETS, describe
from identification.fitting.progress import close_open_bars



def _linear_models() -> str:
    """The models fitted by linear least squares (``BushingModel.linear``), for the help."""
    return ", ".join(name for name, model in MODELS.items() if model.linear is not None)

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


def model_name(text: str) -> str:
    """A model's name or identifier, with its options where given (``berg+backbone9+rig``)."""
    try:
        return get_model(text).name
    except ParameterError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def number_list(text: str) -> list[float]:
    """'0.1,0.5,1' -> [0.1, 0.5, 1.0]."""
    try:
        return [float(part) for part in text.split(",") if part.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: give numbers separated by commas, e.g. 0.5,1,2") from None


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit status: 0, 2 for an input that cannot be used, 130
    or 143 for a command stopped by SIGINT (Ctrl-C) or SIGTERM (``identification.interrupt``: one
    line on stderr saying what was written, no worker process left behind)."""
    program = "bushing-identify" if Path(sys.argv[0]).name.startswith("bushing-identify") else "python -m identification"
    return run(build_parser(program).parse_args(argv))


def build_parser(program: str = "python -m identification") -> argparse.ArgumentParser:
    """Every command and its arguments (``program``: the name the usage lines give)."""
    parser = argparse.ArgumentParser(prog=program,
                                     description="Identify the bushing model's parameters from measured tests.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    subcommands = parser.add_subparsers(dest="command", required=True)
    for add in (_add_fit, _add_sensitivity, _add_report, _add_compare, _add_predict, _add_design, _add_fit_many,
                _add_assemble, _add_characterise, _add_import, _add_export):
        add(subcommands)
    return parser


def _add_fit(subcommands) -> None:
    """The ``fit`` command's arguments."""
    fit_parser = subcommands.add_parser("fit", help="fit a model's parameters to rig tests, with convergence evidence")
    fit_parser.add_argument("--model", type=model_name, metavar="MODEL",
                            help=f"one of {', '.join(MODEL_NAMES)} ({_linear_models()} by linear least squares; "
                                 f"`compare` recommends one), with options where wanted (berg+backbone9+rig); "
                                 f"default: the manifest's, else {DEFAULT_MODEL}, the paper's")
    _add_training_arguments(fit_parser)
    _add_model_option_arguments(fit_parser)
    fit_parser.add_argument("--rig-offsets-in-fmu", action="store_true",
                            help="with the rig's offsets (rig): write them into the parameter file as its mounting's "
                                 "offset and preload (default: only in its provenance, the model without them)")
    fit_parser.add_argument("--coupling", choices=tuple(COUPLED_AXES), metavar="COUPLING",
                            help="how the model runs on the --multiaxis tests (required with them): none (one "
                                 "model per axis), radial (coupled in x, y; z alone) or spherical (x, y, z)")
    _add_search_arguments(fit_parser)
    fit_parser.add_argument("--out", type=Path, required=True, help="parameter file to write (JSON)")
    fit_parser.add_argument("--ssv", type=Path, help="also write an SSP 1.0 ParameterValues file")
    fit_parser.add_argument("--ensemble", type=Path,
                            help="also write the ensemble: every parameter set within the 95 %% confidence threshold")
    fit_parser.add_argument("--plots", type=Path, help="directory for the waterfall and the training tests' plots")


def _add_sensitivity(subcommands) -> None:
    """The ``sensitivity`` command's arguments."""
    sensitivity_parser = subcommands.add_parser(
        "sensitivity", help="rank the 16 parameters by local sensitivity (paper Tables 1 and 3)")
    sensitivity_parser.add_argument("--params", type=Path, required=True, help="parameter file (.json or .ssv)")
    sensitivity_parser.add_argument("--delta", type=fraction, default=0.1,
                                    help="relative change, 0 < delta < 1 (default 0.1)")
    sensitivity_parser.add_argument("--csv", type=Path, help="also write the table as CSV")


def _add_report(subcommands) -> None:
    """The ``report`` command's arguments."""
    report_parser = subcommands.add_parser("report", help="verification report: error tables and plots (paper §5)")
    report_parser.add_argument("--params", type=Path, required=True,
                               help="parameter file (.json or .ssv) or ensemble (then with its band)")
    report_parser.add_argument("--data", action="append", type=Path, default=[], metavar="FILE",
                               help="measured test CSV to compare with; repeatable")
    report_parser.add_argument("--truth", type=Path,
                               help="parameter file of the true model: adds the §5 grid of synthetic cases")
    report_parser.add_argument("--kelvin-voigt-train", action="append", type=Path, default=[], metavar="FILE",
                               help="fit F = k*x + c*v on these files and show it beside the model")
    report_parser.add_argument("--plots", type=Path, help="directory for force-time/force-displacement PNGs")


def _add_compare(subcommands) -> None:
    """The ``compare`` command's arguments."""
    compare_parser = subcommands.add_parser(
        "compare", help="fit several models on training tests, weigh them on held-out files and a table, and "
                        "recommend one")
    _add_training_arguments(compare_parser)
    _add_model_option_arguments(compare_parser)
    _add_search_arguments(compare_parser)
    compare_parser.add_argument("--validate", action="append", type=Path, default=[], metavar="FILE",
                                help="validation test CSV, held out of the fits; repeatable (default: the training "
                                     "files, shown but not held out)")
    compare_parser.add_argument("--validate-kdyn", type=Path, metavar="TABLE",
                                help="dynamic-stiffness table held out of the fits (CSV amplitude_mm,frequency_hz,"
                                     "kdyn_N_per_mm,loss_angle_deg[,preload_mm][,weight]): each model predicts it")
    compare_parser.add_argument("--models", default=",".join(MODEL_NAMES),
                                help=f"comma-separated models, with options where wanted (default: "
                                     f"{','.join(MODEL_NAMES)}; --options gives every one the same)")
    compare_parser.add_argument("--coupling", default=None, metavar="LIST",
                                help="couplings to weigh on the held-out multi-axis files: none and radial (x, y) "
                                     "or spherical (x, y, z), comma-separated (e.g. none,radial)")
    compare_parser.add_argument("--validate-multiaxis", action="append", type=Path, default=[], metavar="FILE",
                                help="multi-axis test held out of the fits (CSV time_s,dx_mm,dy_mm,Fx_N,Fy_N[,dz_mm,"
                                     "Fz_N]); each model predicts it with each --coupling; repeatable")
    compare_parser.add_argument("--try-options", metavar="LIST",
                                help="options to weigh on the recommended model, comma-separated (e.g. band,iwan4): "
                                     "once the race has recommended one, it is fitted again with each of them added, "
                                     "and the recommendation is made again over all, so an option is kept only "
                                     "where it earns its parameters (default: what the first contact tries, given "
                                     "no --options: band where the sines' loops dissipate as friction does; none: "
                                     "try nothing)")
    compare_parser.add_argument("--out", type=Path, required=True,
                                help="directory for the fitted parameter files, the table (CSV) and the plots")
    compare_parser.add_argument("--no-race", action="store_true",
                                help="run every model's least-squares stages (default: a model whose screening "
                                     "shows it cannot win stops there, and its row says why)")
    compare_parser.add_argument("--every-ensemble", action="store_true",
                                help="sample the ensemble (profiles, posterior) of every fitted model, not only of "
                                     "the recommended one")
    compare_parser.add_argument("--leave-one-out", action="store_true",
                                help="fit the recommended model again to the training tests but one, for each test, "
                                     "and predict that one: a test matrix's leave-one-out score beside its training "
                                     "figures (leave_one_out.csv)")


def _add_predict(subcommands) -> None:
    """The ``predict`` command's arguments."""
    predict_parser = subcommands.add_parser(
        "predict", help="simulate a parameter file or an ensemble on a test's displacement")
    predict_parser.add_argument("--params", type=Path, required=True,
                                help="parameter file (.json, .ssv) or ensemble file (fit --ensemble)")
    predict_parser.add_argument("--data", type=Path, required=True,
                                help="CSV with time_s and displacement_* columns, or a multi-axis path (time_s,dx_mm,"
                                     "dy_mm[,dz_mm]); force columns are not needed")
    predict_parser.add_argument("--coupling", choices=tuple(COUPLED_AXES), metavar="COUPLING",
                                help="for a multi-axis path (required there): none, radial (x, y coupled) or "
                                     "spherical (x, y, z)")
    predict_parser.add_argument("--out", type=Path, required=True,
                                help="CSV to write: time_s,displacement_mm,force_N[,force_min_N,force_max_N]; for a "
                                     "multi-axis path time_s,dx_mm,dy_mm,Fx_N,Fy_N[,Fx_min_N,Fx_max_N,...]")
    predict_parser.add_argument("--plot", type=Path, help="also plot the prediction (PNG)")


def _add_design(subcommands) -> None:
    """The ``design`` command's arguments."""
    design_parser = subcommands.add_parser("design", help="rank candidate next tests by how much the ensemble disagrees")
    design_parser.add_argument("--ensemble", type=Path, required=True, help="ensemble file (fit --ensemble)")
    design_parser.add_argument("--noise", type=positive_float, metavar="N",
                               help="noise level [N] to compare with (default: the training tests')")
    design_parser.add_argument("--top", type=positive_int, default=3, help="how many to recommend (default 3)")
    design_parser.add_argument("--json", action="store_true", help="print the ranking as JSON")


def _add_fit_many(subcommands) -> None:
    """The ``fit-many`` command's arguments."""
    fleet_parser = subcommands.add_parser("fit-many", help="fit a fleet: every sub-folder of DIR with a tests.json")
    fleet_parser.add_argument("folder", type=Path, metavar="DIR")
    fleet_parser.add_argument("--out", type=Path, required=True, help="directory for <name>.json and summary.csv")
    _add_search_arguments(fleet_parser)


def _add_assemble(subcommands) -> None:
    """The ``assemble`` command's arguments."""
    assemble_parser = subcommands.add_parser(
        "assemble", help="build a six-axis parameter file (SixAxisBushing) from one fit per axis")
    assemble_parser.add_argument("--axis", action="append", default=[], metavar="NAME=FILE",
                                 help="an axis (x, y, z, rx, ry, rz) and its one-axis parameter or fit file; "
                                      "repeat for each axis. Rotational axes (rx, ry, rz) read in N.mm, rad, s")
    assemble_parser.add_argument("--out", type=Path, required=True, help="six-axis file to write (.json or .ssv)")
    assemble_parser.add_argument("--coupling", metavar="GROUPS", default=None,
                                 help="coupled groups: radial (x, y), spherical (x, y, z), conical (rx, ry), or "
                                      "two of them with a comma (radial,conical); the axes of a group need one "
                                      "model and one parameter set (a .json file)")
    missing = assemble_parser.add_mutually_exclusive_group()
    missing.add_argument("--rigid-missing", action="store_true",
                         help="an axis without a file becomes a stiff Kelvin-Voigt spring")
    missing.add_argument("--default", type=Path, metavar="SIX.json",
                         help="an axis without a file takes its set from this six-axis file")


def _add_import(subcommands) -> None:
    """The ``import`` command's arguments."""
    import_parser = subcommands.add_parser(
        "import", help="read another tool's bushing property file into a six-axis parameter file (Chrono's vehicle "
                       "JSON, Altair's .gbs, Adams' .bus)")
    import_parser.add_argument("file", type=Path, help="the property file: a Chrono vehicle JSON file with "
                                                       "\"Bushing Data\" (.json), an Altair bushing file (.gbs) or "
                                                       "an Adams nonlinear bushing file (.bus)")
    import_parser.add_argument("--bushing", metavar="NAME", help="the bushing, by its part's name, where the file "
                                                                 "holds several (\"Lower Control Arm\")")
    import_parser.add_argument("--joint", choices=("revolute", "universal", "spherical"),
                               help="a Chrono bushing's joint, whose free rotations take the file's DOF values "
                                    "(revolute: rz; universal: rx, ry; spherical: all three; default: they are "
                                    "left out, with a warning)")
    import_parser.add_argument("--out", type=Path, required=True, help="six-axis parameter file to write (.json: an "
                                                                         ".ssv does not say an axis's options)")


def _add_export(subcommands) -> None:
    """The ``export`` command's arguments."""
    from identification.property_files.export import OperatingPoint
    default = OperatingPoint()
    export_parser = subcommands.add_parser(
        "export", help="write a parameter file as another tool's bushing property file (Altair's .gbs): each "
                       "direction's static curve and an equivalent linear damping")
    export_parser.add_argument("params", type=Path, help="a six-axis parameter file, or a one-axis one with --direction")
    export_parser.add_argument("--format", choices=("gbs",), default="gbs", help="the property file's format (gbs)")
    export_parser.add_argument("--direction", metavar="DIR", help="the direction of a one-axis file: FX, FY, FZ, TX, "
                                                                  "TY or TZ")
    for field, kind, metavar, words in (
            ("range_mm", float, "R", "the translations' deflection range, -R to R [mm]"),
            ("range_rad", float, "R", "the rotations' range, -R to R [rad]"),
            ("points", int, "N", "the spline's points, 2 to 32"),
            ("amplitude_mm", float, "X", "the damping's sine amplitude on translations [mm]"),
            ("amplitude_rad", float, "X", "the damping's sine amplitude on rotations [rad]"),
            ("frequency_hz", float, "F", "the damping's sine frequency [Hz]")):
        value = getattr(default, field)
        export_parser.add_argument("--" + field.replace("_", "-"), type=kind, default=value, metavar=metavar,
                                   help=f"{words} (default {value:g})")
    export_parser.add_argument("--out", type=Path, required=True, help="the property file to write (.gbs)")


def _add_characterise(subcommands) -> None:
    """The ``characterise`` command's arguments."""
    characterise_parser = subcommands.add_parser(
        "characterise", help="dynamic stiffness |K*| and loss angle over amplitudes and frequencies (data sheet)")
    characterise_parser.add_argument("--params", type=Path, required=True,
                                     help="parameter file (.json, .ssv) or ensemble file (then with min/max columns)")
    characterise_parser.add_argument("--model", type=model_name, metavar="MODEL", help="check the file is for this model")
    characterise_parser.add_argument("--amplitudes-mm", type=number_list, metavar="LIST",
                                     default=",".join(map(str, DEFAULT_AMPLITUDES_MM)),
                                     help="sine amplitudes [mm], comma-separated (default %(default)s)")
    characterise_parser.add_argument("--frequencies-hz", type=number_list, metavar="LIST",
                                     default=",".join(map(str, DEFAULT_FREQUENCIES_HZ)),
                                     help="frequencies [Hz], comma-separated (default %(default)s)")
    characterise_parser.add_argument("--preload-mm", type=float, default=0.0, metavar="P",
                                     help="static displacement the sines are about [mm] (default 0)")
    characterise_parser.add_argument("--temperatures-c", type=number_list, metavar="LIST",
                                     help="rubber temperatures [degC], comma-separated, for a model with a "
                                          "temperature law (wlf, arrhenius): the table at each, with a "
                                          "temperature_K column, and the sheet over temperature as a plot")
    characterise_parser.add_argument("--out", type=Path, required=True, help="table to write (CSV)")
    characterise_parser.add_argument("--plots", type=Path, help="directory for the data-sheet plots (PNG)")
    characterise_parser.add_argument("--json", action="store_true", help="print a summary as JSON")


def run(args: argparse.Namespace) -> int:
    """Run the command ``args`` names (``build_parser``'s); the exit status as :func:`main`."""
    with warnings.catch_warnings(), signals_raise():
        # A user reads the warning, not where in our code it was raised.
        warnings.showwarning = lambda message, category, *rest, **keywords: commands.print_warning(str(message))
        try:
            _require_extras(args)
            return COMMANDS[args.command](args)
        # OSError: a file that could not be read or written after all
        except (IdentificationError, ParameterError, EngineError, UsageError, MissingExtraError,
                OSError) as exc:
            print(f"error: {exc}", file=sys.stderr)
            return 2
        except KeyboardInterrupt as stop:
            # Interrupted (SIGINT, SIGTERM); the engines stopped their workers on the way here
            return _stopped(stop)
        except SystemError as error:
            # a signal that lands inside compiled code (numba loading its cache) surfaces as a
            # SystemError whose cause is the Interrupted our handler raised: the same stop
            stop = _interrupt_behind(error)
            if stop is None:
                raise
            return _stopped(stop)


def _interrupt_behind(error: BaseException) -> KeyboardInterrupt | None:
    """The interrupt among ``error``'s causes and contexts, or None."""
    seen = set()
    while error is not None and id(error) not in seen:
        if isinstance(error, KeyboardInterrupt):
            return error
        seen.add(id(error))
        error = error.__cause__ or error.__context__
    return None


def _stopped(stop: KeyboardInterrupt) -> int:
    """The one line and the exit status of a command stopped by a signal."""
    close_open_bars()
    sys.stdout.flush()
    print(interrupted_message(), file=sys.stderr)
    return stop.exit_status if isinstance(stop, Interrupted) else 128 + signal.SIGINT


COMMANDS = {"fit": commands.fit_command, "sensitivity": commands.sensitivity_command,
            "report": commands.report_command, "compare": commands.compare_command,
            "predict": commands.predict_command, "design": commands.design_command,
            "fit-many": commands.fit_many_command, "assemble": commands.assemble_command,
            "characterise": commands.characterise_command, "import": commands.import_command,
            "export": commands.export_command}
NEEDS_FIT_EXTRA = ("fit", "compare", "fit-many")
"""Commands that fit: they need numba and the optimizers (the ``fit`` extra). The others only
simulate, which the base install does too, as plain Python (``fmu_src.kernels.jit``), slower."""


def _require_extras(args) -> None:
    """Refuse, before any work, a command whose extra is not installed (one line, exit 2); say
    once that a simulating command runs uncompiled without numba."""
    if args.command in NEEDS_FIT_EXTRA:
        require("fit", f"the {args.command} command")
    elif args.command != "assemble" and not jit.AVAILABLE:
        print(f"note: {jit.MISSING}", file=sys.stderr)
    if getattr(args, "plots", None) is not None or getattr(args, "plot", None) is not None:
        require("plot", f"{'--plots' if getattr(args, 'plots', None) is not None else '--plot'}")
    if getattr(args, "scheduler", None) is not None:
        require("dask", "--scheduler")


def _add_training_arguments(parser) -> None:
    group = parser.add_argument_group("training tests (CSV time_s,displacement_mm,force_N[,velocity_mm_s]"
                                      "[,temperature_C or temperature_K])")
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
    group.add_argument("--multiaxis", action="append", type=Path, default=[], metavar="FILE",
                       help="multi-axis test (CSV time_s,dx_mm,dy_mm,Fx_N,Fy_N[,dz_mm,Fz_N][,vx_mm_s,...]), alone or "
                            "with the one-axis tests; repeatable")


def _add_model_option_arguments(parser) -> None:
    """``--options``, ``--static``, ``--backbone-knots``, ``--fix`` (``model_options``)."""
    group = parser.add_argument_group("model options (a measured backbone, travel limits, the rig's offsets)")
    group.add_argument("--options", metavar="LIST",
                       help="options every model gets, comma-separated: backbone<K> (a static curve of K knots), "
                            "limits (a travel limit each side), maxwell (a Maxwell element in parallel), iwan<N> (N "
                            "spring-sliders in parallel: distributed slip), band (a band brake's self-energizing "
                            "friction through a play with a progressive contact), series (a compliance in series), "
                            "rig (the rig's displacement and load-cell zeros, fitted and kept out of the FMU), wlf "
                            "or arrhenius (a temperature law: each test runs at its file's temperature_C or "
                            "temperature_K column); none: no "
                            "option (compare, given no --options, assumes the ones its training tests show and says "
                            "which and why; named options, or none, turn that off)")
    group.add_argument("--backbone-knots", type=number_list, metavar="LIST",
                       help="the backbone's knot positions [mm], increasing (held; their forces are fitted, or read "
                            "off --static)")
    group.add_argument("--static", type=str, metavar="FILE",
                       help="a quasi-static test (a slow triangle or ramp): the backbone read off it (the mean of its "
                            "loading and unloading branches) at --backbone-knots or 9 knots (compare without "
                            "--options: 9 or 17, as the curve needs), and held; a training test too")
    group.add_argument("--fix", action="append", default=[], metavar="NAME=VALUE",
                       help="hold a parameter at a value (the model's units); repeatable")


def _add_search_arguments(parser) -> None:
    group = parser.add_argument_group("search")
    group.add_argument("--preset", default="default", choices=list(PRESETS),
                       help="; ".join(f"{name}: {describe(name)}" for name in PRESETS))
    group.add_argument("--seed", type=non_negative_int, default=0, help="root seed of the search (default 0)")
    group.add_argument("--screening", type=positive_int, metavar="N",
                       help=f"Sobol points screened (default preset: {PRESETS['default'].screening})")
    group.add_argument("--starts", type=positive_int, metavar="N",
                       help=f"least-squares starts of the first stage (default {PRESETS['default'].stages[0][0]}; "
                            "later stages shrink in proportion)")
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
