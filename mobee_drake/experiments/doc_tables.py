"""Tables in docs/ that a command writes: each sits between two marker lines naming it and the
command that generates it, so that a table and its benchmark cannot disagree.

    <!-- generated: NAME, by COMMAND -->
    | ... the table ... |
    <!-- end generated: NAME -->
"""

import argparse
import pathlib
import re

from mobee_drake.atomic_files import WriteTextAtomically


def _Block(name: str | None = None) -> re.Pattern:
    """The block ``name``, or any block."""
    names = r"[^,\n]+" if name is None else re.escape(name)
    return re.compile(
        rf"^<!-- generated: (?P<name>{names}), by (?P<command>.*?) -->\n"
        rf"(?P<table>.*?)^<!-- end generated: (?P=name) -->$",
        flags=re.MULTILINE | re.DOTALL,
    )


def GeneratedBlocks(doc: str | pathlib.Path) -> list[tuple[str, str, str]]:
    """Every generated block of ``doc``, in order: (name, command, text)."""
    text = pathlib.Path(doc).read_text()
    return [(m["name"], m["command"], m["table"]) for m in _Block().finditer(text)]


def GeneratedTable(doc: str | pathlib.Path, name: str) -> str:
    """The text of the generated block ``name`` in ``doc``; ValueError naming the file if the
    block is missing."""
    match = _Block(name).search(pathlib.Path(doc).read_text())
    if match is None:
        raise ValueError(f"{doc}: no generated block '{name}'")
    return match["table"]


def CheckDocBlocks(parser: argparse.ArgumentParser, doc: str | None, *names: str) -> None:
    """Ends the command in one line through ``parser.error`` (exit code 2) if ``doc`` is given
    and cannot be read or lacks one of the generated blocks ``names``: checked before a run
    spends its time."""
    if not doc:
        return
    for name in names:
        try:
            GeneratedTable(doc, name)
        except (OSError, ValueError) as error:
            parser.error(f"--doc: {error}")


def WriteGeneratedTable(doc: str | pathlib.Path, name: str, command: str, table: str) -> None:
    """Replaces the generated block ``name`` of ``doc`` with ``table`` (and names ``command``
    in its opening marker); ValueError naming the file if the block is missing."""
    doc = pathlib.Path(doc)
    text = doc.read_text()
    block = _Block(name)
    if block.search(text) is None:
        raise ValueError(f"{doc}: no generated block '{name}' to write")
    replacement = (
        f"<!-- generated: {name}, by {command} -->\n{table.rstrip()}\n"
        f"<!-- end generated: {name} -->"
    )
    WriteTextAtomically(doc, block.sub(lambda _: replacement, text, count=1))


# What a table shows where a figure is missing (never measured, not applicable).
_NO_FIGURE = ("-", "n/a")


def TableLayout(table: str) -> list[list[str]]:
    """A markdown table's layout: per row its label cells (those that hold no figure nor stand
    for a missing one), so that two tables of the same rows and columns compare equal whatever
    their figures."""
    rows = []
    for line in table.strip().splitlines():
        if not line.startswith("|"):
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        rows.append(["#" if re.search(r"\d", c) or c in _NO_FIGURE else c for c in cells])
    return rows
