"""The platform a result records: the BLAS kernels chosen at run time, not the build's."""

import json
import os
import pathlib
import subprocess
import sys
import tempfile
import unittest

from mobee_drake.experiments.platform_record import PlatformRecord


def _Recorded(**environment: str) -> dict:
    """The record a fresh process prints (``python -m ...platform_record``) in ``environment``."""
    done = subprocess.run(
        [sys.executable, "-m", "mobee_drake.experiments.platform_record"],
        capture_output=True, text=True, check=True, env={**os.environ, **environment},
    )  # fmt: skip
    return json.loads(done.stdout)


class TestPlatformRecord(unittest.TestCase):
    def test_the_command_prints_this_processs_record(self):
        record = PlatformRecord()
        self.assertEqual(_Recorded(), record)
        self.assertEqual(
            record["python"], ".".join(map(str, sys.version_info[:3]))
        )  # (and numpy's, scipy's and Drake's versions, the CPU)
        self.assertTrue(all(record[name] for name in ("numpy", "scipy", "drake", "cpu")))

    def test_a_sitting_of_older_code_gets_its_line(self):
        """Given a battery folder, the command appends its last sitting's line."""
        with tempfile.TemporaryDirectory() as folder:
            sessions = pathlib.Path(folder, "sessions.jsonl")
            sessions.write_text(
                '{"began": "2026-01-01T00:00:00Z"}\n{"began": "2026-01-02T00:00:00Z"}\n'
            )
            for _ in range(2):
                subprocess.run(
                    [sys.executable, "-m", "mobee_drake.experiments.platform_record", folder],
                    capture_output=True, check=True,
                )  # fmt: skip
            lines = [json.loads(line) for line in open(pathlib.Path(folder, "platforms.jsonl"))]
        self.assertEqual(
            lines, [{"began": "2026-01-02T00:00:00Z", "platform": PlatformRecord()}] * 2
        )

    def test_each_openblas_names_the_kernel_it_chose(self):
        """OpenBLAS picks its kernel at run time: the record names the one chosen (here forced
        with OPENBLAS_CORETYPE), for numpy's BLAS and scipy's own alike."""
        openblas = [b for b in PlatformRecord()["blas"] if "openblas" in b["library"]]
        if not openblas:
            self.skipTest("numpy and scipy use no OpenBLAS here")
        forced = _Recorded(OPENBLAS_CORETYPE="Nehalem")["blas"]
        self.assertEqual(
            [b["architecture"] for b in forced if "openblas" in b["library"]],
            ["Nehalem"] * len(openblas),
        )


if __name__ == "__main__":
    unittest.main()
