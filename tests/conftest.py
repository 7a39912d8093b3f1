import functools
import json
import os
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import build_fmu
# The installed pythonfmu, before any test loads a pythonfmu FMU into this process: such an FMU puts
# its own copy of pythonfmu (resources/pythonfmu, without the builder's binaries) on sys.path, and
# an xdist worker whose first FMU arrives built by another worker would otherwise build from it.
import pythonfmu.builder  # noqa: E402,F401
from fmu_src.parameter_files import load_parameters
from suite_options import (_optimizer_rounding_variant, pytest_addoption, pytest_collection_modifyitems,  # noqa: F401
                           pytest_configure)

REPO = Path(__file__).resolve().parents[1]
DATA = REPO / "data"


def paper_parameters(table: str) -> dict[str, float]:
    """The paper's parameter sets as shipped in data/: 'table2', 'table4' or 'table5'."""
    files = {"table2": "params_table2_sine.json", "table4": "params_table4_step.json",
             "table5": "params_table5_combined.json"}
    return load_parameters(DATA / files[table])


def paper_equations(t, state, p, displacement, velocity):
    """Eqs. 1-4 of the paper, typed from the paper once more, independently of ``fmu_src``:
    d/dt of (y, z1, w, z2) for the input functions ``displacement(t)`` [mm] and
    ``velocity(t)`` [mm/s], parameters ``p`` in N-mm-s units."""
    y, z1, w, z2 = state
    x, xd = displacement(t), velocity(t)
    yd = (p["c1"] * xd + p["k1"] * (x - y) - p["k0"] * y + p["alpha1"] * z1) / p["c1"]      # eq. 3
    wd = (p["c2"] * xd + p["k2"] * (x - w) + p["alpha2"] * z2) / (p["c0"] + p["c2"])       # eq. 4
    z1d = (xd - yd) * (p["A1"] - (p["gamma1"] + p["beta1"] * np.sign(xd - yd) * np.sign(z1))
                       * abs(z1) ** p["n1"])                                                 # eq. 1
    z2d = (xd - wd) * (p["A2"] - (p["gamma2"] + p["beta2"] * np.sign(xd - wd) * np.sign(z2))
                       * abs(z2) ** p["n2"])                                                 # eq. 2
    return [yd, z1d, wd, z2d]


def paper_force(p, time_s, displacement, velocity, rtol=1e-8, atol=1e-8):
    """Eq. 5, F = k0*y + c0*dw/dt [N], at ``time_s`` for a smooth input given as functions of
    time, from scipy's Radau on :func:`paper_equations`, starting in relaxed equilibrium at
    x(0) (y = k1*x/(k0 + k1), w = x, z = 0). The default tolerances leave 5e-9 of the peak force
    against rtol = atol = 1e-10 (Table 2, 2 mm at 30 Hz, 2026-11-25) in a third of the time;
    a test that resolves finer differences passes tighter ones."""
    x0 = displacement(time_s[0])
    start = [p["k1"] * x0 / (p["k0"] + p["k1"]), 0.0, x0, 0.0]
    solution = solve_ivp(paper_equations, (time_s[0], time_s[-1]), start, method="Radau", t_eval=time_s,
                         args=(p, displacement, velocity), rtol=rtol, atol=atol)
    assert solution.success, solution.message
    y, _, w, z2 = solution.y
    x, xd = displacement(time_s), velocity(time_s)
    wd = (p["c2"] * xd + p["k2"] * (x - w) + p["alpha2"] * z2) / (p["c0"] + p["c2"])
    return p["k0"] * y + p["c0"] * wd


@functools.lru_cache(maxsize=64)
def _paper_test_force(parameters: tuple, kind: str, duration_s: float, amplitude_mm: float, frequency_hz: float,
                      rise_time_s: float) -> np.ndarray:
    p = dict(parameters)
    time_s = np.arange(round(duration_s * 1000.0) + 1) / 1000.0   # both ends, as signals.sample_times
    if kind == "sine":
        omega = 2.0 * np.pi * frequency_hz
        return paper_force(p, time_s, lambda t: amplitude_mm * np.sin(omega * t),
                           lambda t: amplitude_mm * omega * np.cos(omega * t))
    rate = amplitude_mm / rise_time_s
    return paper_force(p, time_s, lambda t: np.minimum(rate * np.asarray(t), amplitude_mm),
                       lambda t: np.where(np.asarray(t) < rise_time_s, rate, 0.0))


def paper_test_force(p, kind, duration_s, amplitude_mm=2.0, frequency_hz=10.0, rise_time_s=0.1):
    """The force [N] of the proposed model with parameters ``p`` on the paper's sine
    (``amplitude_mm`` at ``frequency_hz``) or step (ramp to ``amplitude_mm`` over
    ``rise_time_s``, then held), sampled at 1 kHz from t = 0 to ``duration_s``: scipy's Radau on the paper's
    equations (:func:`paper_force`), independent of the project's kernels. Synthetic training
    data made this way cannot share an error with the fitted model."""
    return _paper_test_force(tuple(sorted(p.items())), kind, float(duration_s), amplitude_mm, frequency_hz,
                             rise_time_s).copy()


JUMP_RAMP_S = 1e-9
"""A displacement jump, for the references below: the limit of a ramp this short."""


def paper_ramp(p, state, x_start, dx, duration_s, rtol=1e-10, atol=1e-12):
    """The state (y, z1, w, z2) after the displacement moves from ``x_start`` by ``dx`` [mm] at
    constant speed over ``duration_s``: scipy's Radau on :func:`paper_equations`."""
    speed = dx / duration_s
    solution = solve_ivp(paper_equations, (0.0, duration_s), np.asarray(state, dtype=float), method="Radau",
                         args=(p, lambda t: x_start + speed * t, lambda t: speed), rtol=rtol, atol=atol)
    assert solution.success, solution.message
    return solution.y[:, -1]


def paper_eq5(p, state, x, v):
    """Eq. 5 with eq. 4, F = k0*y + c0*dw/dt [N], typed from the paper once more."""
    y, _, w, z2 = state
    return p["k0"] * y + p["c0"] * (p["c2"] * v + p["k2"] * (x - w) + p["alpha2"] * z2) / (p["c0"] + p["c2"])


def reference_jump(p, state, x_start, jump_mm):
    """Independent reference for a displacement jump: the paper's equations over a ramp of
    JUMP_RAMP_S (its limit differs by about JUMP_RAMP_S times the relaxation rates, < 1e-5)."""
    return paper_ramp(p, state, x_start, jump_mm, JUMP_RAMP_S)


def reference_force(params, time_s, x_mm, v_mm_s, rtol=1e-10, atol=1e-9):
    """Independent reference with the FMU's input convention: scipy's Radau on the paper's
    eqs. 1-4 (:func:`paper_equations`) over each sample with the input x_k + v_k*(t - t_k), a
    displacement jump (:func:`reference_jump`) where x_k differs from the previous step's end,
    and eq. 5 at each sample with the velocity of the step that ends there."""
    p = params
    state = [p["k1"] * x_mm[0] / (p["k0"] + p["k1"]), 0.0, x_mm[0], 0.0]   # relaxed equilibrium
    state_x = x_mm[0]
    forces = [paper_eq5(p, state, x_mm[0], v_mm_s[0])]
    for k in range(len(time_s) - 1):
        h = time_s[k + 1] - time_s[k]
        if x_mm[k] != state_x:
            state = reference_jump(p, state, state_x, x_mm[k] - state_x)
        state = paper_ramp(p, state, x_mm[k], v_mm_s[k] * h, h, rtol=rtol, atol=atol)
        state_x = x_mm[k] + v_mm_s[k] * h
        forces.append(paper_eq5(p, state, state_x, v_mm_s[k]))
    return np.array(forces)


def built_once(tmp_path_factory, name: str, build):
    """``build(folder)`` (a path, or {name: path}) run once per test run: with pytest-xdist, by the
    first worker that asks, in a folder every worker of the run shares; the others wait for it and
    take its FMUs (a build is the same whichever process makes it). Without fcntl (Windows), per
    worker."""
    try:
        import fcntl
    except ImportError:
        return build(tmp_path_factory.mktemp(name))
    root = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        root = root.parent                      # the run's folder, above each worker's own
    folder, record = root / f"built_{name}", root / f"built_{name}.json"
    with open(root / f"built_{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if record.is_file():
            paths = json.loads(record.read_text())
            return Path(paths) if isinstance(paths, str) else {key: Path(path) for key, path in paths.items()}
        folder.mkdir(exist_ok=True)
        built = build(folder)
        record.write_text(json.dumps(str(built) if isinstance(built, Path) else
                                     {key: str(path) for key, path in built.items()}))
        return built


@pytest.fixture(scope="session")
def fmu_path(tmp_path_factory) -> Path:
    """The FMU built with the default parameters (Table 5)."""
    return built_once(tmp_path_factory, "fmu_table5", lambda folder: build_fmu.build_fmu(out_dir=folder))


@pytest.fixture(scope="session")
def fmu_path_table2(tmp_path_factory) -> Path:
    """An FMU built with the paper's Table 2 as default parameters."""
    return built_once(tmp_path_factory, "fmu_table2",
                      lambda folder: build_fmu.build_fmu(DATA / "params_table2_sine.json", folder))


@pytest.fixture(scope="session")
def native_fmu_path(tmp_path_factory) -> Path:
    """The native FMU (compiled C, FMI 2.0) built with the default parameters (Table 5)."""
    return built_once(tmp_path_factory, "native_table5", lambda folder: build_fmu.build_native_fmu(out_dir=folder).path)


def host_platforms(fmi_version: int) -> tuple[str, ...] | None:
    """The platform of this machine's library among a native FMU's (FMI ``fmi_version``): what the
    every-model fixtures build, half the compilations of the quick platforms (the Windows library's
    own tests build theirs: ``native_fmu_path``). None (the quick platforms) on a machine that is
    not one of the FMU's platforms."""
    from fmu_src.fmi.native.platforms import PLATFORMS, host_target
    target = host_target()
    names = tuple(p.name for p in PLATFORMS[fmi_version] if p.targets == (target,))
    return names or None


@pytest.fixture(scope="session")
def native_model_fmus(tmp_path_factory) -> dict:
    """Each model's native FMU (FMI 2.0), and the six-axis one, with their default parameters, for
    this machine's platform only (``host_platforms``)."""
    from fmu_src.model.registry import MODELS
    return built_once(tmp_path_factory, "native", lambda folder: {
        name: build_fmu.build_native_fmu(out_dir=folder, model=name, platforms=host_platforms(2)).path
        for name in (*MODELS, "six_axis")})


@pytest.fixture(scope="session")
def native_model_fmi3_fmus(tmp_path_factory) -> dict:
    """Each model's native FMU as FMI 3.0, and the six-axis one, with their default parameters, for
    this machine's platform only (``host_platforms``)."""
    from fmu_src.model.registry import MODELS
    return built_once(tmp_path_factory, "native_fmi3", lambda folder: {
        name: build_fmu.build_native_fmu(out_dir=folder, model=name, fmi_version=3, platforms=host_platforms(3)).path
        for name in (*MODELS, "six_axis")})


@pytest.fixture(scope="session")
def pythonfmu_model_fmus(tmp_path_factory) -> dict:
    """Each model's pythonfmu FMU, and the six-axis one, with their default parameters."""
    from fmu_src.model.registry import MODELS
    return built_once(tmp_path_factory, "pythonfmu", lambda folder: {
        name: build_fmu.build_fmu(out_dir=folder, model=name) for name in (*MODELS, "six_axis")})


@pytest.fixture(scope="session")
def coupled_six_axis_fmus(tmp_path_factory) -> dict:
    """The illustrative six axes with a spherical group (the proposed model on x, y, z) and a conical
    one (Berg on rx, ry) (``example_parameter_files.six_axis_file``): its parameter file ("file"), its
    pythonfmu FMU and its native FMUs ("fmi2", "fmi3", this machine's platform only)."""
    from example_parameter_files import six_axis_file

    def build(folder):
        path = six_axis_file(folder, {"translation": "spherical", "rotation": "conical"})
        return {"file": path, "pythonfmu": build_fmu.build_fmu(path, folder / "pythonfmu", model="six_axis"),
                "fmi2": build_fmu.build_native_fmu(path, folder / "fmi2", model="six_axis",
                                                   platforms=host_platforms(2)).path,
                "fmi3": build_fmu.build_native_fmu(path, folder / "fmi3", model="six_axis", fmi_version=3,
                                                   platforms=host_platforms(3)).path}
    return built_once(tmp_path_factory, "coupled_six_axis", build)


def is_native(fmu_path) -> bool:
    """Whether ``fmu_path`` is a native FMU (build_fmu.py --native), not a pythonfmu one."""
    from fmpy import read_model_description
    return "--native" in read_model_description(str(fmu_path)).generationTool


_PRINT_LOG_MESSAGE = None


@pytest.fixture(autouse=True)
def _fmpy_logger_proxy_alive():
    """fmpy (0.3.32) formats FMI 2 log messages in a native proxy that keeps the Python logger to
    call in one global: simulate_fmu(logger=...) points it at that call's logger, which is freed
    when the call returns, and the next FMU that logs through fmpy's default callbacks calls
    freed memory (seen here: SIGFPE in fmpy/logging's logMessage, after a test that passed a
    logger; the native FMU logs every error and warning, as the Reference-FMUs do). After every
    test the proxy points again at fmpy's own printer, kept alive here."""
    yield
    global _PRINT_LOG_MESSAGE
    from ctypes import byref
    from fmpy.fmi2 import fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, printLogMessage
    from fmpy.logging import addLoggerProxy
    if _PRINT_LOG_MESSAGE is None:
        _PRINT_LOG_MESSAGE = fmi2CallbackLoggerTYPE(printLogMessage)
    callbacks = fmi2CallbackFunctions()
    callbacks.logger = _PRINT_LOG_MESSAGE
    addLoggerProxy(byref(callbacks))
