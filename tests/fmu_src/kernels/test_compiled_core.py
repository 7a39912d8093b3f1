"""The numba-compiled core (a population of parameter sets at once) against the FMU."""
import numpy as np
import pytest

from conftest import paper_parameters
from fmu_src.model.registry import MODELS
from fmu_src.models.proposed_model import PARAMETER_NAMES
from identification.forward.population import simulate_population_held
from identification.measured.signals import Random, Sine, sample_times
from fmu_harness import simulate_with_fmpy


def population():
    """The paper's tables, the stiff c1 = 0.01 set, and four seeded perturbations of Table 5."""
    sets = [paper_parameters(t) for t in ("table2", "table4", "table5")]
    sets.append(dict(paper_parameters("table5"), c1=0.01))
    rng = np.random.default_rng(11)
    for _ in range(4):
        sets.append({name: value * rng.uniform(0.7, 1.3) for name, value in paper_parameters("table5").items()})
    return sets


@pytest.mark.parametrize("protocol, duration_s", [(Sine(2.0, 10.0), 0.2), (Random(2.0, 0.3, seed=4), 0.3)])
def test_compiled_forces_agree_with_the_fmu_for_every_candidate(fmu_path, protocol, duration_s):
    t = sample_times(duration_s, 1000.0)
    x, v = protocol.signals(t)
    sets = population()
    compiled = simulate_population_held(sets, t, x, v)
    for params, forces in zip(sets, compiled):
        via_fmu = simulate_with_fmpy(fmu_path, t, x, v, start_values=params)
        np.testing.assert_allclose(forces, via_fmu, rtol=1e-9, atol=1e-9 * np.max(np.abs(via_fmu)))


def test_failing_candidate_gets_nan_without_disturbing_the_others():
    # With n2 = 1.5 the loading branch dz2/dxi = A2 + 2.7*|z2|^1.5 reaches infinity within a
    # few millimetres: a 2 mm displacement jump overflows it, while Table 5 stays finite.
    t = sample_times(0.05, 1000.0)
    x = np.concatenate([np.zeros(20), np.full(t.size - 20, 2.0)])
    v = np.zeros(t.size)
    good = paper_parameters("table5")
    forces = simulate_population_held([good, dict(good, n2=1.5), good], t, x, v)
    assert np.all(np.isfinite(forces[0])) and np.array_equal(forces[0], forces[2])
    # The step from sample 20 (where x jumps) gives the force at sample 21.
    assert np.all(np.isfinite(forces[1][:21])) and np.all(np.isnan(forces[1][21:]))


def test_parameter_matrix_rejects_wrong_shapes():
    with pytest.raises(ValueError, match=str(len(PARAMETER_NAMES))):
        simulate_population_held(np.ones((3, 5)), np.arange(3.0), np.zeros(3), np.zeros(3))


def random_population(model: str, count: int, seed: int):
    """``count`` sets of ``model``: its default set with each value scaled by 0.7-1.3."""
    from fmu_src.model.registry import get_model
    from fmu_src.parameter_files import read_parameter_set
    from conftest import REPO
    bushing = get_model(model)
    default = read_parameter_set(REPO / "data" / bushing.default_file, model).parameters
    base = np.array([default[name] for name in bushing.parameter_names])
    return bushing.parameter_names, base * np.random.default_rng(seed).uniform(0.7, 1.3, (count, base.size))


@pytest.mark.parametrize("model", list(MODELS))
def test_compiled_forces_equal_the_python_kernels_bitwise_for_every_model(model):
    # One definition, two paths: the FMU's plain-Python kernels (tests/python_core.py steps them
    # as the FMU does) and their numba-compiled copies must give the same floats.
    from python_core import simulate_python_core
    names, matrix = random_population(model, 40 if model == "proposed" else 12, 2)
    t = sample_times(0.3, 1000.0)
    x, v = Random(2.0, 0.3, seed=5).signals(t)
    x = x + 0.01 * np.sin(2 * np.pi * 50 * t)       # off the held path: a displacement jump at every step
    compiled = simulate_population_held(matrix, t, x, v, model=MODELS[model])
    for row, forces in zip(matrix, compiled):
        python = simulate_python_core(dict(zip(names, row)), t, x, v, model=model)
        np.testing.assert_array_equal(forces, python)


CACHE_PROBE = """
import numpy as np
from fmu_src.model.registry import get_model
from identification.forward import population as compiled_core
t = np.linspace(0.0, 0.02, 21)
compiled_core.simulate_population_held([{"k": 1.0, "c": 1.0, "preload": 0.0}], t, t, np.ones_like(t),
                                       model=get_model("kelvin_voigt"))
module = compiled_core.compiled_model(get_model("kelvin_voigt"))
stats = module._simulate_population.stats
print(module.__file__, len(stats.cache_hits), len(stats.cache_misses))
"""


def run_cache_probe(cache_dir):
    import os
    import subprocess
    import sys
    from conftest import REPO
    environment = dict(os.environ, BUSHING_CACHE_DIR=str(cache_dir), PYTHONPATH=str(REPO))
    result = subprocess.run([sys.executable, "-c", CACHE_PROBE], env=environment, capture_output=True, text=True,
                            timeout=600, cwd=REPO)
    assert result.returncode == 0, result.stderr[-3000:]
    path, hits, misses = result.stdout.split()
    return path, int(hits), int(misses)


@pytest.mark.slow
def test_the_compiled_model_is_cached_on_disk_for_the_next_process(tmp_path):
    path, hits, misses = run_cache_probe(tmp_path)
    assert (hits, misses) == (0, 1)            # the first process compiles ...
    assert path.startswith(str(tmp_path))
    assert any(tmp_path.glob("__pycache__/*_population_loop*.nbi"))
    assert run_cache_probe(tmp_path) == (path, 1, 0)   # ... the next one loads the machine code


UNWRITABLE_PROBE = """
import warnings
import numpy as np
from fmu_src.model.registry import get_model
from identification.forward import population as compiled_core
t = np.linspace(0.0, 0.02, 21)
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    forces = compiled_core.simulate_population_held([{"k": 2.0, "c": 0.0, "preload": 0.0}], t, t, np.ones_like(t),
                                                    model=get_model("kelvin_voigt"))
print(repr(float(forces[0, -1])), len(caught), str(caught[0].message) if caught else "")
"""


@pytest.mark.slow
def test_an_unwritable_cache_folder_compiles_in_memory_and_says_so_once(tmp_path):
    # the folder under a file: the model's module and its population module are both compiled in
    # memory, the population module importing the model's from there; one warning for the two
    import os
    import subprocess
    import sys
    from conftest import REPO
    blocked = tmp_path / "a_file"
    blocked.write_text("")
    environment = dict(os.environ, BUSHING_CACHE_DIR=str(blocked / "cache"), PYTHONPATH=str(REPO))
    result = subprocess.run([sys.executable, "-c", UNWRITABLE_PROBE], env=environment, capture_output=True,
                            text=True, timeout=600, cwd=REPO)
    assert result.returncode == 0, result.stderr[-3000:]
    force, count, message = result.stdout.split(maxsplit=2)
    assert float(force) == pytest.approx(2.0 * 0.02, rel=1e-12) and int(count) == 1   # F = k*x at 0.02 mm
    assert str(blocked / "cache") in message and "BUSHING_CACHE_DIR" in message


SPENCER_PROBE = """
import numpy as np
from fmu_src.model.registry import get_model
from identification.forward import population as compiled_core
t = np.linspace(0.0, 0.02, 21)
values = {"c0": 1.0, "k0": 1.0, "c1": 1.0, "k1": 100.0, "x0": 0.0, "alpha": 1.0, "A": 1.0, "beta": 0.5,
          "gamma": 0.5, "n": 2.0}
forces = compiled_core.simulate_population_held([values], t, t, np.ones_like(t), model=get_model("spencer"))
stats = compiled_core.compiled_model(get_model("spencer"))._simulate_population.stats
print(repr(float(forces[0, -1])), len(stats.cache_hits), len(stats.cache_misses))
"""


@pytest.mark.slow   # in CI's slow phase: it keeps the README's test command near 5 minutes
def test_a_changed_model_source_compiles_afresh_instead_of_loading_stale_machine_code(tmp_path):
    # numba checks only the time stamp of a kernel's own file, and the generated files are
    # rewritten: the cache must follow the model's source. A copy of the packages whose
    # Spencer force law is edited (k1 counted twice) must give other forces at once, with the
    # cache of the unedited run on disk; and the unedited source must load its machine code.
    import os
    import shutil
    import subprocess
    import sys
    from conftest import REPO
    for package in ("fmu_src", "identification"):
        shutil.copytree(REPO / package, tmp_path / "code" / package, ignore=shutil.ignore_patterns("__pycache__"))
    environment = dict(os.environ, BUSHING_CACHE_DIR=str(tmp_path / "cache"), PYTHONPATH=str(tmp_path / "code"))

    def probe():
        done = subprocess.run([sys.executable, "-c", SPENCER_PROBE], env=environment, capture_output=True,
                              text=True, timeout=600, cwd=tmp_path)
        assert done.returncode == 0, done.stderr[-3000:]
        force, hits, misses = done.stdout.split()
        return float(force), int(hits), int(misses)

    original, _, misses = probe()
    assert misses == 1
    assert probe() == (original, 1, 0)                   # unchanged: the machine code is loaded
    model = tmp_path / "code" / "fmu_src" / "models" / "spencer_model.py"
    text = model.read_text()
    law = "return c1 * ((alpha * z + c0 * v + k0 * (x - y)) / C) + k1 * (x - x0)"
    assert text.count(law) == 1
    model.write_text(text.replace(law, law + " + k1 * (x - x0)"))
    edited, hits, misses = probe()
    assert (hits, misses) == (0, 1)                      # compiled afresh ...
    assert edited - original == pytest.approx(100.0 * 0.02, rel=1e-9)   # ... with the edited force law (x = 0.02 mm)


SPENCER_FORCES = """
import numpy as np
from fmu_src.model.registry import get_model
from identification.forward import population as compiled_core
t = np.linspace(0.0, 0.05, 51)
values = {"c0": 1.0, "k0": 1.0, "c1": 1.0, "k1": 100.0, "x0": 0.0, "alpha": 1.0, "A": 1.0, "beta": 0.5,
          "gamma": 0.5, "n": 2.0}
forces = compiled_core.simulate_population_held([values], t, np.sin(60.0 * t), 60.0 * np.cos(60.0 * t),
                                                model=get_model("spencer"))
print(" ".join(repr(float(f)) for f in forces[0]))
"""


def _spencer_process(cache_dir):
    import os
    import subprocess
    import sys
    from conftest import REPO
    environment = dict(os.environ, BUSHING_CACHE_DIR=str(cache_dir), PYTHONPATH=str(REPO))
    return subprocess.Popen([sys.executable, "-c", SPENCER_FORCES], env=environment, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=REPO)


def _spencer_forces_here():
    namespace = {}
    exec(SPENCER_FORCES.replace("print(", "result = ("), namespace)
    return namespace["result"]


@pytest.mark.slow   # two processes compiling at once: CI's slow phase
def test_two_processes_compiling_the_same_model_at_once_both_give_its_forces(tmp_path):
    # issue 50, nothing lost: both start on an empty cache and compile the same generated module
    # at the same moment; each gives the forces bit for bit, and a third process then loads them
    first, second = _spencer_process(tmp_path), _spencer_process(tmp_path)
    outputs = [process.communicate(timeout=600) for process in (first, second)]
    assert [process.returncode for process in (first, second)] == [0, 0], [err[-2000:] for _, err in outputs]
    expected = _spencer_forces_here()
    for printed, _ in outputs:
        assert printed.split() == expected.split()
    third = _spencer_process(tmp_path)
    printed, error = third.communicate(timeout=600)
    assert third.returncode == 0 and printed.split() == expected.split(), error[-2000:]
    assert not list(tmp_path.glob("*.tmp")), "a half-written generated module was left behind"


@pytest.mark.slow
def test_a_compile_stopped_by_a_signal_leaves_a_cache_the_next_process_uses(tmp_path):
    # issue 50, nothing lost: SIGKILL (no handler can run) while the model compiles, at several
    # moments; whatever the stop left in the cache, the next process gives the forces bit for bit
    import signal
    import time
    expected = _spencer_forces_here()
    for delay in (0.5, 1.5, 3.0):
        cache = tmp_path / f"stopped_after_{delay}s"
        stopped = _spencer_process(cache)
        time.sleep(delay)
        stopped.send_signal(signal.SIGKILL)
        stopped.communicate(timeout=60)
        after = _spencer_process(cache)
        printed, error = after.communicate(timeout=600)
        assert after.returncode == 0 and printed.split() == expected.split(), (delay, error[-2000:])
