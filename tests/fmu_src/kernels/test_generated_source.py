"""Generated modules are checked when generated: a function reading a name the module does not
bind is refused, naming the function and the name (fmu_src/kernels/generated_source.py)."""
import ast
import sys

import pytest

from fmu_src.kernels import numba_binding as compiled_kernels
from fmu_src.model.registry import get_model
from fmu_src.kernels.generated_source import GenerationError, unbound_names
from identification.forward import population as compiled_core

TEMPLATE = '''
def _template(row):
    total = 0.0
    for k in range(len(row)):
        total += row[k] * SCALE
    return [prepare(v) for v in row], _UNBOUND(total), math.pi
'''


def test_the_unbound_names_of_a_template_are_found_and_nothing_else():
    source = "import math\nSCALE = 2.0\n\ndef prepare(p):\n    return p\n" + TEMPLATE
    assert unbound_names(source) == [("_template", 7, "_UNBOUND")]
    assert unbound_names(source + "\n_UNBOUND = abs\n") == []
    # a binding in a conditional import at the top counts, as the step protocol's prepare_step does
    assert unbound_names(source + "\nif True:\n    from math import fabs as _UNBOUND\n") == []


def test_a_generated_module_whose_template_reads_an_unbound_name_is_refused_at_generation(monkeypatch, tmp_path):
    monkeypatch.setenv(compiled_kernels.CACHE_ENVIRONMENT, str(tmp_path))
    model = get_model("single_bouc_wen")
    source = compiled_core._population_source(model).replace("_STORE(sensitivities, i, 0, d_f)",
                                                             "_STORE_FORCE(sensitivities, i, 0, d_f)")
    name = compiled_kernels.module_name("bushing_probe", source)
    with pytest.raises(GenerationError, match=r"_population_loop \(line \d+\) reads '_STORE_FORCE'"):
        compiled_kernels.load_generated(name, source)
    assert not (tmp_path / f"{name}.py").exists()       # nothing written


@pytest.mark.slow
def test_every_models_generated_modules_bind_every_name_they_read():
    from identification.forward import parameter_jacobian as fit_jacobian
    machinery = compiled_kernels.integration_module()
    for name in ("proposed", "berg", "fractional", "kelvin_voigt", "hydraulic", "hydraulic_free_decoupler"):
        model = get_model(name)
        for source in (compiled_core._population_source(model),
                       *(compiled_kernels.model_source(model, machinery, appendix)
                         for appendix in (compiled_kernels._fmu_appendix(model), fit_jacobian._appendix(model, 2, machinery)))):
            unbound = unbound_names(source)
            assert [found for found in unbound if found[2] not in compiled_kernels.INJECTED] == [], name


@pytest.mark.slow
def test_a_generated_module_names_no_package_so_every_fmu_shares_it():
    """The source (and so the name and numba's cache) of a model's generated modules is the same
    for fmu_src and for every FMU's packed copy: it imports nothing from the package and keeps of
    the model's module its kernels and constants, the constants written in as values."""
    from identification.forward import parameter_jacobian as fit_jacobian
    machinery = compiled_kernels.integration_module()
    for name in ("proposed", "fractional", "hydraulic_free_decoupler", "single_bouc_wen+backbone4+limits+rig"):
        model = get_model(name)
        for source in (compiled_core._population_source(model),
                       *(compiled_kernels.model_source(model, machinery, appendix)
                         for appendix in (compiled_kernels._fmu_appendix(model), fit_jacobian._appendix(model, 2, machinery)))):
            imported = [node.module for node in ast.walk(ast.parse(source)) if isinstance(node, ast.ImportFrom)]
            assert not [module for module in imported if module.startswith("fmu_src")], name
            assert "ParameterSpec(" not in source and "MODEL =" not in source, name
    # fractional reads berg_model's constants: there as values, not as an import of another module
    tree = ast.parse(compiled_kernels.kernel_source(sys.modules[get_model("fractional").kernel_module], machinery))
    assert not [node for node in ast.walk(tree) if isinstance(node, ast.ImportFrom) and "berg_model" in node.module]
    # what stays at the top besides functions and imports: constants written in as values
    values = [node.value for node in tree.body if isinstance(node, (ast.Assign, ast.AnnAssign))]
    assert values and all(isinstance(value, (ast.Constant, ast.Tuple, ast.UnaryOp)) for value in values)


def test_the_population_loops_take_the_kernels_the_fmu_runs():
    """One compiled copy of a model's kernels: the population loops' module imports them from the
    model's compiled module, which the FMU runs, instead of compiling them again."""
    for name in ("kelvin_voigt", "single_bouc_wen+backbone4+limits+rig"):
        model = get_model(name)
        population, kernels = compiled_core.compiled_model(model), compiled_kernels.kernel_module(model)
        for kernel in compiled_core.KERNELS:
            assert getattr(population, kernel) is getattr(kernels, kernel), (name, kernel)
