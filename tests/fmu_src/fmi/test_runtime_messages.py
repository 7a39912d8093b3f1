"""One runtime policy: the messages both FMUs log are defined once (``fmi.runtime_messages``), the
native FMU's C takes them from the generated ``bushing_messages.h``, and both runtimes log the
table's words, with their fields in the template's places."""
import ast
import math
import re
from pathlib import Path

import pytest

from fmu_src.fmi import runtime_messages
from fmu_src.fmi.runtime_messages import MESSAGES, Message
from fmu_harness import BushingFmu

ROOT = Path(__file__).resolve().parents[3]
C_LAYER = ROOT / "fmu_src" / "fmi" / "native" / "c"
SLAVE = ROOT / "fmu_src" / "fmi" / "pythonfmu_slave.py"
SHORTEST = 24
"""A piece of text this long in both is one written twice (shorter ones are words like ' is not a ')."""
STEP = 1e-3


def c_texts(source: str) -> list[str]:
    """The pieces of the C's string literals (adjacent literals joined) between printf conversions."""
    source = re.sub(r"/\*.*?\*/", " ", source, flags=re.S)
    literals, current = [], None
    for match in re.finditer(r'"((?:[^"\\]|\\.)*)"|(\S)', source):
        if match.group(1) is not None:
            current = (current or "") + match.group(1)
        elif current is not None:
            literals.append(current)
            current = None
    return [piece for literal in literals for piece in re.split(r"%[-+ #0-9.*l]*[a-zA-Z]", literal)]


def python_texts(source: str) -> list[str]:
    """The constant pieces of a module's string literals and f-strings, its docstrings left out."""
    tree = ast.parse(source)
    docstrings = {id(node.body[0].value) for node in ast.walk(tree)
                  if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef))
                  and node.body and isinstance(node.body[0], ast.Expr)
                  and isinstance(node.body[0].value, ast.Constant)}
    return [node.value for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docstrings]


def shared_pieces(c_pieces, python_pieces) -> set[str]:
    """The longest pieces of SHORTEST or more characters that stand in both."""
    python = "\x00".join(python_pieces)
    found = set()
    for piece in c_pieces:
        i = 0
        while i + SHORTEST <= len(piece):
            if piece[i:i + SHORTEST] in python:
                end = i + SHORTEST
                while end < len(piece) and piece[i:end + 1] in python:
                    end += 1
                found.add(piece[i:end])
                i = end
            else:
                i += 1
    return found


def test_the_scan_finds_a_message_written_in_both():
    c = c_texts('bw_log(inst, BW_ERROR, "logStatusError", "input %s = %s is not a finite number; the next "\n'
                '       "doStep will be refused", name, text);')
    python = python_texts('def f(name, value):\n    """is not a finite number; the next doStep docstring"""\n'
                          '    log(f"input {name} = {value} is not a finite number; the next doStep will be refused")\n')
    assert shared_pieces(c, python) == {" is not a finite number; the next doStep will be refused"}
    assert shared_pieces(c, python_texts('"""is not a finite number; the next doStep will be refused"""')) == set()


def test_no_message_is_written_in_both_runtimes():
    c = [piece for path in sorted(C_LAYER.glob("*.c")) for piece in c_texts(path.read_text())]
    python = [text for path in sorted((ROOT / "fmu_src").rglob("*.py"))
              for text in python_texts(path.read_text())]
    assert shared_pieces(c, python) == set()


def test_every_message_of_the_table_is_used_by_the_c_and_every_shared_one_by_the_slave():
    c = "".join(path.read_text() for path in C_LAYER.glob("*.c"))
    slave = SLAVE.read_text()
    # the parameter checks' words reach the slave through the model contract (BushingModel.validate)
    contract = {"PARAMETER_NOT_FINITE", "PARAMETER_OUT_OF_RANGE", "CONSTRAINT_BROKEN", "CONSTRAINT_DOUBTFUL",
                "GROUP_PARAMETER_NOT_ZERO"}
    native_only = {"NOT_COMPUTABLE", "JUMP_NOT_DIFFERENTIABLE", "DERIVATIVE_NOT_FINITE", "RATE_DERIVATIVE_NOT_FINITE"}
    for name in MESSAGES:
        assert f"BW_MESSAGE_{name}(" in c, name
        if name not in contract | native_only:
            assert f'"{name}"' in slave, name
    for name in runtime_messages.TEXTS:
        assert f"BW_TEXT_{name}" in c, name


def test_a_message_fills_its_fields_and_refuses_others():
    message = Message("error", "input {port} = {value} {unit}; {port} again, {h:g} s, {n:d}")
    assert message.fields == ("port", "value", "unit", "h", "n")
    assert message.text(port="x", value=0.5, unit="m", h=1e-3, n=3) == "input x = 0.5 m; x again, 0.001 s, 3"
    assert message.c_format() == ("input %s = %s %s; %s again, %g s, %d", ("port", "value", "unit", "port", "h", "n"))
    with pytest.raises(TypeError, match="takes"):
        message.text(port="x")
    with pytest.raises(ValueError, match="level"):
        Message("notice", "text")
    assert Message("error", "100 % sure {x}").c_format()[0] == "100 %% sure %s"


def pattern(name: str) -> re.Pattern:
    """The message as a regular expression: each field any text (maybe none), a repeated field the same."""
    regex, seen = "", set()
    for literal, field, _, _ in __import__("string").Formatter().parse(MESSAGES[name].template):
        regex += re.escape(literal)
        if field is not None:
            regex += f"(?P={field})" if field in seen else f"(?P<{field}>.*?)"
            seen.add(field)
    return re.compile(regex + "$")


@pytest.fixture(params=["pythonfmu", "native"])
def fmu_path(request):
    """The Table 5 FMU of each kind (conftest's session fixtures)."""
    return request.getfixturevalue("fmu_path" if request.param == "pythonfmu" else "native_fmu_path")


def test_both_runtimes_log_the_tables_words(fmu_path):
    fmu = BushingFmu(fmu_path)
    for k in range(10):
        assert fmu.step(1e-4 * k, 0.1, STEP) == "ok"
    assert fmu.do_step(0.0) == "discard"
    fmu.set("v", math.inf)
    assert fmu.do_step(STEP) == "discard"
    fmu.set("v", 0.0)
    fmu.set("c1", -1.0)
    assert fmu.do_step(STEP) == "discard"
    fmu.set("c1", 1.0)
    assert fmu.step(2.0, 0.0, STEP) == "discard"    # millimetres entered as metres
    errors, warnings = fmu.messages_with("error"), fmu.messages_with("warning")
    expected_errors = [
        MESSAGES["STEP_SIZE_INVALID"].text(value=0.0),
        MESSAGES["INPUT_SET_NOT_FINITE"].text(port="v", value=math.inf, unit="m/s"),
        MESSAGES["STEP_INPUT_NOT_FINITE"].text(port="v", value=math.inf, unit="m/s"),
        MESSAGES["PARAMETER_OUT_OF_RANGE"].text(label="", name="c1", value=-1.0, unit="N.s/mm", allowed="> 0",
                                                why=" (it divides eq. 3)"),
        MESSAGES["STEP_PARAMETERS_INVALID"].text(reason=runtime_messages.TEXTS["PARAMETERS_INVALID"]),
    ]
    for message in expected_errors:
        assert message in errors, (message, errors)
    assert MESSAGES["DISPLACEMENT_BEYOND_TRAVEL"].text(port="x", value=2.0, limit=0.1) in warnings
    refusal = [m for m in errors if m.startswith("doStep at t = ")][-1]
    match = next(m for m in (pattern(name).match(refusal) for name in ("STEP_TOO_MANY_SUBSTEPS", "STEP_NOT_FINITE",
                                                                        "STEP_OUTPUT_NOT_FINITE")) if m)
    assert match["label"] == "" and match["inputs"] == "x = 2.0 m, v = 0.0 m/s", refusal
    assert float(match["time"]) == pytest.approx(0.01)
    fmu.free()


def test_both_runtimes_word_a_jumping_input_and_an_implausible_force_alike(fmu_path):
    fmu = BushingFmu(fmu_path)
    for k in range(60):     # x sampled from a 2 mm, 20 Hz sine, v = 0: every step jumps
        assert fmu.step(2e-3 * math.sin(40 * math.pi * k * STEP), 0.0, STEP) == "ok"
    for k in range(500):    # 2 (mm meant) as metres
        assert fmu.step(k * 4e-3, 4.0, STEP) == "ok"
    warnings = fmu.messages_with("warning")
    jumps = next(pattern("DISPLACEMENT_JUMPS").match(m) for m in warnings if "jumps in" in m)
    assert (jumps["label"], jumps["port"], jumps["velocity"], jumps["unit"]) == ("", "x", "v", "m")
    assert int(jumps["count"]) == 31 and int(jumps["window"]) == 50
    implausible = next(pattern("OUTPUT_IMPLAUSIBLE").match(m) for m in warnings if "largest plausible" in m)
    assert (implausible["output"], implausible["unit"], implausible["quantity"], implausible["motion"],
            implausible["units"]) == ("F", "N", "force", "travel and speed", "metres")
    assert re.fullmatch(r"x = \S+ m, v = 4\.0 m/s", implausible["inputs"])
    fmu.free()
