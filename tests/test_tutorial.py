"""The tutorial's Python examples run as written, in order, after its first command."""

import contextlib
import io
import pathlib
import re
import tempfile
import unittest

from mobee_drake import cli

TUTORIAL = pathlib.Path(__file__).parents[1] / "docs" / "tutorial.md"


class TestTutorial(unittest.TestCase):
    def test_the_examples_run(self):
        text = TUTORIAL.read_text()
        blocks = [block.split("```", 1)[0] for block in text.split("```python\n")[1:]]
        self.assertEqual(len(blocks), 3)
        printed = io.StringIO()
        with contextlib.chdir(tempfile.mkdtemp()), contextlib.redirect_stdout(printed):
            cli.main(["run", "reach_around_ball", "--no-record"])
            for block in blocks:
                exec(compile(block, str(TUTORIAL), "exec"), {})
        # The palm marker's closest approach is what section 2 says it is.
        stated = re.search(r"never comes closer than ([0-9.]+) cm", TUTORIAL.read_text())
        self.assertIsNotNone(stated)
        text = printed.getvalue()
        self.assertIn(f"closest {stated.group(1)} cm", text)
        self.assertIn("right_arm", text)  # the agent with the strategy of section 5


if __name__ == "__main__":
    unittest.main()
