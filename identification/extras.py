"""Which optional parts of the install (the package's extras) a feature needs, and the one-line
error that names the extra to install when it is missing.

The base install builds and runs the FMUs, reads and writes parameter files and simulates;
``fit`` adds the identification (numba, pymoo, emcee, tqdm, matplotlib, threadpoolctl),
``plot`` matplotlib, ``dask`` a Dask cluster, ``cosim`` libcosim (pyproject.toml lists them).
"""
from __future__ import annotations

import importlib.util
import sys

from identification.errors import MissingExtraError

DISTRIBUTION = "boucwen-bushing"
EXTRAS = {
    "fit": ("numba", "threadpoolctl", "emcee", "pymoo", "tqdm", "matplotlib"),
    "plot": ("matplotlib",),
    "dask": ("distributed",),
    "cosim": ("libcosimpy",),
}


def missing_modules(extra: str) -> list[str]:
    """The modules of ``extra`` that cannot be imported here (without importing them)."""
    missing = []
    for module in EXTRAS[extra]:
        if module in sys.modules:
            if sys.modules[module] is None:   # blocked, as a test does to stand for "not installed"
                missing.append(module)
        elif importlib.util.find_spec(module) is None:
            missing.append(module)
    return missing


def require_or_exit(extra: str, feature: str) -> None:
    """For a script: :func:`require`, its error as one ``error:`` line on stderr and exit status 2."""
    try:
        require(extra, feature)
    except MissingExtraError as exc:
        print(f"error: {exc}", file=sys.stderr)
        sys.exit(2)


def require(extra: str, feature: str) -> None:
    """Raise :class:`MissingExtraError` if ``feature`` cannot run for want of ``extra``."""
    missing = missing_modules(extra)
    if missing:
        raise MissingExtraError(f"{feature} needs the '{extra}' extra ({', '.join(missing)} "
                                f"{'is' if len(missing) == 1 else 'are'} not installed): "
                                f"pip install '{DISTRIBUTION}[{extra}]'")
