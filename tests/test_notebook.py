"""The example notebook runs from start to end (so it cannot rot), in an empty folder with the
wheel installed (tests/installed_wheel.py)."""

import base64
import html
import os
import pathlib
import re
import tempfile
import unittest
from unittest import mock

from installed_wheel import Environment, InstalledWheel
import msgpack
import nbclient
import nbformat

NOTEBOOK = pathlib.Path(__file__).parents[1] / "examples" / "first_steps.ipynb"


class TestNotebook(unittest.TestCase):
    def test_first_steps_runs_and_plots(self):
        notebook = nbformat.read(NOTEBOOK, as_version=4)
        probe = nbformat.v4.new_code_cell("import mobee_drake; print(mobee_drake.__file__)")
        notebook.cells.append(probe)
        # The kernel draws inline, as in Jupyter (the suite's MPLBACKEND=Agg would hide plots).
        with mock.patch.dict(os.environ, Environment()):
            os.environ.pop("MPLBACKEND", None)
            nbclient.NotebookClient(notebook, timeout=300, kernel_name="python3").execute(
                cwd=tempfile.mkdtemp()
            )
        (where,) = [o["text"] for o in probe.outputs]
        self.assertTrue(where.startswith(str(InstalledWheel()[1])), where)  # the installed copy
        outputs = [o for cell in notebook.cells for o in cell.get("outputs", [])]
        self.assertFalse([o for o in outputs if o.output_type == "error"])
        text = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
        self.assertIn("closest approach:", text)
        self.assertIn("rows: 601", text)  # 6 s at 10 ms, both ends
        images = [o for o in outputs if "image/png" in o.get("data", {})]
        self.assertEqual(len(images), 1)  # the plot
        # The run's recording is in the notebook itself (it replays without a server).
        (frame,) = [o["data"]["text/html"] for o in outputs if "text/html" in o.get("data", {})]
        recording = html.unescape(re.fullmatch(r'<iframe srcdoc="([^"]*)".*', frame)[1])
        commands = [
            msgpack.unpackb(base64.b64decode(blob), strict_map_key=False)
            for blob in re.findall(r'octet-binary;base64,([A-Za-z0-9+/=]*)"', recording)
        ]
        kinds = {c["type"] for c in commands}
        self.assertLessEqual({"set_object", "set_animation"}, kinds)
        paths = {c.get("path", "") for c in commands}
        self.assertTrue(any(p.startswith("/drake/illustration/icub") for p in paths))
        (animation,) = [c for c in commands if c["type"] == "set_animation"]
        self.assertGreater(len(animation["animations"]), 10)  # the robot moves in it


if __name__ == "__main__":
    unittest.main()
