"""The tutorial runs as written, in order, in an empty folder with the wheel installed: every
command and every Python example (tests/installed_wheel.py)."""

import pathlib
import re
import tempfile
import unittest

from installed_wheel import CodeBlocks, RunCommandLine, RunPython

TUTORIAL = pathlib.Path(__file__).parents[1] / "docs" / "tutorial.md"


class TestTutorial(unittest.TestCase):
    def test_every_command_and_example_runs(self):
        text = TUTORIAL.read_text()
        folder = pathlib.Path(tempfile.mkdtemp())
        printed = []
        blocks = [(kind, code) for kind, code in CodeBlocks(text) if kind in ("", "python")]
        for kind, code in blocks:
            with self.subTest(code.splitlines()[0]):
                if kind == "python":
                    printed.append(RunPython(code, folder))
                else:
                    printed.extend(RunCommandLine(line, folder) for line in code.splitlines())
        printed = "".join(printed)
        # Section 1's first command is the main job; section 6's copy of a scenario holds it.
        self.assertIn("closest approach of the robot's solids", printed)
        self.assertIn("robot: !ModelFileConfig", (folder / "my_arm.yaml").read_text())
        self.assertIn("pillar", printed)
        self.assertTrue((folder / "results" / "ch7" / "report_7.1.md").is_file())
        # The palm marker's closest approach is what section 2 says it is.
        stated = re.search(r"never comes closer than ([0-9.]+) cm", " ".join(text.split()))
        self.assertIsNotNone(stated)
        self.assertIn(f"closest {stated.group(1)} cm", printed)
        self.assertIn("right_arm", printed)  # the agent with the strategy of section 5


if __name__ == "__main__":
    unittest.main()
