"""The TeimOrbit text format other tools' property files are written in: ``$`` comment lines,
``[BLOCK]`` headers, ``NAME = value`` lines (a quoted string or a number), ``(SUB_BLOCK)``
headers, ``{ column column }`` table headers and rows of numbers. :func:`read_teimorbit` reads a
file into its blocks, each line's number kept for the errors a reader raises."""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from identification.errors import IdentificationError


@dataclass
class Table:
    """A ``{ a b }`` table: its ``columns`` and ``rows`` (each the line number and its cells:
    numbers, or the text of a quoted cell)."""
    columns: tuple[str, ...]
    rows: list[tuple[int, tuple]] = field(default_factory=list)


@dataclass
class Block:
    """A ``[NAME]`` block: its ``values`` {NAME: (line, str or float)}, its ``tables`` {sub-block
    name or "": Table} and the line it starts on."""
    name: str
    line: int
    values: dict[str, tuple[int, object]] = field(default_factory=dict)
    tables: dict[str, Table] = field(default_factory=dict)


_BLOCK = re.compile(r"^\[(?P<name>[A-Za-z0-9_]+)\]$")
_SUB = re.compile(r"^\((?P<name>[A-Za-z0-9_]+)\)$")
_VALUE = re.compile(r"^(?P<name>[A-Za-z0-9_]+)\s*=\s*(?P<value>.+)$")


def _value(text: str, path: Path, number: int):
    text = text.strip()
    if len(text) >= 2 and text[0] == text[-1] and text[0] in "'\"":
        return text[1:-1]
    try:
        return float(text)
    except ValueError:
        raise IdentificationError(f"{path}, line {number}: {text!r} is neither a number nor a quoted string") from None


def _without_comment(line: str) -> str:
    """The line without a trailing ``$`` comment (a ``$`` inside quotes is text)."""
    quote = ""
    for i, character in enumerate(line):
        if quote:
            quote = "" if character == quote else quote
        elif character in "'\"":
            quote = character
        elif character == "$":
            return line[:i]
    return line


def read_teimorbit(path: str | Path) -> dict[str, Block]:
    """The blocks of a TeimOrbit file by name (module docstring). IdentificationError names the
    file and line of what it cannot read (a line outside every block, a block twice, a table row
    with a column too many or too few or not a number)."""
    path = Path(path)
    try:
        lines = path.read_text(encoding="utf-8-sig", errors="strict").splitlines()   # -sig: a BOM
    except FileNotFoundError:
        raise IdentificationError(f"property file {path} does not exist") from None
    except UnicodeDecodeError as exc:
        raise IdentificationError(f"{path}: not a text file ({exc})") from None
    blocks: dict[str, Block] = {}
    block, sub, table = None, "", None
    for number, raw in enumerate(lines, start=1):
        line = _without_comment(raw).strip()
        if not line or line.startswith("$"):
            continue
        if (match := _BLOCK.match(line)) is not None:
            name = match["name"].upper()
            if name in blocks:
                raise IdentificationError(f"{path}, line {number}: block [{name}] given twice (also line "
                                          f"{blocks[name].line})")
            block, sub, table = Block(name, number), "", None
            blocks[name] = block
            continue
        if block is None:
            raise IdentificationError(f"{path}, line {number}: {line!r} stands before the first [BLOCK]")
        if (match := _SUB.match(line)) is not None:
            sub, table = match["name"].upper(), None
            continue
        if sub == "COMMENTS":          # free text until the next sub-block or block
            continue
        if line.startswith("{") and line.endswith("}"):
            table = Table(tuple(line[1:-1].split()))
            block.tables[sub] = table
            continue
        if (match := _VALUE.match(line)) is not None and table is None:
            name = match["name"].upper()
            if name in block.values:
                raise IdentificationError(f"{path}, line {number}: [{block.name}] gives {name} twice (also line "
                                          f"{block.values[name][0]})")
            block.values[name] = (number, _value(match["value"], path, number))
            continue
        if table is not None:
            cells = line.split()
            if len(cells) != len(table.columns):
                raise IdentificationError(f"{path}, line {number}: {len(cells)} values for the {len(table.columns)} "
                                          f"columns {' '.join(table.columns)} of [{block.name}]")
            table.rows.append((number, tuple(_value(cell, path, number) for cell in cells)))
            continue
        raise IdentificationError(f"{path}, line {number}: {line!r} is not a value, a table or a block")
    return blocks


def read_layout(path: str | Path, known: set[str], layout: str, blocks_in_words: str) -> dict[str, Block]:
    """:func:`read_teimorbit` of a file whose blocks must be among ``known`` (the ``layout``'s, a
    ``.gbs``'s or a ``.bus``'s, ``blocks_in_words`` what they are): another is refused with its line."""
    blocks = read_teimorbit(path)
    unknown = sorted(set(blocks) - known)
    if unknown:
        raise IdentificationError(f"{path}: block(s) {', '.join(f'[{b}] (line {blocks[b].line})' for b in unknown)} "
                                  f"not in the {layout} layout; its blocks are {blocks_in_words}")
    return blocks
