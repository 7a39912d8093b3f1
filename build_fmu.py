"""Build a bushing FMU, the command line ``bushing-build-fmu`` (``python build_fmu.py``)::

    python build_fmu.py [--model NAME] [--params FILE] [--out DIR]
    python build_fmu.py --native [--fmi-version 2|3] [--platforms all|P,Q] [--model NAME] [--params FILE]
    python build_fmu.py --release [--out DIR] [--allow-missing-platforms]

writes ``DIR/<Identifier>.fmu`` of the model NAME (any of ``fmu_src/model/registry.py``, or
``six_axis``: six axes, each one of the models) with the set in FILE (project JSON or SSP 1.0
``.ssv``, the paper's N-mm-s units; default: the model's set in ``data/``) as its start values:
the pythonfmu FMU (FMI 2.0 co-simulation, :func:`build_fmu`), the native one (compiled C, FMI 2.0
or 3.0, co-simulation and model exchange, :func:`build_native_fmu`), or the release bundle of
every model's native FMU for every platform (:func:`build_release`). The builders live in
``fmu_src/fmi/``: ``pythonfmu_package.py``, ``native/``, ``release.py``.
"""
from __future__ import annotations

import argparse
import sys

from fmu_src import __version__
from fmu_src.fmi.fmu_inputs import SIX_AXIS, SIX_AXIS_DEFAULT_FILE, BuildError, model_of_file
from fmu_src.fmi.native.build import NativeBuildError, build_native_fmu, chosen_platforms
from fmu_src.fmi.pythonfmu_package import build_fmu
from fmu_src.fmi.release import CHECKSUMS, README, RELEASE_DIR, build_release, missing_text
from fmu_src.model.parameter_specs import ParameterError
from fmu_src.model.registry import DEFAULT_MODEL, MODEL_CHOICES, MODEL_NAMES

__all__ = ["build_fmu", "build_native_fmu", "build_release", "main"]


def parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="bushing-build-fmu",
        description="Build a bushing FMU (pythonfmu, FMI 2.0 co-simulation; or --native: compiled C, FMI 2.0 "
                    "or 3.0, co-simulation and model exchange) with a parameter set as its start values; or "
                    "--release: the release bundle of native FMUs.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    parser.add_argument("--model", choices=(*MODEL_CHOICES, SIX_AXIS), metavar="MODEL",
                        help=f"{', '.join(MODEL_NAMES)} or {SIX_AXIS} (six uncoupled axes, each one of the models); "
                             f"default: the model --params is for, else {DEFAULT_MODEL} (the paper's eqs. 1-5)")
    parser.add_argument("--params", help="parameter set of the model, project JSON or SSP 1.0 .ssv "
                                         "(paper N-mm-s units); default: the paper's Table 5 for the "
                                         "proposed model, data/params_<model>_fit_synthetic_table5.json for the "
                                         f"others, data/{SIX_AXIS_DEFAULT_FILE} for six_axis")
    parser.add_argument("--out", help="output directory (default: dist/ in the working directory; "
                                      f"with --release: {RELEASE_DIR}/)")
    parser.add_argument("--native", action="store_true",
                        help="build the native FMU: compiled C, co-simulation and model exchange, no Python in the "
                             "host (linux64 with the system's C compiler, win64 where mingw-w64 is installed; "
                             "more with --platforms)")
    parser.add_argument("--fmi-version", type=int, choices=(2, 3),
                        help="FMI version of the native FMU (default 2; the pythonfmu FMU is FMI 2 only)")
    parser.add_argument("--platforms", metavar="all|P,Q",
                        help="with --native: the binaries to build, 'all' or a comma list of FMI platform names "
                             "(FMI 2: linux64, win64, darwin64, aarch64-linux; FMI 3: x86_64-linux, "
                             "x86_64-windows, x86_64-darwin, aarch64-darwin, aarch64-linux); default linux64 "
                             "and win64 (FMI 3: x86_64-linux, x86_64-windows), each where its compiler is here")
    parser.add_argument("--release", action="store_true",
                        help="build the release bundle: the native FMU of every model, FMI 2 and 3, binaries for "
                             "Linux (x86_64, aarch64), Windows and macOS (x86_64, arm64) and sources in each, each "
                             f"with its default parameter set; the default sets as .ssv, {README} and {CHECKSUMS}. "
                             "Its parameters are start values: one binary per model serves every parameter set, "
                             "no compiler needed to apply one")
    parser.add_argument("--allow-missing-platforms", action="store_true",
                        help="with --release: make the bundle without a platform whose compiler is missing "
                             "(the README names it) instead of refusing")
    return parser


def main(argv: list[str] | None = None) -> int:
    command = parser()
    args = command.parse_args(argv)
    if args.release and (args.model or args.params or args.fmi_version or args.native):
        command.error("--release builds every model, FMI 2 and 3, with its default parameter set: it takes "
                      "no --model, --params, --fmi-version or --native")
    if args.allow_missing_platforms and not args.release:
        command.error("--allow-missing-platforms goes with --release")
    if args.platforms and not args.native:
        command.error("--platforms goes with --native (--release builds every platform)")
    out = args.out or (RELEASE_DIR if args.release else "dist")
    try:
        if args.release:
            bundle = build_release(out, args.allow_missing_platforms)
            if bundle.missing:
                print(f"warning: the bundle has no {missing_text(bundle.missing)}", file=sys.stderr)
            print(f"wrote {bundle.folder}: {len(bundle.fmus)} FMUs, {len(bundle.parameter_files)} parameter sets, "
                  f"{README}, {CHECKSUMS} ({bundle.seconds:.0f} s)")
            return 0
        model = args.model or (model_of_file(args.params) if args.params else DEFAULT_MODEL)
        if args.native:
            version = args.fmi_version or 2
            build = build_native_fmu(args.params, out, model, version, chosen_platforms(args.platforms, version))
            path = build.path
            for platform, why in build.skipped.items():
                print(f"note: no {platform} binary: {why}", file=sys.stderr)
        elif args.fmi_version not in (None, 2):
            raise BuildError("--fmi-version 3 needs --native (pythonfmu builds FMI 2.0 FMUs only)")
        else:
            path = build_fmu(args.params, out, model)
    except (ParameterError, BuildError, NativeBuildError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:   # an output directory that cannot be made or written
        print(f"error: --out {out}: {exc.strerror or exc}", file=sys.stderr)
        return 2
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
