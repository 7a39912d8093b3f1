"""Fit a fleet of bushings: every sub-folder of a directory is one bushing.

    DIR/<name>/tests.json    the manifest (``identification.measured.rig_tests``) and its CSV files

``fit_many(DIR, OUTDIR)`` fits each bushing as one task of the engine (local processes or a
Dask cluster; inside a task the fit runs serially, so every bushing's file is the one
``fit --workers 1`` writes, bit for bit), and writes

- ``OUTDIR/<name>.json``: the parameter file with its provenance, as soon as it is fitted;
- ``OUTDIR/summary.csv``: name, misfit, converged, training NRMSE per file, seconds, error.

The measurements are read here and sent to the workers (which need no access to DIR). A
bushing whose folder, data or fit fails for any reason is a row with its error (and the
exception's type) in the summary, and the fleet goes on; if the engine itself fails (a worker
process killed), the bushings not yet fitted get that error, and the summary is still written.
Stopped by Ctrl-C or SIGTERM, the fleet keeps the bushings' files already written and writes no
summary. Every file is written whole or not at all (``interrupt.writing``). One progress bar
over the fleet.
"""
from __future__ import annotations

import csv
import json
import time
import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path

from fmu_src.model.registry import DEFAULT_MODEL, get_model
from fmu_src.model.parameter_specs import ParameterError
from fmu_src.parameter_files import parameter_document
from identification.fitting.engine import make_engine
from identification.fitting.presets import FitOptions
from identification.errors import FitNotConvergedWarning, MeasurementError
from identification.interrupt import writing
from identification.fitting.progress import bar as progress_bar
from identification.measured.rig_tests import load_manifest

MANIFEST = "tests.json"


@dataclass
class FleetRow:
    name: str
    misfit: float = float("nan")
    converged: bool = False
    nrmse: dict[str, float] = field(default_factory=dict)   # per training file, by its path in the manifest
    seconds: float = 0.0
    error: str = ""


@dataclass(frozen=True)
class _Job:
    name: str
    tests: list
    labels: list           # each test's path relative to the bushing's folder
    model: str
    options: FitOptions    # the fleet's, to run serially in the worker


def _fit_bushing(_, job: _Job):
    """One bushing, fitted serially in a worker; returns (row, parameter document or None)."""
    from identification.fitting.engine import SerialEngine
    from identification.fitting.fit import fit
    started = time.perf_counter()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FitNotConvergedWarning)
            result = fit(job.tests, job.model, job.options, engine=SerialEngine())
    except Exception as exc:   # noqa: BLE001 - one bushing's failure must not stop the fleet; its row says why
        return FleetRow(job.name, seconds=time.perf_counter() - started, error=f"{type(exc).__name__}: {exc}"), None
    provenance = dict(result.provenance(), data=[t.measurement.source for t in job.tests])
    document = parameter_document(result.parameters.parameters, result.model, provenance)
    row = FleetRow(job.name, result.misfit, result.converged,
                   {label: fitted.nrmse for label, fitted in zip(job.labels, result.tests)},
                   time.perf_counter() - started)
    return row, document


def fit_many(folder: str | Path, out_dir: str | Path, options: FitOptions | None = None,
             **keywords) -> list[FleetRow]:
    """Fit every bushing under ``folder`` (see the module docstring); returns the summary rows
    in the order of the folder names. The keywords are ``fit``'s (``FitOptions``): ``workers``
    and ``scheduler`` run the fleet, ``progress`` draws its bar, the others go to every fit,
    which runs serially in its worker; ``ensemble=False``: each fit skips its ensemble, which
    the fleet's files do not hold."""
    options = FitOptions.of(options, **keywords)
    each = replace(options, workers=None, scheduler=None, engine=None, progress=False)
    folder, out_dir = Path(folder), Path(out_dir)
    if not folder.is_dir():
        raise MeasurementError(f"fleet folder {folder} does not exist or is not a directory")
    bushings = sorted(p for p in folder.iterdir() if p.is_dir())
    if not bushings:
        raise MeasurementError(f"fleet folder {folder} has no sub-folders (one per bushing, each with {MANIFEST})")
    out_dir.mkdir(parents=True, exist_ok=True)
    rows: dict[str, FleetRow] = {}
    jobs = []
    for path in bushings:
        try:
            manifest = load_manifest(path / MANIFEST)
            model = manifest.model or DEFAULT_MODEL
            try:
                model = get_model(model).name        # a registered model, with options where named
            except ValueError as exc:         # the registry's words: the models, or the options
                raise MeasurementError(f"{path / MANIFEST}: {exc}") from None
            labels = [_label(t.measurement.source, path) for t in manifest.tests]
            jobs.append(_Job(path.name, manifest.tests, labels, model, each))
        except (MeasurementError, ParameterError, OSError, UnicodeDecodeError) as exc:
            rows[path.name] = FleetRow(path.name, error=f"{type(exc).__name__}: {exc}")

    bar = progress_bar(len(bushings), "bushings", "bushing", options.progress, leave=True)
    if bar is not None:
        bar.update(len(rows))

    def finished(index, result):
        row, document = result
        rows[row.name] = row
        if document is not None:
            with writing(out_dir / f"{row.name}.json") as temporary:
                temporary.write_text(json.dumps(document, indent=2) + "\n", encoding="utf-8")
        if bar is not None:
            bar.update(1)
            bar.set_postfix_str(f"{row.name}: {'converged' if row.converged else 'NOT converged'}"
                                if not row.error else f"{row.name}: error")

    try:
        if jobs:
            with make_engine(options.workers, options.scheduler) as engine:
                engine.map(_fit_bushing, jobs, None, each=finished, chunk_size=1)
    except Exception as exc:   # noqa: BLE001 - the engine failed: record it, keep what was fitted
        for job in jobs:
            rows.setdefault(job.name, FleetRow(job.name, error=f"not fitted: the engine failed "
                                                               f"({type(exc).__name__}: {exc})"))
    finally:
        # a KeyboardInterrupt (Ctrl-C, SIGTERM) passes the `except` above: the fleet stops
        # without a summary, and an earlier run's summary.csv stays as it was
        if bar is not None:
            bar.close()
    ordered = [rows.get(path.name, FleetRow(path.name, error="not fitted")) for path in bushings]
    write_summary(out_dir / "summary.csv", ordered)
    return ordered


def _label(source: str, folder: Path) -> str:
    try:
        return Path(source).relative_to(folder).as_posix()
    except ValueError:
        return Path(source).name


def write_summary(path: Path, rows: list[FleetRow]) -> Path:
    files = sorted({name for row in rows for name in row.nrmse})
    with writing(path) as temporary, open(temporary, "w", newline="", encoding="utf-8") as stream:
        writer = csv.writer(stream)
        writer.writerow(["name", "misfit", "converged", *[f"nrmse_{name}" for name in files], "seconds", "error"])
        for row in rows:
            writer.writerow([row.name, f"{row.misfit:.6g}", row.converged,
                             *[f"{row.nrmse[name]:.6g}" if name in row.nrmse else "" for name in files],
                             f"{row.seconds:.1f}", row.error])
    return path
