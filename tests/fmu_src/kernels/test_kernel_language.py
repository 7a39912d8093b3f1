"""The kernel language's calls (fmu_src/kernels/kernel_language.py): every entry of the table is taken by
every tool that reads the kernels, and means the same in each.

- Python, numba and the C translation give the same result bit for bit (the C compiled with the
  native FMU's flags, tests/fmu_src/kernels/test_python_to_c.py's harness);
- the tangent generator's derivative of a ``chain`` entry equals its derivative written out here
  by hand (an analytic reference), and a ``zero`` entry (a count, a test) carries none;
- a call outside the table is refused by the translator and the tangent generator alike, naming the
  function and the line;
- docs/adding_a_model.md names every entry.
"""
import inspect
import math
from pathlib import Path

import pytest

from fmu_src.kernels import kernel_language
from fmu_src.kernels.jit import numba
from fmu_src.kernels.python_to_c import Translation, TranslationError
from fmu_src.kernels.tangents import TangentError, tangent
from test_python_to_c import python_lines, run_in_c, value_type

REPO = Path(__file__).resolve().parents[3]


def call_exp(a):
    return math.exp(a)


def call_log(a):
    return math.log(a)


def call_sqrt(a):
    return math.sqrt(a)


def call_sin(a):
    return math.sin(a)


def call_cos(a):
    return math.cos(a)


def call_fabs(a):
    return math.fabs(a)


def call_copysign(a, b):
    return math.copysign(a, b)


def call_pow(a, b):
    return math.pow(a, b)


def call_ceil(a):
    return math.ceil(a)


def call_floor(a):
    return math.floor(a)


def call_trunc(a):
    return math.trunc(a)


def call_isfinite(a):
    return math.isfinite(a), math.isfinite(a - a)        # inf - inf is a NaN


def call_isnan(a):
    return math.isnan(a), math.isnan(a - a)


def call_isinf(a):
    return math.isinf(a), math.isinf(a - a)


def call_abs(a):
    return abs(a)


def call_min(a, b):
    return min(a, b)


def call_max(a, b):
    return max(a, b)


def call_float(a):
    return float(a) * 0.5


def call_int(a):
    return int(a)


def call_len(a, pair):
    return len(pair) * a


def call_bool(a):
    return bool(a), bool(a - a)


CASES = {
    "exp": (call_exp, [(0.7,), (-3.25,)]),
    "log": (call_log, [(0.7,), (12.5,)]),
    "sqrt": (call_sqrt, [(0.7,), (2.0,)]),
    "sin": (call_sin, [(0.7,), (-4.0,)]),
    "cos": (call_cos, [(0.7,), (-4.0,)]),
    "fabs": (call_fabs, [(-0.7,), (2.5,), (-0.0,)]),
    "copysign": (call_copysign, [(0.7, -1.5), (-2.0, 3.0), (1.5, -0.0)]),
    "pow": (call_pow, [(1.7, 0.3), (0.5, -2.5), (2.0, 3.0)]),
    "ceil": (call_ceil, [(0.7,), (-2.5,), (-0.0,)]),
    "floor": (call_floor, [(0.7,), (-2.5,), (3.0,)]),
    "trunc": (call_trunc, [(0.7,), (-2.5,), (-3.999,)]),
    "isfinite": (call_isfinite, [(0.7,), (math.inf,)]),
    "isnan": (call_isnan, [(0.7,), (math.inf,)]),
    "isinf": (call_isinf, [(0.7,), (-math.inf,)]),
    "abs": (call_abs, [(-0.7,), (-0.0,), (-3,)]),
    "min": (call_min, [(0.7, -1.5), (-0.0, 0.0), (2, 5)]),
    "max": (call_max, [(0.7, -1.5), (0.0, -0.0), (2, 5)]),
    "float": (call_float, [(3,), (0.7,)]),
    "int": (call_int, [(0.7,), (-2.5,)]),
    "len": (call_len, [(0.7, (1.0, 2.0)), (1.5, (1.0, 2.0, 3.0))]),
    "bool": (call_bool, [(0.7,), (-0.0,), (math.inf,)]),
}

DERIVATIVES = {
    "exp": lambda a: (math.exp(a),),
    "log": lambda a: (1.0 / a,),
    "sqrt": lambda a: (0.5 / math.sqrt(a),),
    "sin": lambda a: (math.cos(a),),
    "cos": lambda a: (-math.sin(a),),
    "fabs": lambda a: (1.0 if a > 0 else -1.0,),
    "copysign": lambda a, b: ((1.0 if (a > 0) == (math.copysign(1.0, b) > 0) else -1.0), 0.0),
    "pow": lambda a, b: (b * a ** (b - 1.0), a ** b * math.log(a)),
    "abs": lambda a: (1.0 if a > 0 else -1.0,),
    "min": lambda a, b: (1.0, 0.0) if a < b else (0.0, 1.0),
    "max": lambda a, b: (1.0, 0.0) if a > b else (0.0, 1.0),
    "float": lambda a: (0.5,),
}
"""d(result)/d(each argument), by hand, at points away from any switch (the cases' floats, which
are not at a tie or at 0)."""


def test_every_entry_of_the_table_has_a_case_and_every_chain_entry_a_derivative():
    assert set(CASES) == {call.name for call in kernel_language.CALLS}
    assert set(DERIVATIVES) == {call.name for call in kernel_language.CALLS if call.tangent == "chain"}


@pytest.fixture(scope="module")
def c_results(tmp_path_factory):
    return run_in_c(list(CASES.values()), tmp_path_factory.mktemp("kernel_language"))


def _bits(value):
    if isinstance(value, tuple):
        return tuple(_bits(v) for v in value)
    return (type(value) is float, float(value).hex() if isinstance(value, float) else int(value))


@pytest.mark.parametrize("name", list(CASES))
def test_python_numba_and_c_agree_bit_for_bit(name, c_results):
    function, argument_sets = CASES[name]
    compiled = numba.njit(function)
    for index, arguments in enumerate(argument_sets):
        expected = function(*arguments)
        got = compiled(*arguments)
        assert _bits(got) == _bits(expected) or (numba_int_or_bool(got, expected)), (name, arguments, got, expected)
        printed, return_type = c_results[(function.__name__, index)]
        assert printed == python_lines(expected, return_type), (name, arguments)


def numba_int_or_bool(got, expected) -> bool:
    """numba returns its own int and bool types (np.int64, np.bool_), equal in value."""
    if isinstance(expected, tuple):
        return all(numba_int_or_bool(g, e) for g, e in zip(got, expected))
    return not isinstance(expected, float) and int(got) == int(expected) and not isinstance(got, float)


@pytest.mark.parametrize("name", [call.name for call in kernel_language.CALLS])
def test_the_tangent_of_every_entry(name):
    call = next(c for c in kernel_language.CALLS if c.name == name)
    function, argument_sets = CASES[name]
    for arguments in argument_sets:
        floats = [a for a in arguments if isinstance(a, float)]
        if len(floats) != len(arguments) or not all(math.isfinite(a) and a != 0.0 for a in arguments) \
                or len(set(arguments)) < len(arguments):
            continue    # ints, tuples and infinities carry no tangent to check here; at 0 and at a tie the
            #             stated one-sided values hold (tests/fmu_src/kernels/test_tangents.py)
        directions = tuple(0.5 + i for i in range(len(arguments)))
        value, derivative = tangent(function, inactive=())(*arguments, *directions)
        assert _bits(value) == _bits(function(*arguments)), (name, arguments)
        if call.tangent == "zero":
            assert all(d == 0.0 for d in (derivative if isinstance(derivative, tuple) else (derivative,))), name
            continue
        slopes = DERIVATIVES[name](*arguments)
        expected = sum(s * d for s, d in zip(slopes, directions))
        assert derivative == pytest.approx(expected, rel=1e-14, abs=1e-300), (name, arguments)


def call_tan(a):
    return math.tan(a)


def call_round(a):
    return round(a)


@pytest.mark.parametrize("function, words", [(call_tan, "math.tan"), (call_round, "round")])
def test_a_call_outside_the_table_is_refused_by_both_naming_function_and_line(function, words):
    line = function.__code__.co_firstlineno + 1
    with pytest.raises(TranslationError, match=f"line {line}.*{words}"):
        Translation(prefix="bw").function(function, tuple(value_type(a) for a in (0.5,)))
    with pytest.raises(TangentError, match=f"{function.__name__}, line {line}.*{words}"):
        tangent(function, inactive=())


from math import exp as exp_by_name  # noqa: E402  (the refused spelling below)


def exp_imported_by_name(a):
    return exp_by_name(a)


def variable_index(a):
    pair = (a, a)
    k = 1
    return pair[k]


def keyword_call(a):
    return call_tan(a=a)


def float_index(a):
    pair = (a, a)
    return pair[1.0]


@pytest.mark.parametrize("function, words", [
    (exp_imported_by_name, "exp_by_name is math.exp imported by name; write math.exp"),
    (variable_index, "only constant tuple indices"),
    (keyword_call, "keyword arguments"),
    (float_index, "index 1.0: only int tuple indices")])
def test_the_shared_analysis_refuses_alike_in_both_tools(function, words):
    # kernel_language.KernelFunction: one reading of names, calls and indices for both tools
    line = function.__code__.co_firstlineno + len(inspect.getsource(function).splitlines()) - 1   # the return
    with pytest.raises(TranslationError, match=f"{function.__name__}, line {line}: {words}"):
        Translation(prefix="bw").function(function, (value_type(0.5),))
    with pytest.raises(TangentError, match=f"{function.__name__}, line {line}: {words}"):
        tangent(function, inactive=())


def test_the_model_authors_guide_names_every_call():
    guide = (REPO / "docs" / "adding_a_model.md").read_text(encoding="utf-8")
    paragraph = guide[guide.index("What the translator takes"):guide.index("It refuses, with a `TranslationError`")]
    missing = [call.written for call in kernel_language.CALLS if f"`{call.written}`" not in paragraph]
    assert not missing, f"docs/adding_a_model.md does not name {missing}"


def test_the_jump_test_is_one_kernel_in_python_numba_and_c(tmp_path):
    # integration.displacement_jumped: the pythonfmu slave calls it, the compiled batched step
    # calls it compiled, the native C calls it translated; at and around its threshold all agree
    from fmu_src.model import integration
    cases = []
    for v, h in ((250.0, 1e-3), (0.0, 1e-3), (-80.0, 5e-4)):
        threshold = integration.JUMP_RELATIVE * (abs(v) * h) + integration.JUMP_FLOOR
        for mismatch in (threshold, math.nextafter(threshold, math.inf), math.nextafter(threshold, 0.0), 0.0):
            cases.append((1.0 + mismatch, 1.0, v, h))
            cases.append((-mismatch, 0.0, v, h))
    # (a double-valued case too: the driver's printer of doubles must be used)
    c = run_in_c([(integration.displacement_jumped, cases), (call_abs, [(-2.5,)])], tmp_path)
    compiled = numba.njit(integration.displacement_jumped)
    for index, arguments in enumerate(cases):
        python = integration.displacement_jumped(*arguments)
        assert bool(compiled(*arguments)) is python
        lines, _ = c[("displacement_jumped", index)]
        assert lines == python_lines(int(python), "int"), arguments


def test_every_differentiable_call_has_its_rule_in_the_table_and_no_other_does():
    for call in kernel_language.CALLS:
        assert (call.derivative is not None) == (call.tangent == "chain"), call.name


def test_the_tangent_generator_decides_no_call_by_its_name():
    # the table holds each call's rule (kernel_language.KernelCall.derivative, .active): the
    # generator compares no name of the table, alone or in a tuple
    import ast
    import inspect

    from fmu_src.kernels import tangents
    names = {call.name for call in kernel_language.CALLS}

    def constants(node):
        if isinstance(node, ast.Constant):
            return [node.value]
        if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
            return [element.value for element in node.elts if isinstance(element, ast.Constant)]
        return []
    named = [f"line {node.lineno}: {ast.unparse(node)}" for node in ast.walk(ast.parse(inspect.getsource(tangents)))
             if isinstance(node, ast.Compare)
             and names & {value for side in (node.left, *node.comparators) for value in constants(side)}]
    assert not named, named
