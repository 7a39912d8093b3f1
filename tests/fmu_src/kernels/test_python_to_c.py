"""The Python -> C translator (fmu_src/kernels/python_to_c.py) as a compiler: every construct it
translates, compiled by the system's C compiler with the native FMU's flags and run, gives the
Python function's result bit for bit; every construct whose C meaning differs from Python's is
refused with a TranslationError naming the function and the line; every registered model's
kernels translate (the check a model author gets, here rather than at import: translating a
model's kernels takes 10-100 ms, too long for every import of the registry).

All supported cases are compiled into one C program by one compiler call (a module fixture)."""
import inspect
import math
import os
import re
import shutil
import struct
import subprocess
from math import exp  # noqa: F401  the refused case `exp_imported_by_name` calls it

import pytest

from fmu_src.model.registry import MODELS
from fmu_src.fmi.native.build import FLAGS, WARNINGS
from fmu_src.fmi.native.generate import ModelCode
from fmu_src.kernels.python_to_c import DOUBLE, INT, Translation, TranslationError

COMPILER = os.environ.get("CC", "cc")   # what build_native compiles the linux binary with
SCALE = 2.5       # a module-level float constant the kernels read
COUNT = 3         # a module-level int constant (also a constant range for tuple/sum)


# ---------------------------------------------------------------- supported constructs
def arithmetic(a, b):
    return (a + b) * (a - b) / b - a * 0.1


def int_true_division(i, j):
    return i / j


def mixed_int_and_float(i, a):
    return i * a + i - 3


def power_with_a_float(a, b):
    return a ** b + a ** 2 + 2 ** b


def unary_signs(a, i):
    return -a, +a, -i


def comparisons_chained_too(a, b, c):
    return a < b < c, a <= b, a > b, a >= c, a == b, a != c, 0.0 < a <= 1.0


def and_or_not_as_tests(a, b):
    if a or b:                                   # floats' truth: C's || and Python agree on it
        first = 1.0
    else:
        first = 2.0
    second = 3.0 if a and not b else 4.0
    return first + second


def and_or_of_booleans(a, b):
    return (a > 0.0 and b > 0.0) or not math.isfinite(a), a < b and True


def conditional_expression(a, i):
    return a if i > 0 else i                     # an int and a float: a float


def if_elif_else(a):
    if a < -1.0:
        result = -1.0
    elif a < 1.0:
        result = a
    else:
        result = 1.0
    return result


def while_with_break_and_continue(n):
    total = 0
    count = 0
    while True:
        count += 1
        if count > n:
            break
        if count == 2:
            continue
        total += count
    return total, count


def for_ranges_with_else(n, limit):
    total = 0.0
    for i in range(n):
        total += i * 0.5
    for k in range(2, n):
        if k > limit:
            break
        total -= k
    else:
        total += 100.0
    return total


def augmented_assignment(a, i):
    a += 1.5
    a -= 0.25
    a *= 3.0
    a /= 7.0
    i += 2
    i *= 3
    i -= 1
    return a, i


def tuples_unpacked_and_indexed(pair, a):
    (x, (y, z)) = (pair[0], (pair[-1], a))
    nested = ((x, y), z)
    return nested[0][1] + z, (z, x)


def helper_kernel(state, gain):
    return state[0] * gain, state[1] + gain


def calls_another_kernel(state, gain):
    first = helper_kernel(state, gain)
    return helper_kernel(first, 2)               # with an int: translated once more


def builtin_functions(a, i, j):
    return abs(a), abs(i), min(i, j), max(a, i), min(-0.0, 0.0), max(0.0, -0.0), int(a), float(i)


def math_functions(a):
    return (math.exp(a), math.log(a), math.sqrt(a), math.sin(a), math.cos(a), math.ceil(-a),
            math.isfinite(a), math.isfinite(-math.inf), math.pi * a)


def module_constants(a):
    return a * SCALE + COUNT


def unrolled_tuple_and_sum(values):
    scaled = tuple(values[i] * SCALE for i in range(COUNT))
    return sum(scaled[i] for i in range(COUNT)), scaled


def docstring_and_pass(a):
    """A docstring is no statement of the C."""
    if a > 0.0:
        pass
    return a


def values_only_an_unused_value_reads(a, i):
    """A value never read is not computed, and so neither is what only it reads (else the C would
    set variables it never uses, which -Werror refuses): a tangent of a value that feeds a count."""
    doubled = a * 2.0
    unused = doubled + 1.0         # noqa: F841 (the point of the case)
    count = i * 2
    unused_too = count * 3         # noqa: F841
    return a + 1.0


SUPPORTED = [
    (arithmetic, [(1.5, 0.3), (-2.75, 1e-300), (1e308, -3.0)]),
    (int_true_division, [(7, 3), (-7, 2), (1, 3)]),
    (mixed_int_and_float, [(3, 0.1), (-5, 2.5)]),
    (power_with_a_float, [(1.7, 0.3), (0.5, -2.5), (3.0, 2.0)]),
    (unary_signs, [(0.0, 0), (-1.25, 7)]),
    (comparisons_chained_too, [(0.5, 0.75, 1.0), (1.0, 1.0, 0.0), (2.0, 0.5, 3.0)]),
    (and_or_not_as_tests, [(0.0, 0.0), (2.5, 0.0), (0.0, -1.0), (1.0, 1.0)]),
    (and_or_of_booleans, [(1.0, 2.0), (-1.0, 2.0), (1.0, -2.0), (math.inf, 1.0)]),
    (conditional_expression, [(1.5, 1), (1.5, 0), (-2.0, -4)]),
    (if_elif_else, [(-3.0,), (0.25,), (7.0,)]),
    (while_with_break_and_continue, [(0,), (1,), (5,)]),
    (for_ranges_with_else, [(0, 10), (4, 10), (6, 3), (1, 0)]),
    (augmented_assignment, [(0.1, 4), (-3.0, -2)]),
    (tuples_unpacked_and_indexed, [((1.5, -0.5), 2.0)]),
    (calls_another_kernel, [((1.5, -0.5), 0.3)]),
    (builtin_functions, [(-2.7, -3, 4), (2.7, 5, 5), (-0.0, 0, -1)]),
    (math_functions, [(0.7,), (2.5,), (1e-5,)]),
    (module_constants, [(0.1,), (-7.0,)]),
    (unrolled_tuple_and_sum, [((0.1, 0.2, 0.3),), ((1e16, -1e16, 1.0),)]),
    (docstring_and_pass, [(0.5,), (-0.0,)]),
    (values_only_an_unused_value_reads, [(0.5, 3)]),
]


def value_type(value):
    """The translator's type of a Python argument value."""
    if isinstance(value, tuple):
        return tuple(value_type(element) for element in value)
    return DOUBLE if isinstance(value, float) else INT


def c_literal(value, t, translation: Translation) -> str:
    """``value`` as a C expression of type ``t``: floats as hexadecimal literals (exact)."""
    if isinstance(t, tuple):
        fields = ", ".join(c_literal(v, e, translation) for v, e in zip(value, t))
        return f"({translation.c_type(t)}){{{fields}}}"
    if t == DOUBLE and math.isinf(value):
        return "HUGE_VAL" if value > 0 else "(-HUGE_VAL)"
    return float.hex(value) if t == DOUBLE else str(value)


def c_prints(expression: str, t) -> list[str]:
    """C statements printing ``expression`` of type ``t``, one scalar a line (floats as their bits)."""
    if isinstance(t, tuple):
        return [line for i, e in enumerate(t) for line in c_prints(f"{expression}.f{i}", e)]
    return [f"print_double({expression});" if t == DOUBLE else f"print_int({expression});"]


def python_lines(value, t) -> list[str]:
    """What the C program prints for ``value`` of type ``t``."""
    if isinstance(t, tuple):
        assert isinstance(value, tuple) and len(value) == len(t)
        return [line for v, e in zip(value, t) for line in python_lines(v, e)]
    if t == DOUBLE:
        # a float, or an int where the translator merged an int and a float into a double
        assert isinstance(value, float) or float(value) == value
        value = float(value)
        return [f"d {struct.unpack('<Q', struct.pack('<d', value))[0]:016x}"]
    assert isinstance(value, (int, bool)) and not isinstance(value, float)
    return [f"i {int(value)}"]


DRIVER_HEAD = """#include <stdio.h>
#include <string.h>
static void print_double(double x) {
    unsigned long long bits;
    memcpy(&bits, &x, sizeof bits);
    printf("d %016llx\\n", bits);
}
static void print_int(int i) { printf("i %d\\n", i); }
"""


def run_in_c(cases, folder) -> dict:
    """{(case name, argument index): (the lines the compiled C printed, the C function's return
    type)} of ``cases`` [(function, [arguments, ...]), ...]: every case in one program, one compiler
    call in ``folder``; skips where there is no C compiler."""
    if shutil.which(COMPILER) is None:
        pytest.skip(f"no C compiler: {COMPILER} is not installed (set CC to one)")
    translation = Translation(prefix="bw")
    calls, return_types = [], {}
    for function, argument_sets in cases:
        for index, arguments in enumerate(argument_sets):
            types_ = tuple(value_type(a) for a in arguments)
            translated = translation.function(function, types_)
            literals = ", ".join(c_literal(a, t, translation) for a, t in zip(arguments, types_))
            result_type = translated.return_type
            return_types[(function.__name__, index)] = result_type
            calls += [f'    printf("case {function.__name__} {index}\\n");', "    {",
                      f"        {translation.c_type(result_type)} r = {translated.name}({literals});",
                      *[f"        {line}" for line in c_prints("r", result_type)], "    }"]
    program = folder / "cases.c"
    program.write_text(DRIVER_HEAD + translation.source() + "\nint main(void) {\n" + "\n".join(calls)
                       + "\n    return 0;\n}\n")
    executable = folder / "cases"
    compiled = subprocess.run([COMPILER, *WARNINGS, *FLAGS, "-o", str(executable), str(program), "-lm"],
                              capture_output=True, text=True)
    assert compiled.returncode == 0, compiled.stderr[-4000:]
    output = subprocess.run([str(executable)], capture_output=True, text=True, check=True).stdout
    results, current = {}, None
    for line in output.splitlines():
        if line.startswith("case "):
            _, name, index = line.split()
            current = results.setdefault((name, int(index)), [])
        else:
            current.append(line)
    return {key: (lines, return_types[key]) for key, lines in results.items()}


@pytest.fixture(scope="module")
def c_results(tmp_path_factory):
    """:func:`run_in_c` of every supported case."""
    return run_in_c(SUPPORTED, tmp_path_factory.mktemp("python_to_c"))


@pytest.mark.parametrize("function, argument_sets", SUPPORTED, ids=[f.__name__ for f, _ in SUPPORTED])
def test_a_supported_construct_compiles_to_c_that_gives_pythons_result_bit_for_bit(c_results, function,
                                                                                   argument_sets):
    for index, arguments in enumerate(argument_sets):
        printed, return_type = c_results[(function.__name__, index)]
        assert printed == python_lines(function(*arguments), return_type), f"{function.__name__}{arguments}"


# ---------------------------------------------------------------- refused constructs
def or_as_a_number(a, b):
    result = a or b  # refused
    return result


def and_as_a_number(i, j):
    return i and j  # refused


def loop_variable_after_its_loop(n):
    total = 0.0
    for i in range(n):
        total += 1.0
    return total + i  # refused


def loop_variable_in_the_loops_else(n):
    total = 0.0
    for i in range(n):
        total += 1.0
    else:
        total += i  # refused
    return total


def loop_variable_assigned_in_its_loop(n):
    total = 0
    for i in range(n):
        i = 5  # refused
        total += i
    return total


def loop_variable_reused_by_an_inner_loop(n):
    total = 0
    for i in range(n):
        for i in range(2):  # refused
            total += i
    return total


def unknown_builtin(a):
    return round(a)  # refused


def exp_imported_by_name(a):
    return exp(a)  # refused


def math_function_not_translated(a):
    return math.tan(a)  # refused


def method_call(a):
    return a.hex()  # refused


def floor_division(i, j):
    return i // j  # refused


def modulo(a, b):
    return a % b  # refused


def int_power(i, j):
    return i ** j  # refused


def import_in_a_kernel(a):
    import os  # refused
    return a


def identity_comparison(a, b):
    return a is b  # refused


def int_beyond_c_int(a):
    return a * 3_000_000_000  # refused


def tuple_as_a_truth_value(pair):
    if pair:  # refused
        return 1.0
    return 0.0


def keyword_argument(state):
    return helper_kernel(state, gain=1.0)  # refused


def recursion(n):
    if n > 0:
        return recursion(n - 1)  # refused
    return 0


def unknown_name(a):
    return a * undefined_gain  # noqa: F821  # refused


def variable_tuple_index(pair, i):
    return pair[i]  # refused


def while_else(n):
    while n > 0:  # refused
        n -= 1
    else:
        n = 3
    return n


def bit_operation(i, j):
    return i & j  # refused


def list_display(a):
    values = [a, a]  # refused
    return values


D, I, DD = DOUBLE, INT, (DOUBLE, DOUBLE)
REFUSED = [
    (or_as_a_number, (D, D), "or used as a number"),
    (and_as_a_number, (I, I), "and used as a number"),
    (loop_variable_after_its_loop, (I,), "loop variable 'i' is read outside its loop"),
    (loop_variable_in_the_loops_else, (I,), "loop variable 'i' is read outside its loop"),
    (loop_variable_assigned_in_its_loop, (I,), "loop variable 'i' is assigned other than by its for"),
    (loop_variable_reused_by_an_inner_loop, (I,), "loop variable 'i' is reused by a loop inside its loop"),
    (unknown_builtin, (D,), r"call of round \(builtin_function_or_method\) is not translated; only other kernels"),
    (exp_imported_by_name, (D,), r"exp is math.exp imported by name; write math.exp"),
    (math_function_not_translated, (D,), "math.tan is not translated"),
    (method_call, (D,), r"call of a.hex is not translated; only other kernels"),
    (floor_division, (I, I), "operator //: Python rounds towards minus infinity"),
    (modulo, (D, D), "operator %: Python rounds towards minus infinity"),
    (int_power, (I, I), r"int \*\* int"),
    (import_in_a_kernel, (D,), "an import in a kernel"),
    (identity_comparison, (D, D), "comparison Is: only"),
    (int_beyond_c_int, (D,), "the int 3000000000 is beyond C's int"),
    (tuple_as_a_truth_value, (DD,), "a tuple as a truth value"),
    (keyword_argument, (DD,), "keyword arguments"),
    (recursion, (I,), "recursion calls itself"),
    (unknown_name, (D,), "unknown name 'undefined_gain'"),
    (variable_tuple_index, (DD, I), "only constant tuple indices"),
    (while_else, (I,), r"while \.\.\. else"),
    (bit_operation, (I, I), "operator BitAnd: only"),
    (list_display, (D,), "expression List is not supported"),
]


def refused_line(function) -> int:
    """The file line of ``function`` marked ``# refused``."""
    lines, first = inspect.getsourcelines(function)
    marked = [i for i, line in enumerate(lines) if line.rstrip().endswith("# refused")]
    assert len(marked) == 1, function.__name__
    return first + marked[0]


@pytest.mark.parametrize("function, argument_types, reason", REFUSED, ids=[f.__name__ for f, _, _ in REFUSED])
def test_a_construct_whose_c_would_differ_is_refused_naming_function_and_line(function, argument_types, reason):
    with pytest.raises(TranslationError) as refusal:
        Translation().function(function, argument_types)
    message = str(refusal.value)
    assert message.startswith(f"{__name__}.{function.__name__}, line {refused_line(function)}: "), message
    assert re.search(reason, message), message


def test_a_builtin_given_as_a_kernel_is_refused_with_a_translation_error():
    with pytest.raises(TranslationError, match=r"<built-in function round> is not a Python function"):
        Translation().function(round, (DOUBLE,))


def equality_tests(a, n):
    while n != 0:
        n -= 1
    if a == 0.0:
        return 1.0
    if a < 1.0 and n == 0:
        return 2.0
    return 3.0


def test_an_if_or_while_on_one_comparison_has_one_pair_of_parentheses():
    # clang refuses `if ((a == b))` under -Werror (-Wparentheses-equality): the test's own pair only
    translation = Translation(prefix="bw")
    translation.function(equality_tests, (DOUBLE, INT))
    source = translation.source()
    assert "while (n != 0) {" in source and "if (a == 0.0) {" in source
    assert "if (((a < 1.0) && (n == 0))) {" in source      # a compound test keeps its grouping
    assert "((n != 0))" not in source and "((a == 0.0))" not in source


@pytest.mark.parametrize("name", list(MODELS))
def test_every_registered_models_kernels_translate(name):
    code = ModelCode(Translation(prefix="bw"), MODELS[name])
    assert all(t == DOUBLE for t in code.state_type)
    assert code.kernels["force"].return_type == DOUBLE
