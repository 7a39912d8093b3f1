"""The front door as a newcomer meets it: what the base install (no extras) can do, the
one-line error when an extra is missing, one reading of "the parameters", the renamed single
Bouc-Wen model and its old name, output directories refused before the work, warnings and
progress bars that do not glue lines."""
import json
import subprocess
import sys
import time

import numpy as np
import pytest

from conftest import DATA, REPO

SINE = DATA / "synthetic_table5_sine_2mm_10Hz.csv"

# Runs Python with numba (and with it the "fit" extra) made unimportable, as in a base install.
WITHOUT_NUMBA = "import sys; sys.modules['numba'] = None\n"


def run_without_numba(code: str, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", WITHOUT_NUMBA + code], cwd=REPO, capture_output=True, text=True,
                          timeout=timeout)


def test_simulate_runs_without_numba_and_equals_the_compiled_forward_model():
    """The base install's simulate (the models' kernels as plain Python, fmu_src.kernels.jit) gives the
    compiled forward model's forces: the same source, run two ways."""
    from identification import load_measurement, simulate
    m = load_measurement(SINE)
    keep = slice(0, 200)     # 0.2 s: two cycles, enough to leave the initial state
    compiled = simulate(DATA / "params_table5_combined.json", m.time_s[keep], m.displacement_mm[keep])
    code = ("import json, numpy as np\n"
            "from fmu_src.kernels import jit\n"
            "assert not jit.AVAILABLE\n"
            "from identification import load_measurement, simulate\n"
            f"m = load_measurement({str(SINE)!r})\n"
            f"f = simulate({str(DATA / 'params_table5_combined.json')!r}, m.time_s[:200], m.displacement_mm[:200])\n"
            "print(json.dumps(f.tolist()))\n")
    done = run_without_numba(code)
    assert done.returncode == 0, done.stderr
    plain = np.array(json.loads(done.stdout))
    peak = np.max(np.abs(compiled))
    assert peak > 1000.0
    assert np.max(np.abs(plain - compiled)) <= 1e-12 * peak


@pytest.mark.parametrize("arguments, extra", [
    (["fit", "--sine", str(SINE), "--out", "{tmp}/p.json"], "fit"),
    (["compare", "--sine", str(SINE), "--out", "{tmp}/cmp"], "fit"),
])
def test_a_command_whose_extra_is_missing_says_which_extra_in_one_line(tmp_path, arguments, extra):
    code = ("import sys\nfrom identification.cli.arguments import main\n"
            f"sys.exit(main({[a.replace('{tmp}', str(tmp_path)) for a in arguments]!r}))\n")
    done = run_without_numba(code, timeout=60)
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in done.stderr
    assert lines[0].startswith("error: the ") and f"needs the '{extra}' extra (numba is not installed)" in lines[0]
    assert f"pip install 'boucwen-bushing[{extra}]'" in lines[0]
    assert not list(tmp_path.iterdir())


def test_a_simulating_command_runs_without_numba_and_says_it_is_slower(tmp_path):
    code = ("import sys\nfrom identification.cli.arguments import main\n"
            f"sys.exit(main(['characterise', '--params', {str(DATA / 'params_table5_combined.json')!r}, "
            f"'--amplitudes-mm', '1', '--frequencies-hz', '10', '--out', {str(tmp_path / 'k.csv')!r}]))\n")
    done = run_without_numba(code)
    assert done.returncode == 0, done.stderr
    assert done.stderr.startswith("note: numba is not installed: the models run as plain Python")
    assert "pip install 'boucwen-bushing[fit]'" in done.stderr
    assert (tmp_path / "k.csv").is_file()


def test_fit_from_python_without_the_extra_raises_a_missing_extra_error():
    done = run_without_numba("from identification import MissingExtraError, fit\n"
                             "try:\n    fit([])\nexcept MissingExtraError as exc:\n    print(exc)\n", timeout=60)
    assert done.returncode == 0, done.stderr
    assert "identification.fit needs the 'fit' extra" in done.stdout


def test_the_same_parameters_in_any_form_give_the_same_forces(tmp_path):
    from fmu_src.parameter_files import read_parameter_set
    from identification import characterise, predict, simulate
    from identification.fitting.result import FitResult
    path = DATA / "params_table5_combined.json"
    parameter_set = read_parameter_set(path)
    mapping = dict(parameter_set.parameters)
    result = FitResult(parameter_set, 1.0, [], [], 0.0, [mapping], None, "default", 0, 1, 0.0)
    t = np.arange(0.0, 0.1, 1e-3)
    x = 2.0 * np.sin(2 * np.pi * 10.0 * t)
    reference = simulate(mapping, t, x)
    for form in (parameter_set, result, path, str(path), [mapping]):
        np.testing.assert_array_equal(simulate(form, t, x), reference)
        np.testing.assert_array_equal(predict(form, t, x).force_N, reference)
    sheet = characterise(result, [1.0], [10.0])
    np.testing.assert_array_equal(sheet.kdyn_N_per_mm, characterise(path, [1.0], [10.0]).kdyn_N_per_mm)
    with pytest.raises(TypeError, match="not int"):
        simulate(5, t, x)


def test_the_single_bouc_wen_model_keeps_its_old_name_as_an_alias(tmp_path):
    from fmu_src.model.registry import MODEL_NAMES, get_model
    from fmu_src.parameter_files import read_parameter_set
    single = get_model("single_bouc_wen")
    assert "single_bouc_wen" in MODEL_NAMES and "bouc_wen" not in MODEL_NAMES
    assert get_model("bouc_wen") is single and single.identifier == "SingleBoucWenBushing"
    document = json.loads((DATA / "params_single_bouc_wen_fit_synthetic_table5.json").read_text())
    document["model"] = "bouc_wen"
    old = tmp_path / "old.json"
    old.write_text(json.dumps(document))
    assert read_parameter_set(old).model is single
    from identification.cli.arguments import main
    # the old name on the command line: accepted, and the file must be for that model
    assert main(["characterise", "--params", str(old), "--model", "bouc_wen", "--amplitudes-mm", "1",
                 "--frequencies-hz", "10", "--out", str(tmp_path / "k.csv"), "--json"]) == 0
    assert main(["characterise", "--params", str(old), "--model", "proposed", "--amplitudes-mm", "1",
                 "--frequencies-hz", "10", "--out", str(tmp_path / "k2.csv")]) == 2


@pytest.mark.parametrize("plots", ["{file}/plots", "/proc/bushing_plots"])
def test_an_unwritable_plots_directory_is_refused_before_the_fit(tmp_path, capsys, plots):
    from identification.cli.arguments import main
    (tmp_path / "file").write_text("a file, not a directory")
    plots = plots.replace("{file}", str(tmp_path / "file"))
    started = time.monotonic()
    assert main(["fit", "--sine", str(SINE), "--out", str(tmp_path / "p.json"), "--plots", plots, "--quiet"]) == 2
    assert time.monotonic() - started < 20    # refused, not fitted: a fit takes a minute
    error = capsys.readouterr().err
    assert f"--plots {plots}:" in error and "Traceback" not in error
    assert not (tmp_path / "p.json").exists()


def test_progress_bars_are_off_when_stderr_is_not_a_terminal_and_a_warning_has_its_own_line(capsys):
    from identification.cli.commands import print_warning
    from identification.fitting.progress import SearchProgress, bar
    from identification.fitting.presets import PRESETS
    assert bar(10, "work", "items") is None          # pytest's captured stderr is not a terminal
    progress = SearchProgress(True, PRESETS["default"], 100)
    progress.screening(50)
    progress.close()
    print_warning("something to read")
    assert capsys.readouterr().err == "WARNING: something to read\n"   # nothing before it on its line


def test_the_command_line_offers_the_presets_defined_once():
    from identification.cli.arguments import main
    from identification.fitting.presets import PRESETS, describe
    with pytest.raises(SystemExit):
        main(["fit", "--preset", "no-such-preset", "--sine", str(SINE), "--out", "p.json"])
    parser_help = subprocess.run([sys.executable, "-m", "identification", "fit", "--help"], cwd=REPO,
                                 capture_output=True, text=True, timeout=60).stdout
    assert "{" + ",".join(PRESETS) + "}" in parser_help
    squashed = " ".join(parser_help.split())
    for name in PRESETS:
        assert " ".join(describe(name).split())[:40] in squashed
    assert str(PRESETS["default"].screening) in squashed


@pytest.mark.slow
def test_the_example_in_the_packages_docstring_runs_as_written(tmp_path):
    """identification/__init__.py's example, verbatim, in a folder where data/ is the repository's."""
    import os
    import textwrap

    import identification
    doc = identification.__doc__
    example = textwrap.dedent(doc[doc.index("::\n") + 3:doc.index("\nUnits:")])
    (tmp_path / "data").symlink_to(REPO / "data")
    (tmp_path / "example.py").write_text(example)
    environment = dict(os.environ, PYTHONPATH=str(REPO))
    done = subprocess.run([sys.executable, "example.py"], cwd=tmp_path, capture_output=True, text=True,
                          timeout=900, env=environment)
    assert done.returncode == 0, done.stderr[-3000:]
    assert "fitted to 2 test(s)" in done.stdout and "|K*|" in done.stdout
    assert (tmp_path / "params.json").is_file() and (tmp_path / "ensemble.json").is_file()


@pytest.mark.parametrize("script", ["examples/cosim/shaker_rig.py", "examples/cosim/engine_mount.py"])
def test_the_cosimulation_examples_name_the_extra_they_lack(script, tmp_path):
    code = ("import runpy, sys\nsys.modules['libcosimpy'] = None\n"
            f"sys.argv = [{script!r}, '--out', {str(tmp_path / 'out')!r}]\n"
            f"runpy.run_path({script!r}, run_name='__main__')\n")
    done = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, timeout=120)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert done.stderr.strip() == (f"error: {script} needs the 'cosim' extra (libcosimpy is not installed): "
                                   "pip install 'boucwen-bushing[cosim]'")
    assert not (tmp_path / "out").exists()


SUBPACKAGES = {"identification": ("measured", "forward", "fitting", "analysis", "property_files", "cli"),
               "fmu_src": ("model", "models", "kernels", "fmi")}
"""Each package's subpackages, in the order they may import each other: each only those before it."""


@pytest.mark.parametrize("name", SUBPACKAGES)
def test_the_package_docstrings_name_every_subpackage_and_module(name):
    import importlib
    import pkgutil

    top = importlib.import_module(name)
    modules = [m.name for m in pkgutil.iter_modules(top.__path__) if m.name != "__main__"]
    missing = [module for module in modules if f"``{module}``" not in top.__doc__]
    assert not missing, f"{name}/__init__.py's module map does not name {missing}"
    assert sorted(m.name for m in pkgutil.iter_modules(top.__path__) if m.ispkg) == sorted(SUBPACKAGES[name])
    for subpackage in SUBPACKAGES[name]:
        package = importlib.import_module(f"{name}.{subpackage}")
        modules = [m.name for m in pkgutil.iter_modules(package.__path__)]
        assert 0 < len(modules) <= 15, f"{name}/{subpackage} holds {len(modules)} modules"
        missing = [module for module in modules if f"``{module}``" not in package.__doc__]
        assert not missing, f"{name}/{subpackage}/__init__.py does not name {missing}"
        assert "May import" in package.__doc__


def _imports(path):
    """(line, absolute module name) of every import of the module at ``path``, at its top or inside a
    function, relative ones resolved."""
    import ast
    parts = path.relative_to(REPO).with_suffix("").parts
    here = list(parts[:-1])
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = ".".join(here[:len(here) - node.level + 1] + ([node.module] if node.module else []))
            yield from ((node.lineno, f"{base}.{alias.name}") for alias in node.names)
            yield node.lineno, base
        elif isinstance(node, ast.Import):
            yield from ((node.lineno, alias.name) for alias in node.names)


@pytest.mark.parametrize("name", SUBPACKAGES)
def test_subpackages_import_only_those_before_them(name):
    """Every import, at a module's top or inside a function, runs down the order of SUBPACKAGES; a
    module beside them (identification's errors, extras, interrupt) imports none of them, and
    fmu_src's parameter_files, above them all, any."""
    order = {subpackage: i for i, subpackage in enumerate(SUBPACKAGES[name])}
    wrong = []
    for path in sorted((REPO / name).rglob("*.py")):
        parts = path.relative_to(REPO).with_suffix("").parts
        if len(parts) == 2 and (parts[-1] in ("__init__", "__main__") or name == "fmu_src"):
            continue                                   # the front doors hand names on; parameter_files is on top
        here = parts[1] if len(parts) > 2 else None
        for line, imported in _imports(path):
            target = imported.split(".")
            if target[0] != name or len(target) < 2 or target[1] not in order:
                continue
            if here is None or order[target[1]] > order[here]:
                wrong.append(f"{path.relative_to(REPO)}:{line} imports {imported}")
    assert not wrong, wrong


def test_the_docs_layout_names_every_module_of_fmu_src():
    from conftest import REPO
    layout = (REPO / "docs" / "index.md").read_text()
    modules = sorted({p.name for p in (REPO / "fmu_src").rglob("*.py")} | {p.name + "/" for p in (REPO / "fmu_src").iterdir()
                                                                          if p.is_dir() and p.name != "__pycache__"})
    missing = [name for name in modules if f"`{name}`" not in layout]
    assert not missing, f"docs/index.md's Layout does not name {missing}"


def _module_of(name: str) -> str | None:
    """The module or package of this repository that the dotted ``name`` is, or is a name of."""
    while name:
        path = REPO / name.replace(".", "/")
        if path.with_suffix(".py").is_file() or (path / "__init__.py").is_file():
            return name
        name = name.rpartition(".")[0]
    return None


def _module_imports() -> dict[str, set[str]]:
    """{module: the modules of fmu_src and identification it imports, at its top or inside a
    function} (a package stands for its __init__)."""
    graph = {}
    for name in SUBPACKAGES:
        for path in sorted((REPO / name).rglob("*.py")):
            parts = path.relative_to(REPO).with_suffix("").parts
            module = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
            graph[module] = {target for _, imported in _imports(path) if imported.split(".")[0] in SUBPACKAGES
                             for target in [_module_of(imported)] if target and target != module}
    return graph


def test_no_two_modules_import_each_other_even_through_others():
    graph = _module_imports()
    circles = []

    def visit(module, path, on_path, done):
        on_path.add(module)
        for imported in sorted(graph.get(module, ())):
            if imported in on_path:
                circles.append(path[path.index(imported):] + [imported])
            elif imported not in done:
                visit(imported, path + [imported], on_path, done)
        on_path.discard(module)
        done.add(module)

    done = set()
    for module in sorted(graph):
        if module not in done:
            visit(module, [module], set(), done)
    # a package's __init__ handing its modules' names on is not a circle of the code
    circles = [c for c in circles if not any(m in SUBPACKAGES or m.count(".") == 1 and m.split(".")[1] in
                                             SUBPACKAGES[m.split(".")[0]] for m in c)]
    assert not circles, circles


def test_no_function_is_longer_than_a_reader_can_hold():
    import ast
    long = []
    for path in [*(REPO / "fmu_src").rglob("*.py"), *(REPO / "identification").rglob("*.py"), REPO / "build_fmu.py"]:
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and node.end_lineno - node.lineno >= 100:
                long.append(f"{path.relative_to(REPO)}:{node.lineno} {node.name}, {node.end_lineno - node.lineno + 1} lines")
    assert not long, long


COMPILED_KERNELS = {"identification/forward/population.py": {"_population_loop", "_STEP"},
                    "identification/forward/steady_state.py": {"_sine_steady_state"}}
"""Loops numba compiles, which take scalars and arrays (no records): exempt from the count below."""


def test_no_function_of_the_identification_or_the_fmi_layer_takes_more_than_seven_parameters():
    import ast
    many = []
    for path in [*(REPO / "identification").rglob("*.py"), *(REPO / "fmu_src" / "fmi").rglob("*.py")]:
        name = path.relative_to(REPO).as_posix()
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            arguments = node.args
            names = [a.arg for a in arguments.posonlyargs + arguments.args + arguments.kwonlyargs]
            count = len(names) - (names[:1] in (["self"], ["cls"])) + bool(arguments.vararg) + bool(arguments.kwarg)
            if count > 7 and node.name not in COMPILED_KERNELS.get(name, ()):
                many.append(f"{name}:{node.lineno} {node.name}, {count} parameters")
    assert not many, many
