"""Multi-axis tests (identification.measured.multiaxis): the file format and its refusals, a model's
prediction of a plane path coupled and uncoupled, and `compare --coupling none,radial` choosing the
coupling from held-out multi-axis files, on data the test makes from a truth of its own (the
coupled equations typed in tests/references/generate_coupled_references.py)."""
import importlib.util
import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from fmu_src.model.registry import get_model
from identification.__main__ import main
from identification.errors import IdentificationError
from fmu_src.parameter_files import save_parameters
from identification.measured.measurements import write_measurement
from identification.forward.simulate import simulate_multiaxis
from identification.measured.multiaxis import load_multiaxis, vector_nrmse, write_multiaxis

REPO = Path(__file__).resolve().parents[3]
_spec = importlib.util.spec_from_file_location("coupled_references",
                                               REPO / "tests" / "references" / "generate_coupled_references.py")
references = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(references)

STEP_S = 1e-3
TRUTH = {"c0": 0.6, "k0": 300.0, "alpha": 1.0, "A": 900.0, "beta": 0.045, "gamma": 0.016, "n": 1.5}
"""The test's own single Bouc-Wen bushing (N-mm-s), as bench_coupled_prediction.py's."""


def continuous_truth(parameters, path, t, coupled=True):
    """The displacements [mm] and force vectors [N] at the times ``t`` of a single Bouc-Wen bushing
    (the reference's equations) driven along the analytic ``path`` in continuous time: scipy's Radau
    on the whole path at once (rtol 1e-8; 1e-10 changes the forces by 8e-10 of the peak), the
    velocity the path's own. What a rig's smooth motion makes, and what the fit's forward model
    approximates. ``coupled``: in the plane, else each axis on its own."""
    bushing = references.SingleBoucWen(parameters)
    h = 1e-6

    def position(s, axes):
        return path(np.array([s]))[0] * axes

    def velocity(s, axes):
        return (path(np.array([s + h]))[0] - path(np.array([s - h]))[0]) / (2 * h) * axes

    def run(axes):
        solution = solve_ivp(lambda s, y: bushing.rates(y, position(s, axes), velocity(s, axes)), (t[0], t[-1]),
                             bushing.initial(), method="Radau", t_eval=t, rtol=1e-8, atol=1e-10)
        return np.array([bushing.force(y, position(s, axes), velocity(s, axes))[:2]
                         for s, y in zip(t, solution.y.T)])
    forces = run(np.ones(2)) if coupled else np.column_stack([run(np.eye(2)[c])[:, c] for c in range(2)])
    return path(t), forces


def scaled_random_path(t_range):
    """The references' random path with its scale fixed over ``t_range`` (so that it is one function
    of time, evaluated a point at a time)."""
    scale = 3.0 / np.max(np.hypot(*references.random_walk(t_range).T))
    return lambda s: scale * references.random_walk(s)


def test_a_file_round_trips_and_a_model_predicts_it_as_the_reference_does(tmp_path):
    t = np.arange(0.0, 0.3 + STEP_S / 2, STEP_S)
    path = references.ellipse(2.0, 1.4, 9.7)
    xy = path(t)
    written = write_multiaxis(tmp_path / "plane.csv", t, xy, 3.0 * xy, ["SYNTHETIC: a test's file"])
    m = load_multiaxis(written)
    assert m.axes == ("x", "y") and m.velocity_mm_s is None
    np.testing.assert_allclose(m.displacement_mm, xy, atol=1e-6)
    model = get_model("single_bouc_wen")
    coupled = simulate_multiaxis(TRUTH, t, xy, model)
    # the scipy reference in continuous time
    _, fine = continuous_truth(TRUTH, path, t)
    peak = np.max(np.abs(fine))
    assert np.max(np.abs(coupled - fine)) <= 1e-3 * peak
    # the FMU's held input at the same samples is further from it: the forward model earns its keep
    held = references.solve_path(references.SingleBoucWen(TRUTH), t, xy, STEP_S)[:, 3:5]
    assert np.max(np.abs(held - fine)[1:]) > 3 * np.max(np.abs(coupled - fine)[1:])
    uncoupled = simulate_multiaxis(TRUTH, t, xy, model, coupling="none")
    assert vector_nrmse(uncoupled, coupled) > 0.01                       # the plane path tells them apart
    line = np.column_stack([xy[:, 0], 0 * t])
    assert np.max(np.abs(simulate_multiaxis(TRUTH, t, line, model) - simulate_multiaxis(TRUTH, t, line, model,
                                                                                      coupling="none"))) \
        <= 1e-12 * np.max(np.abs(coupled))


def test_radial_on_a_three_axis_path_couples_x_and_y_and_leaves_z_alone():
    t = np.arange(0.0, 0.2 + STEP_S / 2, STEP_S)
    xy = references.ellipse(2.0, 1.4, 9.7)(t)
    z = 0.8 * np.sin(2 * math.pi * 6.1 * t)
    xyz = np.column_stack([xy, z])
    model = get_model("single_bouc_wen")
    radial = simulate_multiaxis(TRUTH, t, xyz, model, coupling="radial")
    assert np.array_equal(radial[:, :2], simulate_multiaxis(TRUTH, t, xy, model, coupling="radial"))
    assert np.array_equal(radial[:, 2], simulate_multiaxis(TRUTH, t, xyz, model, coupling="none")[:, 2])
    spherical = simulate_multiaxis(TRUTH, t, xyz, model, coupling="spherical")
    assert vector_nrmse(spherical, radial) > 1e-3                         # z takes part in the hysteresis
    with pytest.raises(IdentificationError, match="the spherical coupling needs 3 axes"):
        simulate_multiaxis(TRUTH, t, xy, model, coupling="spherical")
    with pytest.raises(IdentificationError, match="unknown coupling 'conical'"):
        simulate_multiaxis(TRUTH, t, xy, model, coupling="conical")


@pytest.mark.parametrize("text, message", [
    ("time_s,dx_mm,Fx_N,Fy_N\n0,0,0,0\n", "line 1: missing column dy_mm"),
    ("time_s,dx_mm,dy_mm,Fx_N,Fy_N,vx_mm_s\n0,0,0,0,0,0\n", "velocity columns vx_mm_s without vy_mm_s"),
    ("time_s,dx_mm,dy_mm,Fx_N,Fy_N,Mx\n0,0,0,0,0,0\n", "unknown columns Mx"),
    ("# comment\ntime_s,dx_mm,dy_mm,Fx_N,Fy_N\n0,0,0,0,0\n0.001,0,0,0\n", "line 4: 4 values, the header has 5"),
    ("time_s,dx_mm,dy_mm,Fx_N,Fy_N\n0,0,0,0,0\n0.001,0,x,0,0\n", "line 3: '0.001,0,x,0,0' holds a value that is not"),
    ("time_s,dx_mm,dy_mm,Fx_N,Fy_N\n0,0,0,0,0\n0.001,0,0,0,0\n0.001,0,0,0,0\n", "line 4: time 0.001 s does not increase"),
    ("time_s,dx_mm,dy_mm,Fx_N,Fy_N\n0,0,0,0,nan\n0.001,0,0,0,0\n", "line 2: a value is not finite"),
])
def test_a_multiaxis_file_that_cannot_be_used_is_refused_naming_the_line_or_column(tmp_path, text, message):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(IdentificationError, match=message.replace("(", r"\(").replace(")", r"\)")):
        load_multiaxis(path)


@pytest.fixture(scope="module")
def rig(tmp_path_factory):
    """Two sines along x alone (3 N noise) and an ellipse in the plane held out, of the coupled truth
    and of the uncoupled one (each axis on its own), from the scipy reference in continuous time:
    SYNTHETIC files made here."""
    folder = tmp_path_factory.mktemp("multiaxis_rig")
    rng = np.random.default_rng(5)
    t = np.arange(0.0, 1.0 + STEP_S / 2, STEP_S)
    sines = []
    for amplitude, frequency in ((2.0, 10.0), (0.7, 4.0)):
        line, force = continuous_truth(TRUTH, lambda s: np.column_stack([amplitude * np.sin(2 * math.pi * frequency * s),
                                                                  0 * s]), t)
        path = folder / f"synthetic_sine_{amplitude}mm_{frequency}Hz.csv"
        write_measurement(path, t, line[:, 0], force[:, 0] + 3.0 * rng.standard_normal(t.size),
                          ["SYNTHETIC: tests/identification/measured/test_multiaxis.py"])
        sines.append(path)
    held = {}
    for coupled in (True, False):
        xy, force = continuous_truth(TRUTH, references.ellipse(2.0, 1.2, 4.7), t, coupled)
        held[coupled] = write_multiaxis(folder / f"synthetic_ellipse_{'coupled' if coupled else 'uncoupled'}.csv",
                                        t, xy, force + 3.0 * rng.standard_normal(xy.shape),
                                        ["SYNTHETIC: tests/identification/measured/test_multiaxis.py"])
    return folder, sines, held


@pytest.mark.slow
@pytest.mark.parametrize("coupled, expected", [(True, "radial"), (False, "none")])
def test_compare_picks_radial_on_coupled_data_and_none_on_uncoupled_data(rig, capsys, coupled, expected):
    folder, sines, held = rig
    out = folder / f"compare_{expected}"
    code = main(["compare", "--models", "single_bouc_wen", *[a for s in sines for a in ("--sine", str(s))],
                 "--coupling", "none,radial", "--validate-multiaxis", str(held[coupled]), "--screening", "512",
                 "--starts", "8", "--no-ensemble", "--quiet", "--workers", "1", "--out", str(out)])
    printed = capsys.readouterr().out
    assert code == 0
    lines = printed.strip().splitlines()
    assert lines[-1] == "recommended: single_bouc_wen"
    assert any(line.startswith(f"recommended coupling: {expected} ") for line in lines), printed[-1500:]
    assert (out / "coupling.csv").is_file()


@pytest.mark.slow
def test_compare_refuses_couplings_without_the_files_they_need(rig, capsys):
    folder, sines, held = rig
    common = ["compare", "--models", "single_bouc_wen", "--sine", str(sines[0]), "--out", str(folder / "refused")]
    assert main(common + ["--coupling", "none,radial"]) == 2
    assert "needs held-out multi-axis files" in capsys.readouterr().err
    assert main(common + ["--coupling", "none,spherical", "--validate-multiaxis", str(held[True])]) == 2
    assert "--coupling spherical needs multi-axis files of three axes" in capsys.readouterr().err
    assert main(common + ["--coupling", "diagonal", "--validate-multiaxis", str(held[True])]) == 2
    assert "'diagonal' is not a coupling compare weighs" in capsys.readouterr().err


FIT_TRUTH = {"c0": 0.6, "k0": 300.0, "alpha": 1.0, "A": 900.0, "beta": 0.3, "gamma": 0.11, "n": 1.2}
"""A single Bouc-Wen bushing inside the search box (n < 1.5), saturating near 600 N as TRUTH does."""
NOISE_N = 3.0


@pytest.fixture(scope="module")
def fit_rig(tmp_path_factory):
    """SYNTHETIC files of FIT_TRUTH, coupled, 3 N noise, from the scipy reference in continuous time:
    a sine along x alone and an ellipse in the plane to train on, and two plane paths the fits never
    see (a circle and the references' random path)."""
    folder = tmp_path_factory.mktemp("multiaxis_fit")
    rng = np.random.default_rng(11)
    t = np.arange(0.0, 1.0 + STEP_S / 2, STEP_S)
    x = lambda s: np.column_stack([2.0 * np.sin(2 * math.pi * 10.0 * s), 0 * s])   # noqa: E731
    sine = folder / "synthetic_sine_2mm_10Hz.csv"
    line, force = continuous_truth(FIT_TRUTH, x, t)
    write_measurement(sine, t, line[:, 0], force[:, 0] + NOISE_N * rng.standard_normal(t.size),
                      ["SYNTHETIC: tests/identification/measured/test_multiaxis.py"])
    files = {}
    for name, path, duration in (("ellipse", references.ellipse(2.0, 1.2, 4.7), 1.0),
                                 ("circle", references.circle(1.0, 9.7), 0.5),
                                 ("random", scaled_random_path(t), 1.0)):
        s = t[t <= duration + STEP_S / 2]
        xy, force = continuous_truth(FIT_TRUTH, path, s)
        files[name] = write_multiaxis(folder / f"synthetic_{name}.csv", s, xy,
                                      force + NOISE_N * rng.standard_normal((s.size, 2)),
                                      ["SYNTHETIC: tests/identification/measured/test_multiaxis.py"])
    return folder, sine, files


def _fit_arguments(out, *extra):
    return ["fit", "--model", "single_bouc_wen", *extra, "--screening", "256", "--starts", "6", "--no-ensemble",
            "--quiet", "--workers", "1", "--out", str(out)]


@pytest.mark.slow
def test_a_fit_to_a_sine_and_an_ellipse_coupled_reaches_the_floor_and_predicts_unseen_plane_paths(fit_rig, capsys):
    folder, sine, files = fit_rig
    out = folder / "radial.json"
    code = main(_fit_arguments(out, "--sine", str(sine), "--multiaxis", str(files["ellipse"]), "--coupling", "radial"))
    printed = capsys.readouterr()
    assert code == 0, printed.err[-2000:]
    assert "converged: yes" in printed.out, printed.out
    assert "ellipse" in printed.out and "2-axis" in printed.out
    saved = json.loads(out.read_text())
    assert saved["fit"]["multiaxis_coupling"] == "radial"
    fits = {Path(t["file"]).name: t for t in saved["fit"]["tests"]}
    assert fits["synthetic_ellipse.csv"]["kind"] == "2-axis" and fits["synthetic_ellipse.csv"]["at_floor"]
    assert str(files["ellipse"]) in saved["fit"]["data"]
    parameters = saved["parameters"]
    for name in ("random", "circle"):
        m = load_multiaxis(files[name])
        exact = m.force_N                                               # measured: truth + 3 N noise
        coupled = vector_nrmse(simulate_multiaxis(parameters, m.time_s, m.displacement_mm, "single_bouc_wen"), exact)
        uncoupled = vector_nrmse(simulate_multiaxis(parameters, m.time_s, m.displacement_mm, "single_bouc_wen",
                                                    coupling="none"), exact)
        assert coupled <= 0.03, (name, coupled)                          # the 3 % on unseen paths
        assert uncoupled > 3 * coupled, (name, coupled, uncoupled)


@pytest.mark.slow
def test_the_same_data_fitted_uncoupled_misses_its_noise_by_far(fit_rig, capsys):
    folder, sine, files = fit_rig
    out = folder / "none.json"
    code = main(_fit_arguments(out, "--multiaxis", str(files["ellipse"]), "--coupling", "none"))
    printed = capsys.readouterr()
    assert code == 0
    assert "WARNING: not converged" in printed.err
    ratio = json.loads(out.read_text())["fit"]["tests"][0]["nrmse_over_noise"]
    assert ratio > 5.0, ratio


@pytest.mark.parametrize("arguments, message", [
    (["--multiaxis", "{ellipse}"], "--multiaxis needs --coupling"),
    (["--sine", "{sine}", "--coupling", "radial"], "--coupling radial says how the model runs on multi-axis tests"),
    (["--multiaxis", "{ellipse}", "--coupling", "spherical"], "the spherical coupling needs 3 axes"),
    (["--multiaxis", "{missing}", "--coupling", "radial"], "does not exist"),
])
@pytest.mark.slow
def test_fit_refuses_multiaxis_options_it_cannot_use_before_any_work(fit_rig, capsys, arguments, message):
    folder, sine, files = fit_rig
    names = {"ellipse": files["ellipse"], "sine": sine, "missing": folder / "missing.csv"}
    out = folder / "refused.json"
    code = main(_fit_arguments(out, *[a.format(**names) for a in arguments]))
    assert code == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.slow
def test_compare_says_where_multiaxis_training_goes(fit_rig, capsys):
    folder, sine, files = fit_rig
    code = main(["compare", "--models", "single_bouc_wen", "--sine", str(sine), "--multiaxis", str(files["ellipse"]),
                 "--out", str(folder / "compare")])
    assert code == 2
    assert "fit --multiaxis FILE --coupling radial" in capsys.readouterr().err


@pytest.mark.slow
def test_the_multiaxis_rows_of_the_jacobian_are_its_forward_differences(fit_rig):
    """The exact Jacobian's one-axis rows come from the sensitivities, the multi-axis rows (no
    sensitivities) from differences: those rows equal difference_jacobian's bit for bit."""
    from identification.measured.measurements import load_measurement
    from identification.fitting.multistart import Problem, difference_jacobian
    from identification.fitting.objectives import MultiAxisTests, Objective
    from identification.measured.rig_tests import RigTest
    from identification.fitting.search_space import SearchSpace
    folder, sine, files = fit_rig
    ellipse = load_multiaxis(files["ellipse"])
    tests = [RigTest(load_measurement(sine), "sine")]
    space = SearchSpace.from_measurements([tests[0].measurement] + ellipse.components(), "single_bouc_wen")
    objective = Objective(tests, model=get_model("single_bouc_wen"),
                          multiaxis=MultiAxisTests([ellipse], coupling="radial"))
    assert objective.difference_size == ellipse.force_N.size
    theta = space.to_coordinates(FIT_TRUTH)
    residual, jacobian = Problem(objective, space, "exact").residuals_and_jacobian(theta)
    differences, at = difference_jacobian(Problem(objective, space, "difference"), theta)
    rows = slice(residual.size - objective.difference_size, residual.size)
    assert np.array_equal(residual, at)
    assert np.array_equal(jacobian[rows], differences[rows])
    # the sine's rows: the sensitivities agree with the differences to the differences' accuracy
    sine_rows = slice(0, residual.size - objective.difference_size)
    scale = np.max(np.abs(jacobian[sine_rows]), axis=0)
    assert np.max(np.abs(jacobian[sine_rows] - differences[sine_rows]) / scale) < 1e-3


@pytest.mark.slow
def test_predict_runs_a_multiaxis_path_with_its_coupling_and_writes_a_multiaxis_file(fit_rig, capsys):
    folder, sine, files = fit_rig
    params = folder / "truth.json"
    save_parameters(params, FIT_TRUTH, "single_bouc_wen")
    m = load_multiaxis(files["circle"])
    path_only = folder / "circle_path.csv"
    path_only.write_text("time_s,dx_mm,dy_mm\n" + "".join(f"{a:.6f},{b:.6f},{c:.6f}\n" for a, (b, c)
                                                          in zip(m.time_s, m.displacement_mm)))
    out = folder / "predicted_circle.csv"
    assert main(["predict", "--params", str(params), "--data", str(path_only), "--coupling", "radial",
                 "--out", str(out), "--plot", str(folder / "predicted_circle.png")]) == 0
    predicted = load_multiaxis(out)
    expected = simulate_multiaxis(FIT_TRUTH, m.time_s, m.displacement_mm, "single_bouc_wen")
    assert np.max(np.abs(predicted.force_N - expected)) <= 1e-4                 # the file's 4 decimals
    assert vector_nrmse(predicted.force_N, m.force_N) < 0.01                     # the truth within its noise
    assert (folder / "predicted_circle.png").is_file()
    assert main(["predict", "--params", str(params), "--data", str(files["circle"]), "--coupling", "none",
                 "--out", str(folder / "none.csv")]) == 0
    assert "NRMSE of the force vector against synthetic_circle.csv" in capsys.readouterr().out
    assert main(["predict", "--params", str(params), "--data", str(path_only), "--out", str(out)]) == 2
    assert "is a multi-axis path: give --coupling" in capsys.readouterr().err
    assert main(["predict", "--params", str(params), "--data", str(sine), "--coupling", "radial",
                 "--out", str(out)]) == 2
    assert "is a one-axis test" in capsys.readouterr().err
