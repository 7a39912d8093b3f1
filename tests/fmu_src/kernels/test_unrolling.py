"""The kernels' source as numba and the C translation read it: tuple(...) and sum(...) over a
constant range written out term by term (fmu_src/kernels/unrolling.py), with the plain-Python result bit
for bit; the compiled path's contract on a model module's imports and step kernels
(fmu_src/kernels/numba_binding.py), checked on its syntax tree."""
import ast
import dataclasses
import math
import re
import sys
import textwrap

import pytest

from fmu_src.kernels import numba_binding as compiled_kernels
from fmu_src.model.registry import MODELS
from fmu_src.model.definition import ModelContractError
from fmu_src.kernels.python_to_c import DOUBLE, Translation, TranslationError
from fmu_src.kernels.unrolling import UnrollError, unroll

MODES = 4
SOURCE = textwrap.dedent('''
    def kernel(k, f, v):
        rates = tuple(math.exp(0.5 * i) for i in range(MODES))
        updated = tuple(f[i] * rates[i] + k[i] * v for i in range(1, MODES + 0 * 1 - 0))
        return updated, sum(k[i] * f[i] for i in range(MODES))
''')


def unrolled_function(source, namespace):
    tree = unroll(ast.parse(source), namespace, "test")
    code = compile(tree, "<unrolled>", "exec")
    exec(code, namespace)
    return namespace["kernel"]


def test_unrolled_tuples_and_sums_give_the_plain_python_floats_bit_for_bit():
    namespace = {"math": math, "MODES": MODES}
    exec(compile(SOURCE, "<plain>", "exec"), namespace)
    plain = namespace["kernel"]
    # the range with a non-literal bound is left as it is; the others are written out
    text = ast.unparse(unroll(ast.parse(SOURCE), {"math": math, "MODES": MODES}, "test"))
    assert "math.exp(0.5 * 3)" in text and "0 + k[0] * f[0] + k[1] * f[1]" in text
    assert "for i in range(1, MODES + 0 * 1 - 0)" in text
    unrolled = unrolled_function(SOURCE, {"math": math, "MODES": MODES})
    for k, f, v in [((1.5, -2.0, 0.1, 3.0), (0.3, 0.7, -1.1, 1e-300), 2.5),
                    ((-0.0, -0.0, -0.0, -0.0), (1.0, 1.0, 1.0, 1.0), 0.0)]:
        assert repr(unrolled(k, f, v)) == repr(plain(k, f, v))   # repr: -0.0 and 0.0 differ


def test_an_unrolled_sum_starts_from_zero_as_pythons_does():
    source = "def kernel(a):\n    return sum(a[i] for i in range(2))\n"
    unrolled = unrolled_function(source, {})
    assert repr(unrolled((-0.0, -0.0))) == repr(sum((-0.0, -0.0))) == "0.0"


@pytest.mark.parametrize("generator", ["x[i] for i in range(3) if i > 0", "x[i] + j for i in range(3) for j in range(2)"])
def test_a_generator_it_cannot_write_out_names_the_line(generator):
    source = f"\n\ndef kernel(x):\n    return tuple({generator})\n"
    with pytest.raises(UnrollError, match=r"where, line 4: tuple\(\.\.\. for name in range"):
        unroll(ast.parse(source), {}, "where")


def test_the_c_translation_writes_the_terms_out(tmp_path):
    namespace = {"math": math, "MODES": 3}
    source = textwrap.dedent('''
        def mean_rate(m):
            return sum(m[i] for i in range(MODES)) / MODES
    ''')
    path = tmp_path / "unrolled_kernel.py"
    path.write_text(source)
    import importlib.util
    spec = importlib.util.spec_from_file_location("unrolled_kernel", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.MODES = namespace["MODES"]
    translation = Translation()
    function = translation.function(module.mean_rate, ((DOUBLE, DOUBLE, DOUBLE),))
    assert function.return_type == DOUBLE
    assert "(((0 + m.f0) + m.f1) + m.f2)" in translation.source()


def test_the_c_translation_refuses_a_generator_over_anything_else(tmp_path):
    path = tmp_path / "refused_kernel.py"
    path.write_text("def total(m):\n    return sum(value for value in m)\n")
    import importlib.util
    spec = importlib.util.spec_from_file_location("refused_kernel", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    with pytest.raises(TranslationError, match="refused_kernel.total, line 2"):
        Translation().function(module.total, ((DOUBLE, DOUBLE),))


def test_indices_are_folded_and_a_written_out_tuple_is_spliced_into_a_display():
    source = "def kernel(state, v):\n    return (v, 0.0, *tuple(state[2 + i] * 2 for i in range(3)))\n"
    text = ast.unparse(unroll(ast.parse(source), {}, "test"))
    assert "return (v, 0.0, state[2] * 2, state[3] * 2, state[4] * 2)" in text
    namespace = {}
    exec(source, namespace)
    assert unrolled_function(source, {})((1.0, 2.0, 3.0, 4.0, 5.0), 7.0) == namespace["kernel"]((1.0, 2.0, 3.0, 4.0, 5.0), 7.0)


def test_floor_division_and_remainder_of_indices_are_folded_as_python_computes_them():
    # element i of 3-vectors of a spectrum: its mode i // 3 and its component i % 3
    source = "def kernel(k, v):\n    return tuple(k[i // 3] * v[i % 3] for i in range(6))\n"
    text = ast.unparse(unroll(ast.parse(source), {}, "test"))
    assert "return (k[0] * v[0], k[0] * v[1], k[0] * v[2], k[1] * v[0], k[1] * v[1], k[1] * v[2])" in text
    namespace = {}
    exec(source, namespace)
    assert unrolled_function(source, {})((2.0, 3.0), (1.0, 5.0, 7.0)) == namespace["kernel"]((2.0, 3.0), (1.0, 5.0, 7.0))


ALLOWED_IMPORTS = textwrap.dedent('''
    from __future__ import annotations

    import math

    from ..model.parameter_specs import SPRING, ParameterSpec
    from ..model.integration import OK, maxwell_step as step_of_a_maxwell_element
    from .berg_model import CUBIC
''')


def test_a_model_modules_allowed_imports_are_pointed_at_the_compiled_machinery_and_the_package():
    tree = compiled_kernels.checked_imports(ast.parse(ALLOWED_IMPORTS), "pkg.models.some_model", "machinery_0123",
                                            "pkg.models")
    assert ast.unparse(tree).splitlines() == [
        "from __future__ import annotations", "import math", "from pkg.model.parameter_specs import SPRING, ParameterSpec",
        "from machinery_0123 import OK, maxwell_step as step_of_a_maxwell_element",
        "from pkg.models.berg_model import CUBIC"]


@pytest.mark.parametrize("statement", [
    "from math import exp", "import numpy as np", "import math as m", "import math, os", "from . import integration",
    "from ..integration import OK", "from ..model.integration import *", "from .native.build import FLAGS",
    "from numpy import exp", "from ..model import integration", "from ...fmi.axes import Axis",
    "from ..kernels.tangents import tangent", "from ..model.native.build import FLAGS"])
def test_any_other_import_form_is_refused_naming_module_and_line(statement):
    source = f"import math\n\n{statement}\n"
    expected = rf"^pkg\.models\.some_model, line 3: {re.escape(repr(statement))} is not allowed.*may import only: " \
        "from __future__"
    with pytest.raises(ModelContractError, match=expected):
        compiled_kernels.checked_imports(ast.parse(source), "pkg.models.some_model", "machinery_0123", "pkg.models")


def test_an_import_inside_a_kernel_is_refused():
    source = "import math\n\n\ndef force(m, state, x, v):\n    from ..model.integration import OK\n    return OK\n"
    with pytest.raises(ModelContractError, match=r"pkg.models.some_model, line 5: 'from \.\.model\.integration import OK' "
                                                 "is inside a function or block"):
        compiled_kernels.checked_imports(ast.parse(source), "pkg.models.some_model", "machinery_0123", "pkg.models")


@pytest.mark.parametrize("name", list(MODELS))
def test_every_registered_model_keeps_the_compiled_paths_contract(name):
    module = sys.modules[MODELS[name].kernel_module]
    source = compiled_kernels.kernel_source(module, "machinery_0123")
    assert "from machinery_0123 import" in source and "from ." not in source


def test_a_model_whose_step_kernels_are_not_the_modules_jump_and_integrate_is_refused_when_defined():
    model = MODELS["kelvin_voigt"]

    def other_jump(m, state, jump_mm):
        return state, 0
    with pytest.raises(ModelContractError, match=r"kelvin_voigt_model: the step protocol calls its global 'jump', "
                                                 r"which is <function jump .*not the model 'kelvin_voigt''s jump"):
        dataclasses.replace(model, jump=other_jump)
