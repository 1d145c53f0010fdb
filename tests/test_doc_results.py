"""The tables of docs/ that a report writes from a battery kept in docs/results are what the
report gives from the kept result files now: a table edited by hand, or left behind by runs
added to its folder since, fails (docs/results/README.md)."""

import pathlib
import re
import unittest

from mobee_drake.experiments.ch8_claims import ClaimsTables
from mobee_drake.experiments.ch8_reaching import StoredResults
from mobee_drake.experiments.doc_tables import GeneratedTable

ROOT = pathlib.Path(__file__).parents[1]

# The opening marker of a generated block written by the ch. 8 report of a kept battery.
_CH8_KEPT = re.compile(
    r"^<!-- generated: (?P<name>[\w-]+), by mobee-drake experiment ch8 --report-only "
    r"--output (?P<folder>docs/results/\S+) ",
    flags=re.MULTILINE,
)


class TestKeptBatteries(unittest.TestCase):
    def test_every_ch8_claims_table_is_what_its_kept_runs_give(self):
        blocks = [
            (doc, found["name"], ROOT / found["folder"])
            for doc in sorted((ROOT / "docs").glob("*.md"))
            for found in _CH8_KEPT.finditer(doc.read_text())
        ]
        self.assertLessEqual({"ch8-stage100", "ch8-sweep400"}, {name for _, name, _ in blocks})
        for doc, name, folder in blocks:
            with self.subTest(doc=doc.name, block=name):
                results = StoredResults(folder)
                self.assertTrue(results, f"{folder}: no finished runs")
                self.assertEqual(
                    GeneratedTable(doc, name).rstrip(), "\n".join(ClaimsTables(results)).rstrip()
                )
