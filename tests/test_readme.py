"""The README tells the truth about the interface and the commands CI runs."""
import re

from fmpy import read_model_description

from conftest import REPO


def test_interface_table_matches_the_model_description(fmu_path):
    rows = re.findall(r"^\| `(\w+)` \| (\w+) \| ([^|]+) \| ([^|]+) \|", (REPO / "README.md").read_text(), re.M)
    table = {name: (causality, unit.strip(), default.strip()) for name, causality, unit, default in rows}
    variables = {v.name: v for v in read_model_description(fmu_path).modelVariables}
    assert set(table) == set(variables)
    for name, variable in variables.items():
        causality, unit, default = table[name]
        assert (causality, unit) == (variable.causality, variable.unit), name
        if variable.start is not None:
            assert float(default) == float(variable.start), name
        else:
            assert default == "—", name


def test_interface_table_states_each_parameters_allowed_range():
    from fmu_src.models.proposed_model import MODEL
    rows = re.findall(r"^\| `(\w+)` \| parameter \| [^|]+ \| [^|]+ \| ([^|]+) \|", (REPO / "README.md").read_text(), re.M)
    allowed = {name: value.strip() for name, value in rows}
    assert allowed == {spec.name: spec.allowed.replace("any finite value", "any") for spec in MODEL.specs} | \
        {spec.name: "finite" for spec in MODEL.mounting_specs}


def test_ci_runs_the_readme_test_command():
    readme = (REPO / "README.md").read_text()
    ci = (REPO / ".ci" / "run").read_text()
    commands = [line.strip() for line in readme.splitlines() if line.startswith("    python3 -m venv")]
    assert len(commands) == 2
    assert commands[1] in ci
