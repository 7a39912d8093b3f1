"""The command line ``bushing-identify`` (``python -m identification``).

- ``arguments``: the commands and their arguments, checked before any work starts, and ``main``;
- ``commands``: what each command does;
- ``model_options``: ``--options``, ``--static``, ``--backbone-knots``, ``--fix``: the model a command
  runs and the parameters it holds.

May import everything else of ``identification``; nothing imports it but ``__main__`` and the
console script.
"""
from identification.cli.arguments import main

__all__ = ["main"]
