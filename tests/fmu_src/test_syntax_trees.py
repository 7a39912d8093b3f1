"""Source is parsed one thread at a time (fmu_src/syntax_trees.py: CPython 3.11's parser shares a
recursion counter between threads, python/cpython#106905)."""
import ast
import pathlib
import threading

import pytest

from fmu_src import syntax_trees

FMU_SRC = pathlib.Path(syntax_trees.__file__).parent


def test_no_module_of_fmu_src_parses_source_but_through_the_lock():
    direct = [f"{path.relative_to(FMU_SRC.parent)}:{node.lineno}"
              for path in sorted(FMU_SRC.rglob("*.py")) if path.name != "syntax_trees.py"
              for node in ast.walk(ast.parse(path.read_text()))
              if isinstance(node, ast.Attribute) and node.attr == "parse"
              and isinstance(node.value, ast.Name) and node.value.id == "ast"]
    assert direct == [], f"ast.parse outside fmu_src/syntax_trees.parse: {direct}"


def test_parse_holds_the_lock_while_parsing(monkeypatch):
    held = []

    def parse_and_look(source, mode):
        held.append(syntax_trees._PARSING.locked())
        return ast.Module(body=[], type_ignores=[])

    monkeypatch.setattr(syntax_trees.ast, "parse", parse_and_look)
    syntax_trees.parse("x = 1")
    assert held == [True] and not syntax_trees._PARSING.locked()


def test_a_syntax_error_releases_the_lock():
    with pytest.raises(SyntaxError):
        syntax_trees.parse("def (")
    thread = threading.Thread(target=syntax_trees.parse, args=("x = 1",))
    thread.start()
    thread.join(5)
    assert not thread.is_alive()
