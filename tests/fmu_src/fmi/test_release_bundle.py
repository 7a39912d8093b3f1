"""The release bundle (``build_fmu.py --release``): the native FMU of every model, FMI 2 and 3, the
binaries of every platform (Linux x86_64 and aarch64, Windows, macOS) and sources in each, its default parameter set as start values; the default sets
as ``.ssv``, README.txt and SHA256SUMS. A user without a compiler applies a fitted set to the bundle's
FMU as start values: the same forces as an FMU built with that set as its defaults (one binary serves
every parameter set).

The quick tests build a bundle of two models (a Bouc-Wen one and a filled-rubber one); the whole
bundle, fourteen FMUs (about a minute on two cores), is built by the slow test."""
import hashlib
import re
import shutil
import subprocess
import zipfile

import numpy as np
import pytest
from fmpy import read_model_description, supported_platforms
from fmpy.validation import validate_fmu

import build_fmu
from conftest import DATA
from fmu_src import __version__
from fmu_src.fmi import release
from fmu_src.fmi.fmu_inputs import identifier_of
from fmu_src.fmi.native import build as native_build
from fmu_src.fmi.native import platforms
from fmu_src.model.registry import MODEL_NAMES
from fmu_src.parameter_files import load_parameters, read_parameter_set, read_six_axis, save_parameters
from identification.measured.signals import Random, sample_times
from fmu_harness import simulate_with_fmpy
from test_six_axis_fmu import axis_signals, run_with_fmpy

MISSING = {version: native_build.missing_platforms(version) for version in (2, 3)}
"""The platforms whose compilers are not installed here, by FMI version: the bundle goes without them."""
HAS_MINGW = shutil.which(platforms.MINGW) is not None
NO_MINGW = f"mingw-w64 ({platforms.MINGW}) is not installed: the bundle has no win64 binaries"
QUICK_MODELS = ("proposed", "berg")      # a Bouc-Wen model and a filled-rubber one
LINUX = {2: "linux64", 3: "x86_64-linux"}
WINDOWS = {2: "win64", 3: "x86_64-windows"}
MM = 1e-3


@pytest.fixture(scope="module")
def bundle(tmp_path_factory):
    """A bundle of QUICK_MODELS, FMI 2 and 3 (every platform whose compiler is installed)."""
    return release.build_release(tmp_path_factory.mktemp("release"), allow_missing_platforms=any(MISSING.values()),
                                   models=QUICK_MODELS)


def expected_platforms(version: int) -> set[str]:
    return set(native_build.platform_names(version)) - set(MISSING[version])


def binary_platforms(fmu) -> set[str]:
    """The platforms of the binaries in ``fmu`` (binaries/<platform>/, by the FMI version's names;
    fmpy's supported_platforms gives FMI 2's names for FMI 3 too)."""
    with zipfile.ZipFile(fmu) as archive:
        return {name.split("/")[1] for name in archive.namelist() if name.startswith("binaries/")}


def ssv_values(path, model: str) -> dict[str, float]:
    """The FMU's parameter names and values in a bundle's ``.ssv``."""
    return read_six_axis(path).flat() if model == "six_axis" else load_parameters(path, model)


def check_bundle(bundle, models, versions=(2, 3)):
    """What every bundle must be: its files, their checksums, every FMU valid with its platforms and
    its default set's start values, the README naming every file and the version."""
    folder = bundle.folder
    fmus = {release.release_fmu_name(model, version): (model, version) for model in models for version in versions}
    sets = {release.release_parameter_name(model): model for model in models}
    names = {*fmus, *sets, release.README}
    assert {path.name for path in folder.iterdir()} == names | {release.CHECKSUMS}
    assert set(bundle.files) == {folder / name for name in names | {release.CHECKSUMS}}

    # SHA256SUMS: `sha256sum -c` format ("<64 hex>  <name>"), every file but itself, right digests
    lines = (folder / release.CHECKSUMS).read_text().splitlines()
    listed = {}
    for line in lines:
        match = re.fullmatch(r"([0-9a-f]{64})  (\S+)", line)
        assert match, line
        listed[match[2]] = match[1]
    assert set(listed) == names
    for name, digest in listed.items():
        assert hashlib.sha256((folder / name).read_bytes()).hexdigest() == digest, name
    if shutil.which("sha256sum"):
        done = subprocess.run(["sha256sum", "--strict", "-c", release.CHECKSUMS], cwd=folder, capture_output=True,
                              text=True)
        assert done.returncode == 0, done.stdout + done.stderr

    for name, (model, version) in fmus.items():
        path = folder / name
        assert validate_fmu(str(path)) == [], name
        description = read_model_description(str(path))
        assert description.fmiVersion == f"{version}.0"
        identifier = identifier_of(model)
        assert description.coSimulation.modelIdentifier == description.modelExchange.modelIdentifier == identifier
        assert name.startswith(identifier + "-")
        assert binary_platforms(path) == expected_platforms(version), name
        assert "c-code" in supported_platforms(str(path))
        with zipfile.ZipFile(path) as archive:
            assert f"sources/{identifier}.c" in archive.namelist()
        # its start values are the bundle's .ssv of its model, bit for bit
        starts = {v.name: float(v.start) for v in description.modelVariables if v.causality == "parameter"}
        assert starts == ssv_values(folder / release.release_parameter_name(model), model), name

    readme = (folder / release.README).read_text()
    assert __version__ in readme.splitlines()[0]
    for name in [*names, release.CHECKSUMS]:
        assert name in readme
    assert "start values" in readme and "simulate_fmu" in readme and "start_values=" in readme
    assert ("MISSING PLATFORMS" in readme) == any(MISSING.values())


@pytest.mark.slow
def test_the_bundle_holds_valid_fmus_their_default_sets_a_readme_and_checksums(bundle):
    check_bundle(bundle, QUICK_MODELS)
    assert bundle.missing == {version: why for version, why in MISSING.items() if why}


@pytest.mark.slow
@pytest.mark.skipif(not HAS_MINGW, reason=NO_MINGW)
def test_the_win64_binaries_are_x86_64_windows_dlls_exporting_the_fmi_functions(bundle):
    for (model, version), path in bundle.fmus.items():
        identifier = identifier_of(model)
        with zipfile.ZipFile(path) as archive:
            dll = archive.read(f"binaries/{WINDOWS[version]}/{identifier}.dll")
        assert dll[:2] == b"MZ"
        pe = int.from_bytes(dll[0x3C:0x40], "little")
        assert dll[pe:pe + 4] == b"PE\0\0" and int.from_bytes(dll[pe + 4:pe + 6], "little") == 0x8664   # AMD64
        assert f"fmi{version}DoStep".encode() in dll and f"fmi{version}Instantiate".encode() in dll


def berg_set() -> dict[str, float]:
    """A Berg set other than the default: another filled rubber (stiffer, more friction, slower Maxwell elements)."""
    return {"k0": 620.0, "k3": 14.0, "Ff_max": 85.0, "x2": 0.12, "k1": 90.0, "c1": 22.0, "k2": 310.0, "c2": 0.9}


def fitted_set(model: str) -> dict[str, float]:
    if model == "proposed":    # fitted to the friction damper's 0.5 Hz sine (data/brfd)
        return read_parameter_set(DATA / "params_fit_brfd_sine_0.5Hz_1in.json", model).parameters
    return berg_set()


@pytest.mark.slow
@pytest.mark.parametrize("version", (2, 3))
@pytest.mark.parametrize("model", QUICK_MODELS)
def test_a_fitted_set_from_an_ssv_as_start_values_equals_an_fmu_built_with_it(bundle, tmp_path, model, version):
    # The bundle's FMU with the set as start values (read from an .ssv, as a user would) against an
    # FMU built with the set as its defaults: the same forces, so one binary serves every set.
    ssv = save_parameters(tmp_path / "fit.ssv", fitted_set(model), model)
    start_values = load_parameters(ssv, model)
    assert start_values != ssv_values(bundle.parameter_files[model], model)
    built = build_fmu.build_native_fmu(ssv, tmp_path / "built", model, version, platforms=(LINUX[version],)).path
    t = sample_times(0.4, 1000.0)
    x, v = Random(2.0, 1.0, seed=3).signals(t)
    released = bundle.fmus[model, version]
    applied = simulate_with_fmpy(released, t, x, v, start_values=start_values)
    reference = simulate_with_fmpy(built, t, x, v)
    assert np.max(np.abs(applied - reference)) <= 1e-12 * np.max(np.abs(reference))   # measured: equal, bit for bit
    # and the start values did act: the defaults give other forces
    defaults = simulate_with_fmpy(released, t, x, v)
    assert np.max(np.abs(defaults - reference)) > 1e-3 * np.max(np.abs(reference))


def test_a_release_without_mingw_is_refused_unless_allowed(monkeypatch, tmp_path, capsys):
    monkeypatch.setattr(platforms, "MINGW", "x86_64-w64-mingw32-gcc-not-here")
    out = tmp_path / "refused"
    assert build_fmu.main(["--release", "--out", str(out)]) == 2
    error = capsys.readouterr().err
    assert error.startswith("error: a release bundle carries every platform")
    assert "win64 (FMI 2): x86_64-w64-mingw32-gcc-not-here is not installed (Debian: apt-get install " \
           "gcc-mingw-w64-x86-64)" in error
    assert "x86_64-windows (FMI 3)" in error and "--allow-missing-platforms" in error
    assert not out.exists()     # refused before building anything

    # allowed: the bundle says what it lacks, on stderr and in its README (one model, to be quick)
    monkeypatch.setattr(release, "release_models", lambda: ("kelvin_voigt",))
    out = tmp_path / "allowed"
    assert build_fmu.main(["--release", "--allow-missing-platforms", "--out", str(out)]) == 0
    captured = capsys.readouterr()
    assert "warning: the bundle has no win64 (FMI 2)" in captured.err and "x86_64-windows (FMI 3)" in captured.err
    assert captured.out.startswith(f"wrote {out}: 2 FMUs, 1 parameter sets")
    readme = (out / release.README).read_text()
    assert "MISSING PLATFORMS" in readme and "win64 (FMI 2): x86_64-w64-mingw32-gcc-not-here is not installed" in readme
    for version in (2, 3):
        fmu = out / release.release_fmu_name("kelvin_voigt", version)
        assert binary_platforms(fmu) == expected_platforms(version) - {WINDOWS[version]}
        assert validate_fmu(str(fmu)) == []


def test_a_native_build_without_a_compiler_points_to_the_release_bundle(monkeypatch, tmp_path, capsys):
    monkeypatch.setenv("CC", "cc-not-here")
    monkeypatch.setattr(platforms, "MINGW", "x86_64-w64-mingw32-gcc-not-here")
    monkeypatch.setattr(platforms, "CROSS_GCC", {"x86_64": "x86_64-gcc-not-here", "aarch64": "aarch64-gcc-not-here"})
    monkeypatch.setattr(platforms, "ZIG", ("zig-not-here", "cc"))
    assert build_fmu.main(["--native", "--out", str(tmp_path)]) == 2
    error = capsys.readouterr().err
    assert error.startswith("error: no platform could be built: linux64: cc-not-here is not installed (Debian: "
                            "apt-get install gcc); win64: x86_64-w64-mingw32-gcc-not-here is not installed")
    assert error.rstrip().endswith(native_build.NO_COMPILER)
    assert "python build_fmu.py --release" in error and "start values" in error
    # a release bundle cannot be made here either, allowed or not
    assert build_fmu.main(["--release", "--allow-missing-platforms", "--out", str(tmp_path / "r")]) == 2
    assert "no platform could be built" in capsys.readouterr().err


@pytest.mark.parametrize("flags", (["--model", "berg"], ["--params", str(DATA / "params_table2_sine.json")],
                                   ["--fmi-version", "3"], ["--native"]))
def test_release_takes_no_model_parameters_or_version(flags, capsys):
    with pytest.raises(SystemExit) as exit_:
        build_fmu.main(["--release", *flags])
    assert exit_.value.code == 2 and "--release builds every model" in capsys.readouterr().err


@pytest.mark.slow
def test_the_full_release_bundle(tmp_path, capsys):
    # The command a release runs: every model, FMI 2 and 3; every FMU runs with its .ssv as start values.
    flags = ["--allow-missing-platforms"] if any(MISSING.values()) else []
    assert build_fmu.main(["--release", "--out", str(tmp_path), *flags]) == 0
    models = release.release_models()
    assert set(models) == {*MODEL_NAMES, "six_axis"} and len(models) == len(MODEL_NAMES) + 1
    bundle = release.ReleaseBundle(tmp_path)
    bundle.fmus = {(m, v): tmp_path / release.release_fmu_name(m, v) for m in models for v in (2, 3)}
    bundle.parameter_files = {m: tmp_path / release.release_parameter_name(m) for m in models}
    bundle.readme, bundle.checksums = tmp_path / release.README, tmp_path / release.CHECKSUMS
    check_bundle(bundle, models)
    t = sample_times(0.05, 1000.0)
    x, v = Random(2.0, 1.0, seed=3).signals(t)
    for (model, version), fmu in bundle.fmus.items():
        start_values = ssv_values(bundle.parameter_files[model], model)
        if model == "six_axis":
            signals = axis_signals(t)
            applied, defaults = run_with_fmpy(fmu, t, signals, start_values), run_with_fmpy(fmu, t, signals)
            assert all(np.array_equal(applied[k], defaults[k]) for k in defaults), fmu.name
        else:
            applied, defaults = simulate_with_fmpy(fmu, t, x, v, start_values), simulate_with_fmpy(fmu, t, x, v)
            assert np.all(np.isfinite(applied)) and np.array_equal(applied, defaults), fmu.name
    with capsys.disabled():
        print(f"\n  release bundle: {len(bundle.fmus)} FMUs, "
              f"{sum(p.stat().st_size for p in tmp_path.iterdir()) / 1e6:.1f} MB")
