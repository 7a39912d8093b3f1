"""The suite's own pytest options: slow tests, and the rounding variants of the optimizer tests.

``slow``: tests that take a minute or more (a full fit through the command line, the
determinism checks on three engines). Skipped unless ``--run-slow``; ``.ci/run`` runs them.

``optimizer``: tests whose outcome rests on an optimizer's path (a fit's stages, its
agreement, its ensemble). Another processor rounds differently (a BLAS kernel, a numba
target, a thread count), and a different rounding takes the optimizer down another path. Such
a test must assert what holds on every path, and these options make another path here:

- ``--perturb-force REL``: every rig test's measured force is multiplied by 1 + REL*r, r a
  standard normal draw per sample (a fixed seed), as the test is made (``RigTest``): a REL of
  1e-12 is the size of a rounding difference, and it changes every later rounding.
- ``--seed-offset N``: every fit's seed is N more than the test gives it.

``.ci/run`` runs the optimizer tests once with ``--perturb-force 1e-12`` and once with
``--perturb-force 1e-12 --seed-offset 1``. The variants reach what a fit computes in this
process and what its worker processes compute from it (the objective travels with the
perturbed forces); a fleet, whose fits run in worker processes, is not an optimizer test.
"""
from __future__ import annotations

import contextlib
import dataclasses
import inspect

import numpy as np
import pytest

PERTURBATION_SEED = 20261125


def pytest_addoption(parser):
    group = parser.getgroup("bushing", "boucwen-bushing test suite")
    group.addoption("--run-slow", action="store_true", help="also run the tests marked slow (.ci/run does)")
    group.addoption("--perturb-force", type=float, default=0.0, metavar="REL",
                    help="optimizer tests: multiply every measured force by 1 + REL*N(0, 1) (e.g. 1e-12)")
    group.addoption("--seed-offset", type=int, default=0, metavar="N",
                    help="optimizer tests: add N to every fit's seed")


def pytest_configure(config):
    config.addinivalue_line("markers", "slow: takes a minute or more; runs with --run-slow (CI runs it)")
    config.addinivalue_line("markers", "optimizer: its outcome rests on an optimizer's path; runs under "
                                       "--perturb-force and --seed-offset in CI")


def pytest_collection_modifyitems(config, items):
    if config.getoption("--run-slow"):
        return
    skip = pytest.mark.skip(reason="slow: run with --run-slow (.ci/run runs it)")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip)


@contextlib.contextmanager
def rounding_variant(config):
    """Apply ``--perturb-force`` and ``--seed-offset`` while the context is open."""
    relative, offset = config.getoption("--perturb-force"), config.getoption("--seed-offset")
    with pytest.MonkeyPatch.context() as patch:
        if relative:
            from identification.measured.rig_tests import RigTest
            made = RigTest.__post_init__

            def perturbed(test):
                m = test.measurement
                r = np.random.default_rng(PERTURBATION_SEED).standard_normal(m.force_N.size)
                object.__setattr__(test, "measurement", dataclasses.replace(m, force_N=m.force_N * (1.0 + relative * r)))
                made(test)

            patch.setattr(RigTest, "__post_init__", perturbed)
        if offset:
            from identification.fitting import search
            begin = search.begin     # every search starts there: fit's and compare's

            def offset_seed(*args, **kwargs):
                bound = inspect.signature(begin).bind(*args, **kwargs)
                request = bound.arguments["request"]
                bound.arguments["request"] = dataclasses.replace(request, seed=request.seed + offset)
                return begin(*bound.args, **bound.kwargs)

            patch.setattr(search, "begin", offset_seed)
        yield


@pytest.fixture(autouse=True)
def _optimizer_rounding_variant(request):
    """Tests marked ``optimizer`` run under the rounding variant the options ask for (a fixture
    of wider scope that fits would have to apply :func:`rounding_variant` itself)."""
    if request.node.get_closest_marker("optimizer") is None:
        yield
        return
    with rounding_variant(request.config):
        yield
