"""Chrono's vehicle JSON bushings read as six Kelvin-Voigt axes (identification/property_files/
chrono_json.py), on Chrono's own HMMWV front-suspension file (tests/fixtures/chrono, BSD-3, with
its licence): the constants in the project's units (typed here from the file's SI values), the
six-axis FMU's forces k x + c v on a translation and a rotation, the free axis, refusals."""
from __future__ import annotations

import json
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest

from identification.errors import IdentificationError
from identification.property_files.chrono_json import PropertyFileWarning, read_chrono_bushing

HMMWV = Path(__file__).resolve().parents[2] / "fixtures" / "chrono" / "HMMWV_DoubleWishboneFront_bushings.json"


def quiet_read(*arguments):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PropertyFileWarning)
        return read_chrono_bushing(*arguments)


@pytest.mark.parametrize("name", ["Upper Control Arm", "Lower Control Arm"])
def test_the_hmmwv_bushings_in_the_projects_units(name):
    # the file: 7e7 N/m, 0.35e5 N.s/m, 1e5 N.m/rad, 0.5e3 N.m.s/rad
    imported = quiet_read(HMMWV, name)
    for axis in ("x", "y", "z"):
        assert imported.axes[axis] == ("kelvin_voigt", {"k": 7e4, "c": 35.0, "preload": 0.0})
    for axis in ("rx", "ry", "rz"):
        assert imported.axes[axis] == ("kelvin_voigt", {"k": 1e8, "c": 5e5, "preload": 0.0})
    assert imported.provenance["bushing"] == name and imported.provenance["format"] == "chrono-json"


def test_the_joints_free_rotations_take_the_dof_values_and_without_a_joint_they_are_left_out_with_a_warning():
    with pytest.warns(PropertyFileWarning, match="belong to the free rotations of the joint it replaces, which the "
                                                 "file does not name: left out"):
        read_chrono_bushing(HMMWV, "Lower Control Arm")
    with warnings.catch_warnings():
        warnings.simplefilter("error", PropertyFileWarning)
        revolute = read_chrono_bushing(HMMWV, "Lower Control Arm", "revolute")
        spherical = read_chrono_bushing(HMMWV, "Lower Control Arm", "spherical")
    # Chrono's ChVehicleJoint: the DOF values on the joint's free rotations, never on a translation
    assert revolute.axes["rz"][1] == {"k": 0.0, "c": 0.0, "preload": 0.0} and revolute.axes["rx"][1]["k"] == 1e8
    assert all(spherical.axes[a][1]["k"] == 0.0 for a in ("rx", "ry", "rz"))
    assert all(spherical.axes[a][1]["k"] == 7e4 for a in ("x", "y", "z"))
    assert revolute.provenance["free_axes"] == ["rz"]
    with pytest.raises(IdentificationError, match="joint 'prismatic': one of revolute, universal, spherical"):
        read_chrono_bushing(HMMWV, "Lower Control Arm", "prismatic")


def test_import_to_a_six_axis_fmu_gives_k_x_plus_c_v(tmp_path):
    import build_fmu
    from fmpy import simulate_fmu
    from fmu_src.parameter_files import save_six_axis
    if shutil.which("gcc") is None and shutil.which("cc") is None:
        pytest.skip("no C compiler for the native FMU")
    imported = quiet_read(HMMWV, "Upper Control Arm")
    file = save_six_axis(tmp_path / "uca.json", imported.axes, imported.provenance)
    fmu = build_fmu.build_native_fmu(file, tmp_path, model="six_axis").path
    t = np.arange(0.0, 0.2, 1e-3)
    names = ["dx", "vx", "dy", "vy", "dz", "vz", "rx", "wx", "ry", "wy", "rz", "wz"]
    signals = np.zeros(t.size, dtype=[("time", float)] + [(name, float) for name in names])
    w = 2 * np.pi * 5.0
    signals["time"] = t
    # each step's mean velocity: the FMU's path then meets every sample, and its force at t_k reads
    # the displacement there and the velocity held over the step that ends there
    signals["dz"], signals["rz"] = 1e-3 * np.sin(w * t), 0.01 * np.sin(w * t)
    signals["vz"], signals["wz"] = (np.append(np.diff(signals[name]) / 1e-3, 0.0) for name in ("dz", "rz"))
    result = simulate_fmu(str(fmu), stop_time=t[-1], step_size=1e-3, output_interval=1e-3, input=signals,
                          output=["Fz", "Mz", "Fx"])
    n = len(result)
    held = {name: np.append(signals[name][0], signals[name][:-1]) for name in ("vz", "wz")}
    # SI: 7e7 N/m and 3.5e4 N.s/m; 1e5 N.m/rad and 500 N.m.s/rad
    fz = 7e7 * signals["dz"][:n] + 3.5e4 * held["vz"][:n]
    mz = 1e5 * signals["rz"][:n] + 500.0 * held["wz"][:n]
    np.testing.assert_allclose(result["Fz"], fz, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(result["Mz"], mz, rtol=1e-12, atol=1e-9)
    assert np.all(result["Fx"] == 0.0)


def test_refusals_name_the_file_the_key_and_what_is_allowed(tmp_path):
    with pytest.raises(IdentificationError, match="holds 2 bushings: name one with --bushing \\(one of 'Upper Control "
                                                  "Arm', 'Lower Control Arm'\\)"):
        read_chrono_bushing(HMMWV)
    with pytest.raises(IdentificationError, match="no bushing 'Tierod'; the file's are"):
        read_chrono_bushing(HMMWV, "Tierod")
    document = json.loads(HMMWV.read_text())
    data = document["Lower Control Arm"]["Bushing Data"]
    cases = [({"Stiffness Linear": -1.0}, r"Stiffness Linear = -1.0 \[N/m\] must be >= 0"),
             ({"Damping Rotational": "soft"}, r"Damping Rotational = 'soft' is not a finite number \[N.m.s/rad\]")]
    for change, message in cases:
        broken = json.loads(json.dumps(document))
        broken["Lower Control Arm"]["Bushing Data"].update(change)
        path = tmp_path / "broken.json"
        path.write_text(json.dumps(broken))
        with pytest.raises(IdentificationError, match=message):
            quiet_read(path, "Lower Control Arm")
    missing = json.loads(json.dumps(document))
    del missing["Upper Control Arm"]["Bushing Data"]["Damping Linear"]
    (tmp_path / "missing.json").write_text(json.dumps(missing))
    with pytest.raises(IdentificationError, match=r"'Upper Control Arm': missing 'Damping Linear' \[N.s/m\]"):
        quiet_read(tmp_path / "missing.json", "Upper Control Arm")
    extra = json.loads(json.dumps(document))
    extra["Upper Control Arm"]["Bushing Data"]["Preload"] = 10.0
    (tmp_path / "extra.json").write_text(json.dumps(extra))
    with pytest.warns(PropertyFileWarning, match="'Preload' not read"):
        read_chrono_bushing(tmp_path / "extra.json", "Upper Control Arm", "revolute")
    (tmp_path / "bad.json").write_text('{"Bushing Data": {\n  "Stiffness Linear": 7e7,,\n}}')
    with pytest.raises(IdentificationError, match="bad.json, line 2, column 27: not JSON"):
        read_chrono_bushing(tmp_path / "bad.json")
    del data


def test_comments_a_byte_order_mark_and_two_bushings_of_one_name(tmp_path):
    text = HMMWV.read_text()
    commented = "\ufeff// Chrono allows comments\n" + text.replace('"Stiffness Linear": 7e7,',
                                                                    '"Stiffness Linear": 7e7, /* N/m */', 1)
    (tmp_path / "commented.json").write_text(commented, encoding="utf-8")
    assert quiet_read(tmp_path / "commented.json", "Upper Control Arm").axes["x"][1]["k"] == 7e4
    twice = json.loads(text)
    twice["Spindle"]["Upper Control Arm"] = {"Bushing Data": twice["Upper Control Arm"]["Bushing Data"]}
    (tmp_path / "twice.json").write_text(json.dumps(twice))
    with pytest.raises(IdentificationError, match="two bushings are named 'Upper Control Arm'"):
        read_chrono_bushing(tmp_path / "twice.json", "Upper Control Arm")
    (tmp_path / "latin.json").write_bytes(b'{"Bushing Data": {"Stiffness Linear": 7e7} "\xe9"}')
    with pytest.raises(IdentificationError, match="not UTF-8 text"):
        read_chrono_bushing(tmp_path / "latin.json")


def test_the_command_line_imports_and_refuses_what_it_does_not_read(tmp_path, capsys):
    from identification.cli.arguments import main
    assert main(["import", str(HMMWV), "--bushing", "Lower Control Arm", "--joint", "revolute",
                 "--out", str(tmp_path / "lca.json")]) == 0
    written = json.loads((tmp_path / "lca.json").read_text())
    assert written["model"] == "SixAxisBushing" and written["axes"]["rz"]["parameters"]["k"] == 0.0
    assert written["fit"]["imported_from"].endswith("HMMWV_DoubleWishboneFront_bushings.json")
    other = tmp_path / "mount.gdf"
    other.write_text("[MDI_HEADER]\n")
    assert main(["import", str(other), "--out", str(tmp_path / "x.json")]) == 2
    assert "Adams' nonlinear bushing files (.bus)" in capsys.readouterr().err
