"""The package's architecture: no import cycles, no imports hidden in functions, one plotting
backend, and a release that ships what a run needs."""

import ast
import pathlib
import re
import tempfile
import unittest
import zipfile

import grimp
from installed_wheel import CodeBlocks, InstalledWheel, RunCommandLine, RunPython

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
        (code,) = [c for kind, c in CodeBlocks(text) if kind == "python" and containing in c]
        return code

    def test_the_client_example_runs(self):
        """In an empty folder, with the wheel installed (as every README example below)."""
        printed = RunPython(self._Example("class BendElbow"), pathlib.Path(tempfile.mkdtemp()))
        self.assertIn("[", printed)  # the robot's state

    def test_the_behaviour_example_runs(self):
        """The head shakes (neck_yaw follows 30 deg sin(t), behind it as a spring does) while
        the palm behaviour turns the wrist."""
        printed = RunPython(self._Example("class ShakeHead"), pathlib.Path(tempfile.mkdtemp()))
        yaw = float(re.search(r"neck_yaw (-?[0-9.]+) deg", printed).group(1))
        self.assertGreater(abs(yaw), 1.0)
        self.assertLess(abs(yaw), 30.0)

    def test_the_data_log_example_plots_the_main_job(self):
        folder = pathlib.Path(tempfile.mkdtemp())
        RunCommandLine("mobee-drake run reach_around_ball --no-record", folder)
        RunPython(self._Example("read_parquet"), folder)
        self.assertGreater((folder / "results" / "palm_to_ball.png").stat().st_size, 10_000)


class TestRelease(unittest.TestCase):
    """A wheel built from the repository carries the models and scenarios, and its main job runs
    from any directory with nothing of the repository around it."""

    @classmethod
    def setUpClass(cls):
        cls.wheel, cls.site = InstalledWheel()
        cls.folder = pathlib.Path(tempfile.mkdtemp())

    def test_the_wheel_ships_models_scenarios_and_license(self):
        names = set(zipfile.ZipFile(self.wheel).namelist())
        for shipped in (
            "mobee_drake/models/package.xml",
            "mobee_drake/models/icub_overlay.yaml",
            "mobee_drake/models/katana.xml",
            "mobee_drake/models/reach_targets.yaml",
            "mobee_drake/models/three_link_arm.urdf",
            "mobee_drake/models/three_link_arm_overlay.yaml",
            "mobee_drake/models/pillar.obj",
            "mobee_drake/diagrams/reach_around_ball.yaml",
            "mobee_drake/diagrams/three_link_arm.yaml",
            "mobee_drake/station/builder.py",
        ):
            self.assertIn(shipped, names)
        self.assertTrue(any(name.endswith("LICENSE") for name in names))

    def test_the_installed_main_job_runs_from_another_directory(self):
        self.assertRegex(
            RunCommandLine("mobee-drake --version", self.folder), r"^mobee-drake \d+\.\d+\.\d+"
        )
        run = RunCommandLine(
            "mobee-drake run reach_around_ball --duration 0.2 --no-meshcat", self.folder
        )
        self.assertIn("simulated 0.20 s", run)
        # The package imported is the installed copy, not the repository's.
        probe = RunPython("import mobee_drake; print(mobee_drake.__file__)", self.folder)
        self.assertTrue(probe.startswith(str(self.site)), probe)


if __name__ == "__main__":
    unittest.main()
