"""modelDescription.xml: validity, units, start values, structure."""
import zipfile

from fmpy import read_model_description
from fmpy.validation import validate_fmu

from conftest import paper_parameters
from paper_units import PARAMETER_UNITS, fmu_parameter_units

PROPOSED_UNITS = PARAMETER_UNITS["proposed"]


def test_fmpy_validation_finds_no_problem(fmu_path):
    assert validate_fmu(str(fmu_path)) == []


def test_ports_are_si_and_parameters_in_paper_units(fmu_path):
    description = read_model_description(fmu_path)
    variables = {v.name: v for v in description.modelVariables}
    assert (variables["x"].causality, variables["x"].unit) == ("input", "m")
    assert (variables["v"].causality, variables["v"].unit) == ("input", "m/s")
    assert (variables["F"].causality, variables["F"].unit) == ("output", "N")
    for name in ("z1", "z2"):
        assert variables[name].unit == "N"
    for name in ("y", "w"):
        assert variables[name].unit == "m"
    parameters = {v.name for v in description.modelVariables if v.causality == "parameter"}
    assert parameters == set(fmu_parameter_units("proposed"))
    for name, unit in fmu_parameter_units("proposed").items():
        assert variables[name].variability == "tunable"
        assert variables[name].unit == unit, name
    defined = {unit.name: unit for unit in description.unitDefinitions}
    assert defined["N/mm"].baseUnit.kg == 1 and defined["N/mm"].baseUnit.s == -2
    assert defined["N/mm"].baseUnit.factor == 1000.0


def test_parameter_start_values_are_table5_exactly(fmu_path):
    variables = {v.name: v for v in read_model_description(fmu_path).modelVariables}
    table5 = paper_parameters("table5")
    for name in PROPOSED_UNITS:
        assert float(variables[name].start) == table5[name]


def test_force_depends_directly_on_x_and_v_and_is_an_initial_unknown(fmu_path):
    description = read_model_description(fmu_path)
    (output,) = description.outputs
    assert output.variable.name == "F"
    assert sorted(v.name for v in output.dependencies) == ["v", "x"]
    assert [u.variable.name for u in description.initialUnknowns] == ["F"]


def test_state_handling_declared_and_default_experiment_present(fmu_path):
    description = read_model_description(fmu_path)
    assert description.coSimulation.canGetAndSetFMUstate
    assert description.coSimulation.canSerializeFMUstate
    assert description.coSimulation.modelIdentifier == "BoucWenBushing"
    assert description.defaultExperiment.stepSize == "0.001"
    assert description.version and description.description


def test_packed_modules_have_build_specific_names(fmu_path, fmu_path_table2):
    def slave_module(path):
        with zipfile.ZipFile(path) as archive:
            return archive.read("resources/slavemodule.txt").decode().strip()
    first, second = slave_module(fmu_path), slave_module(fmu_path_table2)
    assert first.startswith("boucwen_bushing_") and second.startswith("boucwen_bushing_")
    assert first != second


def test_a_build_from_the_pythonfmu_copy_an_fmu_carries_is_refused_with_why(fmu_path, tmp_path):
    # A pythonfmu FMU carries pythonfmu without the builder's binaries; a process that loaded one
    # first would build FMUs without binaries: build_fmu says so instead.
    import subprocess
    import sys
    import zipfile
    from conftest import REPO
    with zipfile.ZipFile(fmu_path) as archive:
        archive.extractall(tmp_path / "unzipped")
    code = (f"import sys\nsys.path.insert(0, {str(tmp_path / 'unzipped' / 'resources')!r})\n"
            "import pythonfmu.builder\nimport build_fmu\n"
            "try:\n    build_fmu.build_fmu(out_dir=sys.argv[1])\n"
            "except build_fmu.BuildError as exc:\n    print(exc)\n")
    done = subprocess.run([sys.executable, "-c", code, str(tmp_path / "out")], cwd=REPO, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "has no FMU binaries" in done.stdout and not (tmp_path / "out").exists()
