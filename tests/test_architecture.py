"""The package's architecture: no import cycles, no imports hidden in functions, one plotting
backend, and a release that ships what a run needs."""

import ast
import contextlib
import io
import os
import pathlib
import subprocess
import sys
import tempfile
import unittest
import zipfile

import grimp

from mobee_drake import cli

PACKAGE = pathlib.Path(__file__).resolve().parents[1] / "mobee_drake"
ROOT = PACKAGE.parent


def _Cycles(graph: grimp.ImportGraph) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan's algorithm)."""
    index, low, stack, on_stack, cycles = {}, {}, [], set(), []

    def Visit(module: str) -> None:
        index[module] = low[module] = len(index)
        stack.append(module)
        on_stack.add(module)
        for imported in graph.find_modules_directly_imported_by(module):
            if imported not in index:
                Visit(imported)
                low[module] = min(low[module], low[imported])
            elif imported in on_stack:
                low[module] = min(low[module], index[imported])
        if low[module] == index[module]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == module:
                    break
            if len(component) > 1:
                cycles.append(sorted(component))

    for module in sorted(graph.modules):
        if module not in index:
            Visit(module)
    return cycles


class TestImports(unittest.TestCase):
    def test_no_module_imports_itself_through_others(self):
        graph = grimp.build_graph("mobee_drake", include_external_packages=False)
        self.assertGreater(len(graph.modules), 50)
        self.assertEqual(_Cycles(graph), [])

    def test_the_cycle_finder_finds_a_cycle(self):
        graph = grimp.ImportGraph()
        for module in ("a", "b", "c"):
            graph.add_module(module)
        graph.add_import(importer="a", imported="b")
        graph.add_import(importer="b", imported="c")
        self.assertEqual(_Cycles(graph), [])
        graph.add_import(importer="c", imported="a")
        self.assertEqual(_Cycles(graph), [["a", "b", "c"]])

    def test_no_package_import_inside_a_function(self):
        hidden = []
        for path in sorted(PACKAGE.rglob("*.py")):
            tree = ast.parse(path.read_text())
            for function in ast.walk(tree):
                if not isinstance(function, ast.FunctionDef | ast.AsyncFunctionDef):
                    continue
                for node in ast.walk(function):
                    names = (
                        [node.module or ""]
                        if isinstance(node, ast.ImportFrom)
                        else [a.name for a in node.names]
                        if isinstance(node, ast.Import)
                        else []
                    )
                    if any(name.startswith("mobee_drake") for name in names):
                        hidden.append(f"{path.relative_to(ROOT)}:{node.lineno}")
        self.assertEqual(hidden, [])

    def test_one_module_sets_the_plotting_backend(self):
        setters = [
            str(path.relative_to(ROOT))
            for path in sorted(PACKAGE.rglob("*.py"))
            if "matplotlib.use(" in path.read_text()
        ]
        self.assertEqual(setters, ["mobee_drake/experiments/plots.py"])

    def test_every_package_says_what_it_is(self):
        for init in sorted(PACKAGE.rglob("__init__.py")):
            docstring = ast.get_docstring(ast.parse(init.read_text()))
            self.assertTrue(docstring and len(docstring) > 40, init)


class TestReadme(unittest.TestCase):
    def test_the_first_screen_has_two_commands(self):
        first_screen = (ROOT / "README.md").read_text().split("## ")[0]
        commands = [
            line for line in first_screen.splitlines() if line.startswith("python3 -m venv")
        ]
        self.assertEqual(len(commands), 2)
        self.assertIn("mobee-drake run", commands[0])
        self.assertIn("pytest", commands[1])

    @staticmethod
    def _Example(containing: str) -> str:
        """The README's Python example that contains ``containing`` (unindented)."""
        text = (ROOT / "README.md").read_text()
        blocks = [block.split("```", 1)[0] for block in text.split("```python\n")[1:]]
        (code,) = [block for block in blocks if containing in block]
        return "\n".join(line[2:] if line.startswith("  ") else line for line in code.splitlines())

    def test_the_client_example_runs(self):
        printed = io.StringIO()
        with contextlib.redirect_stdout(printed):
            exec(compile(self._Example("class BendElbow"), "README.md", "exec"), {})
        self.assertIn("[", printed.getvalue())  # the robot's state

    def test_the_data_log_example_plots_the_main_job(self):
        folder = pathlib.Path(tempfile.mkdtemp())
        with contextlib.chdir(folder), contextlib.redirect_stdout(io.StringIO()):
            cli.main(["run", "reach_around_ball", "--no-record"])
            exec(compile(self._Example("read_parquet"), "README.md", "exec"), {})
        self.assertGreater((folder / "results" / "palm_to_ball.png").stat().st_size, 10_000)


class TestRelease(unittest.TestCase):
    """A wheel built from the repository carries the models and scenarios, and its main job runs
    from any directory with nothing of the repository around it."""

    @classmethod
    def setUpClass(cls):
        cls.temporary = tempfile.TemporaryDirectory()
        cls.addClassCleanup(cls.temporary.cleanup)
        folder = pathlib.Path(cls.temporary.name)
        subprocess.run(
            [sys.executable, "-m", "pip", "wheel", "--no-deps", "-q",
             "-w", str(folder / "dist"), str(ROOT)],
            check=True,
        )  # fmt: skip
        (cls.wheel,) = (folder / "dist").glob("mobee_drake-*.whl")
        cls.site = folder / "site"
        subprocess.run(
            [sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target",
             str(cls.site), str(cls.wheel)],
            check=True,
        )  # fmt: skip
        cls.folder = folder

    def test_the_wheel_ships_models_scenarios_and_license(self):
        names = set(zipfile.ZipFile(self.wheel).namelist())
        for shipped in (
            "mobee_drake/models/package.xml",
            "mobee_drake/models/icub_overlay.yaml",
            "mobee_drake/models/katana.xml",
            "mobee_drake/models/reach_targets.yaml",
            "mobee_drake/diagrams/reach_around_ball.yaml",
            "mobee_drake/station/builder.py",
        ):
            self.assertIn(shipped, names)
        self.assertTrue(any(name.endswith("LICENSE") for name in names))

    def _RunInstalled(self, *args: str) -> subprocess.CompletedProcess:
        elsewhere = self.folder / "elsewhere"
        elsewhere.mkdir(exist_ok=True)
        return subprocess.run(
            [sys.executable, "-m", "mobee_drake.cli", *args],
            cwd=elsewhere,
            env={**os.environ, "PYTHONPATH": str(self.site)},
            capture_output=True,
            text=True,
            timeout=300,
        )

    def test_the_installed_main_job_runs_from_another_directory(self):
        where = self._RunInstalled("--version")
        self.assertEqual(where.returncode, 0, where.stderr)
        self.assertRegex(where.stdout, r"^mobee-drake \d+\.\d+\.\d+")
        run = self._RunInstalled("run", "reach_around_ball", "--duration", "0.2", "--no-meshcat")
        self.assertEqual(run.returncode, 0, run.stderr)
        self.assertIn("simulated 0.20 s", run.stdout)
        # The package imported is the installed copy, not the repository's.
        probe = subprocess.run(
            [sys.executable, "-c", "import mobee_drake; print(mobee_drake.__file__)"],
            cwd=self.folder,
            env={"PYTHONPATH": str(self.site)},
            capture_output=True,
            text=True,
            check=True,
        )
        self.assertTrue(probe.stdout.startswith(str(self.site)), probe.stdout)


if __name__ == "__main__":
    unittest.main()
