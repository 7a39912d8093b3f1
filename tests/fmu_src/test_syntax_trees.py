"""Source is parsed one thread at a time (fmu_src/syntax_trees.py: CPython 3.11's parser shares a
recursion counter between threads, python/cpython#106905)."""
import ast
import pathlib
import sys
import threading

import pytest

from fmu_src import syntax_trees

REPO = pathlib.Path(syntax_trees.__file__).parents[1]


def _held_elsewhere() -> bool:
    """Whether another thread holds the parsing lock (an RLock: this thread could re-enter it)."""
    result = []

    def probe():
        got = syntax_trees._PARSING.acquire(blocking=False)
        if got:
            syntax_trees._PARSING.release()
        result.append(not got)
    thread = threading.Thread(target=probe)
    thread.start()
    thread.join()
    return result[0]


def test_no_module_of_the_packages_parses_source_but_through_the_lock():
    direct = [f"{path.relative_to(REPO)}:{node.lineno}"
              for package in ("fmu_src", "identification")
              for path in sorted((REPO / package).rglob("*.py")) if path.name != "syntax_trees.py"
              for node in ast.walk(ast.parse(path.read_text()))
              if isinstance(node, ast.Attribute) and node.attr == "parse"
              and isinstance(node.value, ast.Name) and node.value.id == "ast"]
    assert direct == [], f"ast.parse outside fmu_src/syntax_trees.parse: {direct}"


def test_parse_holds_the_lock_while_parsing(monkeypatch):
    held = []

    def parse_and_look(source, mode):
        held.append(_held_elsewhere())
        return ast.Module(body=[], type_ignores=[])

    monkeypatch.setattr(syntax_trees, "_UNSERIALISED_PARSE", parse_and_look)
    syntax_trees.parse("x = 1")
    assert held == [True] and not _held_elsewhere()


@pytest.mark.skipif(sys.version_info >= (3, 12), reason="CPython 3.12 keeps the counter per thread")
def test_every_callers_ast_parse_waits_for_the_lock():
    # numba parses a function's source while it compiles it (numba.misc.firstlinefinder), on the
    # race's compiling thread: its ast.parse must wait while another thread parses
    done = threading.Event()
    thread = threading.Thread(target=lambda: (ast.parse("x = 1"), done.set()))
    with syntax_trees._PARSING:
        thread.start()
        assert not done.wait(0.3)
    thread.join(5)
    assert done.is_set()


def test_a_syntax_error_releases_the_lock():
    with pytest.raises(SyntaxError):
        syntax_trees.parse("def (")
    with pytest.raises(SyntaxError):
        ast.parse("def (")
    assert not _held_elsewhere()


def test_a_second_copy_of_the_module_takes_the_first_ones_lock():
    # a pythonfmu FMU's resources carry their own copy of fmu_src, which a test process loads beside it
    import importlib.util
    spec = importlib.util.spec_from_file_location("a_second_copy_of_syntax_trees", syntax_trees.__file__)
    copy = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(copy)
    assert copy._PARSING is syntax_trees._PARSING
    assert copy._UNSERIALISED_PARSE is syntax_trees._UNSERIALISED_PARSE
