"""Altair's bushing property files (identification/property_files/gbs.py) on a file hand-written
after the documented layout (tests/fixtures/gbs: its blocks, the (ACTIVITY) table, the spline
rows), imported into a six-axis FMU: the static force at every spline point the file's within
1e-9 N, between them scipy's monotone cubic, the damping c v, the units converted; refusals."""
from __future__ import annotations

import math
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

from identification.errors import IdentificationError
from identification.property_files.chrono_json import PropertyFileWarning
from identification.property_files.gbs import read_gbs

MOUNT = Path(__file__).resolve().parents[2] / "fixtures" / "gbs" / "mount_after_the_documented_layout.gbs"
FX = [(-4.0, -2600.0), (-3.0, -1500.0), (-2.0, -800.0), (-1.0, -350.0), (0.0, 0.0), (1.0, 300.0), (2.0, 650.0),
      (3.0, 1150.0), (4.0, 2000.0)]
"""The file's FX spline [mm, N], typed here."""


def quiet_read(path=MOUNT):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PropertyFileWarning)
        return read_gbs(path)


def test_each_direction_becomes_its_axis_in_the_projects_units():
    axes = quiet_read().axes
    assert axes["x"][0] == "kelvin_voigt+backbone9" and axes["x"][1]["c"] == 1.2
    assert [(axes["x"][1][f"backbone_x{i}"], axes["x"][1][f"backbone_F{i}"]) for i in range(1, 10)] == FX
    assert axes["y"] == ("kelvin_voigt", {"k": 800.0, "c": 1.5, "preload": 0.0})
    assert axes["z"][0] == "kelvin_voigt+backbone5" and axes["z"][1]["c"] == 2.0
    # 5000 N.mm/deg and 2000 N.mm/deg in N.mm/rad
    assert axes["rx"][1]["k"] == pytest.approx(5000.0 * 180.0 / math.pi, rel=1e-15)
    assert axes["rz"][1]["k"] == pytest.approx(2000.0 * 180.0 / math.pi, rel=1e-15)
    assert axes["ry"][1] == {"k": 0.0, "c": 0.0, "preload": 0.0}


def test_what_it_does_not_map_is_named_with_its_values():
    with pytest.warns(PropertyFileWarning, match=r"\[CUBIC_STIFFNESS_TY\] \{'K1': 4000.0, 'K3': 10.0\}; "
                                                 r"\[RUBBER_DAMPING_TZ\] \{'LOSS_ANGLE': 5.0\}"):
        read_gbs(MOUNT)


def test_the_six_axis_fmu_gives_the_splines_forces_and_the_damping(tmp_path):
    import build_fmu
    from fmpy import simulate_fmu
    from fmu_src.parameter_files import save_six_axis
    if shutil.which("gcc") is None and shutil.which("cc") is None:
        pytest.skip("no C compiler for the native FMU")
    imported = quiet_read()
    fmu = build_fmu.build_native_fmu(save_six_axis(tmp_path / "mount.json", imported.axes, imported.provenance),
                                     tmp_path, model="six_axis").path
    h = 1e-3
    knots = np.array([x for x, _ in FX])
    # through every knot and then a sine inside them, each step at its mean velocity
    x = np.concatenate([np.repeat(knots, 3), 3.5 * np.sin(2 * np.pi * 2.0 * np.arange(0.0, 0.5, h))])
    t = np.arange(x.size) * h
    v = np.append(np.diff(x) / h, 0.0)
    names = ["dx", "vx", "dy", "vy", "dz", "vz", "rx", "wx", "ry", "wy", "rz", "wz"]
    signals = np.zeros(t.size, dtype=[("time", float)] + [(name, float) for name in names])
    signals["time"], signals["dx"], signals["vx"] = t, x * 1e-3, v * 1e-3
    signals["dy"], signals["vy"] = signals["dx"], signals["vx"]
    result = simulate_fmu(str(fmu), stop_time=t[-1], step_size=h, output_interval=h, input=signals,
                          output=["Fx", "Fy"])
    n = len(result)
    held = np.append(v[0], v[:-1])[:n]               # the velocity the step that ends at t_k held
    static = result["Fx"] - 1.2 * held               # c = 1.2 N.s/mm
    at_knots = np.arange(1, 3 * knots.size, 3)       # the middle sample of each knot's three
    np.testing.assert_allclose(static[at_knots], [f for _, f in FX], rtol=0, atol=1e-9)
    inside = slice(3 * knots.size, n)
    spline = PchipInterpolator(knots, [f for _, f in FX])
    np.testing.assert_allclose(static[inside], spline(x[:n][inside]), rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(result["Fy"], 800.0 * x[:n] + 1.5 * held, rtol=1e-12, atol=1e-9)


@pytest.mark.parametrize("change, message", [
    (("LENGTH = 'mm'", "LENGTH = 'furlong'"), r"line 13: LENGTH = 'furlong' is not a unit this reader knows"),
    (("  1.0    300.0", "  -1.5    300.0"), r"the deflections must increase"),
    (("{ formulation FX FY FZ TX TY TZ }", "{ formulation FX FY FZ TX TY TZZ }"), r"\(ACTIVITY\) table has no column TZ"),
    (("[CONSTANT_STIFFNESS_FY]\nK = 800.0\n", ""), r"CONSTANT_STIFFNESS is active in FY .* no \[CONSTANT_STIFFNESS_FY\]"),
    (("[GLOBAL]", "[GLOBALS]"), r"block\(s\) \[GLOBALS\] \(line 19\) not in the .gbs layout"),
    (("'CONSTANT_STIFFNESS' 0 1 0 1 0 1", "'CONSTANT_STIFFNESS' 1 1 0 1 0 1"), "FX has a spline and a constant stiffness"),
])
def test_bad_files_are_refused_with_the_line_and_what_is_allowed(tmp_path, change, message):
    path = tmp_path / "bad.gbs"
    text = MOUNT.read_text()
    assert change[0] in text
    path.write_text(text.replace(change[0], change[1], 1))
    with pytest.raises(IdentificationError, match=message):
        quiet_read(path)


@pytest.mark.parametrize("change, message", [
    (("C = 1.2", "C = 1.2\nC = 1.3"), r"\[CONSTANT_DAMPING_FX\] gives C twice"),
    (("{ disp force }\n -4.0  -2600.0", "{ disp force k }\n -4.0  -2600.0 1"), r"3 values for the 2 columns|columns"),
    ((" -4.0  -2600.0", " -4.0  'soft'"), r"is not a row of two finite numbers"),
])
def test_misleading_tables_and_repeated_values_are_refused(tmp_path, change, message):
    path = tmp_path / "bad.gbs"
    path.write_text(MOUNT.read_text().replace(change[0], change[1], 1))
    with pytest.raises(IdentificationError, match=message):
        quiet_read(path)


def test_columns_by_name_trailing_comments_and_a_byte_order_mark(tmp_path):
    text = MOUNT.read_text()
    start = text.index("[SPLINE_STIFFNESS_FX]")
    end = text.index("[CONSTANT_DAMPING_FX]")
    swapped = "[SPLINE_STIFFNESS_FX]\n(SPLINE_DATA)\n{ force disp }\n" + "".join(f"{f} {x}\n" for x, f in FX)
    path = tmp_path / "swapped.gbs"
    path.write_text("\ufeff" + (text[:start] + swapped + text[end:]).replace("C = 1.2", "C = 1.2   $ N.s/mm", 1),
                    encoding="utf-8")
    axes = quiet_read(path).axes
    assert [(axes["x"][1][f"backbone_x{i}"], axes["x"][1][f"backbone_F{i}"]) for i in range(1, 10)] == FX
    assert axes["x"][1]["c"] == 1.2


def test_the_command_line_imports_a_gbs(tmp_path):
    import json
    from identification.cli.arguments import main
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PropertyFileWarning)
        assert main(["import", str(MOUNT), "--out", str(tmp_path / "mount.json")]) == 0
    written = json.loads((tmp_path / "mount.json").read_text())
    assert written["axes"]["x"]["model"] == "KelvinVoigtBushing_Backbone9" and written["fit"]["format"] == "gbs"
