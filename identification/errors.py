"""The identification's own error type: input it cannot use, as opposed to a bug.

The command line turns these (and ``ParameterError``, ``EngineError``) into a one-line
``error: ...`` with exit status 2; anything else is a bug and keeps its traceback.
"""


class IdentificationError(ValueError):
    """Input the identification cannot use (a file, an option, an ensemble for a task); the
    message names the value, its unit and what is allowed."""
