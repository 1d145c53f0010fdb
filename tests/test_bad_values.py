"""Every bad value is caught where it enters, as our error naming where it came from: generated
scenario overrides (hypothesis), damaged checkpoints, and the fixed regressions of issue 18."""

import math
import pathlib
import shutil
import tempfile
import unittest
import zipfile

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
import numpy as np

from mobee_drake.atomic_files import CurrentGeneration
from mobee_drake.scenario import (
    BuildScenario,
    LoadScenario,
    ResumableConfiguration,
    RunScenario,
    ScenarioErrors,
)
from mobee_drake.station.checkpoint import CheckpointError, LoadCheckpoint
from mobee_drake.yaml_io import YamlFileError


def _Yaml(value) -> str:
    """A value as YAML text (floats as YAML writes them: .nan, .inf, -.inf)."""
    if isinstance(value, float) and math.isnan(value):
        return ".nan"
    if isinstance(value, float) and math.isinf(value):
        return ".inf" if value > 0 else "-.inf"
    if isinstance(value, str):
        return repr(value)
    if isinstance(value, list):
        return "[" + ", ".join(_Yaml(v) for v in value) + "]"
    return repr(value)


NUMBERS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(10**6), max_value=10**6),
    st.sampled_from([0, -1, 1e-9, 1e6, 1e308]),
)
ANY = st.one_of(NUMBERS, st.text(max_size=5), st.lists(NUMBERS, max_size=4))
# Where a value enters a scenario: a template of YAML with one hole.
PLACES = [
    "{{time_step: {}}}",
    "{{duration: {}}}",
    "{{random_seed: {}}}",
    "{{objects: [{{name: a, shape: !Sphere {{radius: {}}}}}]}}",
    "{{objects: [{{name: a, shape: !Box {{size: {}}}}}]}}",
    "{{objects: [{{name: a, shape: !Cylinder {{radius: 0.1, length: {}}}}}]}}",
    "{{objects: [{{name: a, position: {}}}]}}",
    "{{objects: [{{name: a, role: {}}}]}}",
    "{{mover: !Dynamic {{control: {}}}}}",
    "{{mover: !Dynamic {{plant_config: {{time_step: {}}}}}}}",
    "{{mover: !Reflex {{speed_deg: {}}}}}",
    "{{attractor: !RandomAttractors {{period: {}}}}}",
    "{{attractor: !RandomAttractors {{range_fraction: {}}}}}",
    "{{attractor: !ExploreAttractor {{agents: [{{name: a, joints: [r_elbow], levels: {}}}]}}}}",
    "{{attractor: !ExploreAttractor {{agents: [{{name: a, joints: [r_elbow], nearest: {}}}]}}}}",
    "{{attractor: !ExploreAttractor {{agents: [{{joints: [r_elbow]}}], timing: {{timeout: {}}}}}}}",
    "{{attractor: !StateActionAttractor {{forcing: {{force: {}}}}}}}",
    "{{world_events: [{{time: {}, object: ball, role: ghost}}]}}",
]


class TestGeneratedOverrides(unittest.TestCase):
    @settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(place=st.sampled_from(PLACES), value=ANY)
    def test_a_value_is_accepted_valid_or_refused_by_our_error(self, place, value):
        text = place.format(_Yaml(value))
        try:
            scenario = LoadScenario("reach_around_ball", text)
        except YamlFileError as error:
            self.assertRegex(str(error), r"^(overrides '|\S+\.yaml)")  # Names where it entered.
            return
        self.assertEqual(ScenarioErrors(scenario), [])
        self.assertTrue(math.isfinite(scenario.duration) and 0 < scenario.time_step <= 0.1)

    @settings(max_examples=25, deadline=None)
    @given(place=st.sampled_from(PLACES), value=NUMBERS)
    def test_what_loads_builds_or_is_refused_clearly(self, place, value):
        try:
            scenario = LoadScenario("reach_around_ball", place.format(_Yaml(value)))
        except YamlFileError:
            return
        try:
            BuildScenario(scenario)
        except ValueError as error:  # Unknown joints, objects and the like, named.
            self.assertTrue(str(error))


class TestFixedRegressions(unittest.TestCase):
    """The bad values that issue 18 found accepted or crashing."""

    CASES = {
        "{time_step: .inf}": "time_step must be",
        "{time_step: 1e6}": "time_step must be",
        "{duration: 0}": "duration must be",
        "{duration: .inf}": "duration must be",
        "{duration: 1e308}": "duration must be",
        "{duration: -1}": "duration must be",
        "{duration: .nan}": "duration must be",
        "{duration: [": "invalid YAML",
        "{objects: [{name: a, shape: !Sphere {radius: -0.1}}]}": "sizes must be finite and > 0",
        "{attractor: !ExploreAttractor {agents: [{name: a, joints: [r_elbow], nearest: -3}]}}": (
            "nearest must be >= 0"
        ),
        "{attractor: !ExploreAttractor {agents: [{name: a, joints: [r_elbow], levels: []}]}}": (
            "levels must be"
        ),
        "{attractor: !ExploreAttractor {agents: [{name: a, joints: []}]}}": "needs joints",
        "{attractor: !ExploreAttractor {agents: [{name: a, joints: [r_elbow]}, "
        "{name: a, joints: [l_elbow]}]}}": "unique",
        # Issue 31, item 6: explorer settings that would run a meaningless experiment.
        "{attractor: !ExploreAttractor {agents: [{name: a, joints: [r_elbow], levels: [0.5]}]}}": (
            "levels need at least two different values"
        ),
        "{attractor: !ExploreAttractor {agents: [{name: a, joints: [r_elbow], "
        "levels: [0.5, 0.5]}]}}": "levels need at least two different values",
        "{attractor: !ExploreAttractor {agents: [{name: a, joints: [r_elbow], nearest: 1000}]}}": (
            "nearest must be >= 0 and less than the 2 states"
        ),
        "{attractor: !ExploreAttractor {agents: [{name: a, joints: [r_elbow], "
        "explorer: {delta: -1}}]}}": "explorer delta must be > 0",
        "{attractor: !ExploreAttractor {agents: [{name: a, joints: [r_elbow], "
        "explorer: {delta: .nan}}]}}": "explorer delta must be > 0",
        "{attractor: !ExploreAttractor {agents: [{name: a, joints: [r_elbow], "
        "explorer: {strategy: bold}}]}}": "explorer strategy must be one of",
        # Issue 31, item 8: tracebacks.
        "{robot: {controlled_joints: []}}": "controlled_joints must name at least one joint",
        "{mover: !Dynamic {plant_config: {contact_model: bogus}}}": (
            "plant_config: Unknown contact_model: 'bogus'"
        ),
        "{mover: !Dynamic {plant_config: {discrete_contact_approximation: bogus}}}": (
            "plant_config: Unknown discrete_contact_approximation"
        ),
        "{simulator_config: {integration_scheme: bogus}}": (
            "simulator_config: Unknown integration scheme: bogus"
        ),
        # Issue 31, item 11: silent nonsense.
        "{duration: 1, duration: 2}": "key 'duration' given twice",
        "{mobee: {damping: 30, damping: 40}}": "key 'damping' given twice",
        "{objects: [{name: a, shape: !Sphere {radius: 0.1}, position: [1e300, 0, 0]}]}": (
            "position must lie within 1000 m"
        ),
        "{simulator_config: {max_step_size: -1}}": "max_step_size must be finite and > 0",
        "{simulator_config: {accuracy: .nan}}": "accuracy must be finite and > 0",
        # Issue 31, item 9: no run that would go for days without a line.
        "{time_step: 1e-9}": "time_step must be >= 0.0001",
        "{mover: !Dynamic {plant_config: {time_step: 1e-9}}}": "plant_config time_step must be",
        "{simulator_config: {target_realtime_rate: 1e-6}}": "target_realtime_rate must be 0",
        "{simulator_config: {target_realtime_rate: -1}}": "target_realtime_rate must be 0",
        # Issue 31, item 3: a name is a file name in checkpoints, never a path.
        "{attractor: !ExploreAttractor {agents: [{name: ../../x, joints: [r_elbow]}]}}": (
            "exploring agent name '../../x': use letters"
        ),
        "{attractor: !ExploreAttractor {agents: [{name: a/b, joints: [r_elbow]}]}}": (
            "exploring agent name 'a/b'"
        ),
    }

    def test_each_ends_in_our_error_naming_the_override(self):
        for text, message in self.CASES.items():
            with self.subTest(text):
                with self.assertRaisesRegex(YamlFileError, rf"^overrides '.*{message}"):
                    LoadScenario("reach_around_ball", text)

    def test_too_many_objects_are_refused_at_load(self):
        """Issue 31, item 5: 10,000 objects built for minutes and ended in a MemoryError."""
        objects = ", ".join(
            f"{{name: b{i}, shape: !Sphere {{radius: 0.01}}, position: [-2, 0, {i * 0.03}]}}"
            for i in range(2001)
        )
        with self.assertRaisesRegex(YamlFileError, r"objects: at most 2000 .*got 2001"):
            LoadScenario("reach_around_ball", f"{{objects: [{objects}]}}")

    def test_bad_files(self):
        folder = pathlib.Path(tempfile.mkdtemp())
        self.addCleanup(shutil.rmtree, folder)
        for name, content, message in (
            ("binary.yaml", b"\x00\x01\x02", "not a text file"),
            ("latin.yaml", b"\xff\xfe duration: 3", "not a text file"),
            ("empty.yaml", b"", "empty"),
        ):
            (folder / name).write_bytes(content)
            with self.assertRaisesRegex(YamlFileError, rf"{name}: {message}"):
                LoadScenario(folder / name)


class TestDamagedCheckpoints(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.folder = pathlib.Path(tempfile.mkdtemp())
        cls.scenario = LoadScenario("explore_hypercube", "{duration: 3}")
        RunScenario(cls.scenario, checkpoint=str(cls.folder / "run"))

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.folder)

    def _Damaged(self, damage) -> pathlib.Path:
        copy = self.folder / f"copy{len(list(self.folder.iterdir()))}"
        shutil.copytree(self.folder / "run", copy)
        damage(CurrentGeneration(copy))
        return copy

    def _Load(self, folder: pathlib.Path) -> None:
        station = BuildScenario(self.scenario)
        LoadCheckpoint(
            station,
            station.diagram.CreateDefaultContext(),
            folder,
            ResumableConfiguration(self.scenario),
        )

    def test_each_damage_is_named(self):
        def Truncate(generation):
            data = (generation / "simulation.npz").read_bytes()
            (generation / "simulation.npz").write_bytes(data[: len(data) // 2])

        def DamagedStream(generation):
            """The start of the model's first array's deflate stream overwritten."""
            path = generation / "right_arm.npz"
            data = bytearray(path.read_bytes())
            with zipfile.ZipFile(path) as saved:
                offset = saved.infolist()[0].header_offset
            name, extra = (int.from_bytes(data[offset + k : offset + k + 2], "little")
                           for k in (26, 28))  # fmt: skip
            start = offset + 30 + name + extra
            data[start : start + 16] = b"\xff" * 16
            path.write_bytes(data)

        def Nan(generation):
            saved = dict(np.load(generation / "simulation.npz"))
            saved["time"] = np.array(np.nan)
            np.savez(generation / "simulation.npz", **saved)

        def NanModel(generation):
            saved = dict(np.load(generation / "right_arm.npz"))
            key = next(k for k, v in saved.items() if np.issubdtype(v.dtype, np.floating))
            saved[key] = np.full_like(saved[key], np.nan)
            np.savez(generation / "right_arm.npz", **saved)

        def NegativeTime(generation):
            saved = dict(np.load(generation / "simulation.npz"))
            saved["time"] = np.array(-5.0)
            np.savez(generation / "simulation.npz", **saved)

        cases = {
            "truncated": (Truncate, "damaged checkpoint"),
            "damaged stream": (DamagedStream, "damaged checkpoint \\(zlib.error: "),
            "nan": (Nan, "'time' holds NaN"),
            "no world": (lambda g: (g / "world.json").unlink(), "damaged checkpoint"),
            "broken json": (
                lambda g: (g / "right_arm.json").write_text("{"),
                "damaged checkpoint",
            ),
            "no model": (lambda g: (g / "right_arm.npz").unlink(), "damaged checkpoint"),
            # Issue 31, item 10: each damage with its own message.
            "nan in a model": (NanModel, "right_arm.npz: '.*' holds NaN"),
            "negative time": (NegativeTime, "holds the time -5.0 s, not >= 0"),
            "no configuration": (
                lambda g: (g / "configuration.yaml").unlink(),
                "damaged checkpoint \\(no configuration.yaml\\)",
            ),
        }
        for name, (damage, message) in cases.items():
            with self.subTest(name):
                folder = self._Damaged(damage)
                with self.assertRaisesRegex(CheckpointError, rf"^{folder}.*{message}"):
                    self._Load(folder)


if __name__ == "__main__":
    unittest.main()
