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
# A generated block, in a text whose whitespace is folded.
_BLOCK = re.compile(r"<!-- generated: ([\w.-]+), by .*? -->.*?<!-- end generated: \1 -->")
# A ratio with its interval, as the prose quotes one: "1.43 [1.40, 1.46]".
_RATIO = re.compile(r"(\d+\.\d+) \[(\d+\.\d+), (\d+\.\d+)\]")


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

    def test_the_ratios_the_prose_quotes_are_its_generated_blocks(self):
        """docs/reaching.md's prose quotes random's robot time over the others' from its
        generated blocks (R times [low, high]); a block written again from new runs fails the
        prose that still quotes the old figures."""
        text = " ".join((ROOT / "docs" / "reaching.md").read_text().split())
        blocks = " ".join(block[0] for block in _BLOCK.finditer(text))
        quoted = _RATIO.findall(_BLOCK.sub("", text))
        self.assertTrue(quoted)
        for ratio, low, high in quoted:
            with self.subTest(ratio=ratio):
                self.assertIn(f"{ratio} times [{low}, {high}]", blocks)
