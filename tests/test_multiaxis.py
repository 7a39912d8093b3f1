"""Multi-axis tests (identification.multiaxis): the file format and its refusals, a model's
prediction of a plane path coupled and uncoupled, and `compare --coupling none,radial` choosing the
coupling from held-out multi-axis files, on data the test makes from a truth of its own (the
coupled equations typed in tests/references/generate_coupled_references.py)."""
import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

from fmu_src.bushing_models import get_model
from identification.__main__ import main
from identification.errors import IdentificationError
from identification.measurements import write_measurement
from identification.multiaxis import load_multiaxis, simulate_multiaxis, vector_nrmse, write_multiaxis
from test_coupled_models import run_coupled

REPO = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("coupled_references",
                                               REPO / "tests" / "references" / "generate_coupled_references.py")
references = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(references)

STEP_S = 1e-3
TRUTH = {"c0": 0.6, "k0": 300.0, "alpha": 1.0, "A": 900.0, "beta": 0.045, "gamma": 0.016, "n": 1.5}
"""The test's own single Bouc-Wen bushing (N-mm-s), as bench_coupled_prediction.py's."""


def truth(t, xy, coupled=True):
    """The truth's force vectors at every sample [N]: coupled in the plane, or each axis on its own."""
    if coupled:
        return references.solve_path(references.SingleBoucWen(TRUTH), t, xy, STEP_S)[:, 3:5]
    along = [references.solve_path(references.SingleBoucWen(TRUTH), t, np.column_stack([xy[:, c], 0 * t]),
                                   STEP_S)[:, 3] for c in range(2)]
    return np.column_stack(along)


def test_a_file_round_trips_and_a_model_predicts_it_coupled_as_its_kernels_do(tmp_path):
    t = np.arange(0.0, 0.3 + STEP_S / 2, STEP_S)
    xy = np.stack([2.0 * np.sin(2 * math.pi * 9.7 * t), 1.4 * (1.0 - np.cos(2 * math.pi * 9.7 * t))], axis=1)
    path = write_multiaxis(tmp_path / "plane.csv", t, xy, 3.0 * xy, ["SYNTHETIC: a test's file"])
    m = load_multiaxis(path)
    assert m.axes == ("x", "y") and m.velocity_mm_s is None
    np.testing.assert_allclose(m.displacement_mm, xy, atol=1e-6)
    model = get_model("single_bouc_wen")
    coupled = simulate_multiaxis(TRUTH, t, xy, model)
    assert np.max(np.abs(coupled[1:] - run_coupled(model, TRUTH, xy)[:, :2])) <= 1e-11 * np.max(np.abs(coupled))
    uncoupled = simulate_multiaxis(TRUTH, t, xy, model, coupled=False)
    assert vector_nrmse(uncoupled, coupled) > 0.01                       # the plane path tells them apart
    line = np.column_stack([xy[:, 0], 0 * t])
    assert np.max(np.abs(simulate_multiaxis(TRUTH, t, line, model) - simulate_multiaxis(TRUTH, t, line, model,
                                                                                      coupled=False))) \
        <= 1e-12 * np.max(np.abs(coupled))


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
    and of the uncoupled one (each axis on its own): SYNTHETIC files made here."""
    folder = tmp_path_factory.mktemp("multiaxis_rig")
    rng = np.random.default_rng(5)
    t = np.arange(0.0, 1.0 + STEP_S / 2, STEP_S)
    sines = []
    for amplitude, frequency in ((2.0, 10.0), (0.7, 4.0)):
        x = amplitude * np.sin(2 * math.pi * frequency * t)
        force = truth(t, np.column_stack([x, 0 * t]))[:, 0] + 3.0 * rng.standard_normal(t.size)
        path = folder / f"synthetic_sine_{amplitude}mm_{frequency}Hz.csv"
        write_measurement(path, t, x, force, ["SYNTHETIC: tests/test_multiaxis.py"])
        sines.append(path)
    w = 2 * math.pi * 4.7
    xy = np.stack([2.0 * np.sin(w * t), 1.2 * (1.0 - np.cos(w * t))], axis=1)
    held = {}
    for coupled in (True, False):
        force = truth(t, xy, coupled) + 3.0 * rng.standard_normal(xy.shape)
        held[coupled] = write_multiaxis(folder / f"synthetic_ellipse_{'coupled' if coupled else 'uncoupled'}.csv",
                                        t, xy, force, ["SYNTHETIC: tests/test_multiaxis.py"])
    return folder, sines, held


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


def test_compare_refuses_couplings_without_the_files_they_need(rig, capsys):
    folder, sines, held = rig
    common = ["compare", "--models", "single_bouc_wen", "--sine", str(sines[0]), "--out", str(folder / "refused")]
    assert main(common + ["--coupling", "none,radial"]) == 2
    assert "needs held-out multi-axis files" in capsys.readouterr().err
    assert main(common + ["--coupling", "none,spherical", "--validate-multiaxis", str(held[True])]) == 2
    assert "--coupling spherical needs multi-axis files of three axes" in capsys.readouterr().err
    assert main(common + ["--coupling", "diagonal", "--validate-multiaxis", str(held[True])]) == 2
    assert "'diagonal' is not a coupling compare weighs" in capsys.readouterr().err
