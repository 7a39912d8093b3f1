"""The identification's error and warning types, all of them: input it cannot use, as opposed to a bug.

The command line turns the errors (and ``fmu_src.model.parameter_specs.ParameterError``) into a
one-line ``error: ...`` with exit status 2; anything else is a bug and keeps its traceback. The
warnings say what a result's reader must know; the command line prints them as one line each.

The modules that raise them re-export them under their old names
(``identification.measured.measurements.MeasurementError``, ``identification.measured.rig_tests.ManifestError``,
``identification.fitting.result.FitNotConvergedWarning``, ``identification.fitting.engine.EngineError``,
``identification.extras.MissingExtraError``, ``identification.cli.commands.UsageError``,
``identification.forward.dynamic_stiffness.CharacterisationWarning``), and ``identification`` exports
the ones a user catches. This module imports nothing from the package (every module may import it).
"""


# ------------------------------------------------------------------------------------------ errors
class IdentificationError(ValueError):
    """Input the identification cannot use (a file, an option, an ensemble for a task); the
    message names the value, its unit and what is allowed. Raised by the front door (``fit``,
    ``simulate``, ``predict``, ``characterise``, ``compare``, ...) and by the readers of its
    input, e.g. ``load_kdyn_table`` for a dynamic-stiffness table that cannot be used."""


class MeasurementError(IdentificationError):
    """A measurement file that cannot be used; the message names the file, column and row.
    Raised by ``load_measurement`` (a missing column, a value that is not a number, time that
    does not increase, ...) and by ``fit-many`` for a fleet folder that cannot be read."""


class ManifestError(MeasurementError):
    """A tests manifest or a set of training tests that cannot be used. Raised by
    ``load_manifest`` and ``training_tests`` (a manifest that is not valid JSON, an unknown test
    kind, a rise time for a test that is not a step or missing for a step, no tests at all, ...)."""


class UsageError(Exception):
    """A command-line option with a value that cannot be used. Raised by the commands of
    ``python -m identification`` (``identification.cli.commands``) before any work, e.g. for an
    output path that cannot be written or options that contradict each other."""


class EngineError(RuntimeError):
    """The engine cannot run tasks. Raised by ``identification.fitting.engine`` when the Dask scheduler
    cannot be reached within the timeout, has no workers, has workers with more than one thread,
    or has had no worker for too long during a fit."""


class MissingExtraError(ImportError):
    """A feature whose extra is not installed; the message says which one to install. Raised by
    ``identification.extras.require`` (e.g. a fit without numba: the ``fit`` extra)."""


# ---------------------------------------------------------------------------------------- warnings
class MeasurementWarning(UserWarning):
    """A measurement that loads but looks implausible for a bushing test (likely wrong units).
    Warned by ``load_measurement`` (a displacement, force, stiffness or sample rate outside what
    a bushing test has), naming the column, what it found and the likely mistake."""


class FitNotConvergedWarning(UserWarning):
    """A fit that ended above its floor or whose starts do not agree. Warned by ``fit``
    (its text is ``FitResult.warning``; ``FitResult.converged`` is then False)."""


class EnsembleWarning(UserWarning):
    """Warned by a fit whose posterior cannot be sampled as set (``ensemble.SamplingFailed``): its
    ensemble, and so its band, holds the prediction profiles' ends and the final starts only."""


class CharacterisationWarning(UserWarning):
    """Warned by ``characterise`` when a case does not reach its steady state within the cycle
    cap (its numbers are then the last cycle's) or an ensemble member fails on a case; by
    ``characterise`` and ``load_kdyn_table`` when an amplitude or a frequency is implausibly
    large (a unit mistake, most likely); by a fit on a table when its check of the table at the
    result cannot converge."""
