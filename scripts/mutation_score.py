"""The mutation score of a finished ``mutmut run`` (docs/testing.md), per mutated package.

Reads the per-file results mutmut keeps in ``mutants/**/*.py.meta`` (run from the folder that
holds ``mutants/``), counts each mutant's status as mutmut names it, and prints a markdown table:
per package (``mobee_drake/mobee``, ``mobee_drake/station``) and both, the mutants, those killed,
survived, timed out, without a test, crashed, not (yet) checked, and (killed + timeout) /
mutants. With ``--doc`` the table replaces the generated block ``mutation-score`` of that doc.

Run: ``python scripts/mutation_score.py [--mutants mutants] [--doc docs/testing.md]``.
"""

import argparse
import collections
import json
import pathlib
import sys

from mutmut.stats import status_by_exit_code

from mobee_drake.experiments.doc_tables import WriteGeneratedTable

PACKAGES = ("mobee", "station")
COLUMNS = ("killed", "survived", "timeout", "no tests", "segfault", "not checked")


def Tally(mutants: pathlib.Path) -> dict[str, collections.Counter]:
    """Per package, the count of each status."""
    tallies = {package: collections.Counter() for package in PACKAGES}
    for package in PACKAGES:
        for meta in sorted((mutants / "mobee_drake" / package).rglob("*.py.meta")):
            codes = json.loads(meta.read_text())["exit_code_by_key"]
            tallies[package].update(status_by_exit_code[code] for code in codes.values())
    return tallies


def Table(tallies: dict[str, collections.Counter]) -> str:
    rows = dict(tallies, both=sum(tallies.values(), collections.Counter()))
    lines = [
        "| | mutants | killed | survived | timeout | no test | crashed | not checked | (killed + "
        "timeout) / mutants |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for name, counts in rows.items():
        total = sum(counts.values())
        score = (counts["killed"] + counts["timeout"]) / total if total else 0.0
        label = f"{name}/" if name in PACKAGES else name
        cells = [f"{counts[c]:,}" for c in COLUMNS]
        lines.append(f"| {label} | {total:,} | " + " | ".join(cells) + f" | {100 * score:.1f} % |")
    return "\n".join(lines)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mutants", default="mutants", help="mutmut's folder of results")
    parser.add_argument("--doc", help="a doc whose generated block 'mutation-score' to rewrite")
    args = parser.parse_args(argv)
    mutants = pathlib.Path(args.mutants)
    if not mutants.is_dir():
        sys.exit(f"mutation_score: {mutants} is not a folder of mutmut results")
    table = Table(Tally(mutants))
    print(table)
    if args.doc:
        command = f"python scripts/mutation_score.py --mutants {args.mutants} --doc {args.doc}"
        WriteGeneratedTable(args.doc, "mutation-score", command, table)


if __name__ == "__main__":
    main()
