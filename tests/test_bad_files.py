"""Malformed robot files (MoBeE's XML), overlays and scenario files (YAML): each ends in one line
naming the file, the line and the element, or loads correctly where the file is valid (issue 5,
part 4). Every case reads a small file: the whole set runs in a second or two."""

import pathlib
import tempfile
import time
import unittest

from mobee_drake.robots.overlay import LoadOverlay
from mobee_drake.robots.zero_position import (
    MAX_DEPTH,
    LoadZeroPositionTree,
    ZeroPositionConfig,
    ZeroPositionError,
)
from mobee_drake.scenario import LoadScenario
from mobee_drake.yaml_io import MAX_YAML_DEPTH, YamlFileError

MODELS = pathlib.Path(__file__).resolve().parents[1] / "models"
HEADER = '<?xml version="1.0"?>\n<ZeroPositionKinematicTree version="1.0" robotName="r">\n'

# (s) What a refused file may take: a guard against a hang (an alias bomb walked for hours), not
# a speed test (speed belongs in benchmarks).
HANG_GUARD = 10.0


def _Tree(body: str) -> str:
    """A file whose ``body`` starts on line 4, inside the bodypart 'arm'."""
    return f'{HEADER}<bodypart name="arm">\n{body}\n</bodypart>\n</ZeroPositionKinematicTree>\n'


def _Joint(attributes: str = "", inside: str = "") -> str:
    return (
        f'<motor minPos="0" maxPos="10"><joint z="1" minPos="0" maxPos="10" {attributes}>'
        f"{inside}</joint></motor>"
    )


def _Write(data: str | bytes, name: str = "robot.xml") -> pathlib.Path:
    path = pathlib.Path(tempfile.mkdtemp()) / name
    path.write_bytes(data.encode() if isinstance(data, str) else data)
    return path


def _Bomb(levels: int = 8, key: str = "exclude") -> str:
    """A 'billion laughs' YAML: each level's list repeats the previous one nine times."""
    lines = ['_l0: &l0 ["x", "x", "x", "x", "x", "x", "x", "x", "x"]']
    for i in range(1, levels):
        lines.append(f"_l{i}: &l{i} [" + ", ".join([f"*l{i - 1}"] * 9) + "]")
    lines.append(f"{key}: [" + ", ".join([f"*l{levels - 1}"] * 9) + "]")
    return "\n".join(lines) + "\n"


class TestMalformedRobotFiles(unittest.TestCase):
    """Each malformed file of the issue's 84 that was accepted, crashed or failed inside Drake."""

    def _Fails(self, data: str | bytes, pattern: str) -> str:
        path = _Write(data)
        with self.assertRaises(ZeroPositionError) as caught:
            LoadZeroPositionTree(path)
        message = str(caught.exception)
        self.assertRegex(message, pattern)
        self.assertTrue(message.startswith(f"{path}:"), message)  # file and line first
        self.assertNotIn("\n", message)
        return message

    def test_numbers_python_would_accept(self):
        # Qt's toDouble (the original's) reads none of these; Python's float reads most.
        for text in ("1 0", "0_19", "nan", "-inf", "infinity", "0x10", "\u0661", "1,5", "1e"):
            with self.subTest(text=text):
                self._Fails(
                    _Tree(f'<link z="{text}"/>'), r"robot\.xml:4: <link>: z=\".*\" is not a number"
                )
        self._Fails(_Tree('<link z="1&#10;0"/>'), r'z="1\\n0" is not a number')  # one line

    def test_huge_numbers(self):
        self._Fails(
            _Tree(_Joint().replace('joint z="1"', 'joint z="1e308"')),
            r'robot\.xml:4: <joint>: z="1e308" is out of range: .* at most 1e\+06 m',
        )
        for limits in ('minPos="-1e308" maxPos="10"', 'minPos="0" maxPos="1e308"'):
            with self.subTest(limits=limits):
                joint = f'<motor minPos="0" maxPos="10"><joint z="1" {limits}/></motor>'
                self._Fails(
                    _Tree(joint), r'robot\.xml:4: <joint>: \w+Pos=".*" is out of range: .* deg'
                )
        self._Fails(_Tree('<link z="1e400"/>'), r'z="1e400" is out of range')
        self._Fails(_Tree('<link z="1e-12"/>'), r"<link>: its vector .* shorter than 1e-09 m")
        self._Fails(
            _Tree('<link z="1"><box width="1" height="1" depth="1" hx="1e-300"/></link>'),
            r"<box>: its axis \(hx, hy, hz\) is shorter",
        )

    def test_elements_where_they_do_not_belong(self):
        constraint = (
            '<constraintList>\n<constraint a="1" q="0" b="1">{}</constraint>\n</constraintList>'
        )
        self._Fails(
            _Tree(_Joint() + constraint.format("<foo/>")), r"robot\.xml:5: <foo>: unknown element"
        )
        self._Fails(
            _Tree(_Joint() + constraint.format('<link z="1"/>')),
            r"robot\.xml:5: <link>: cannot sit inside <constraint>, which holds nothing",
        )
        self._Fails(
            _Tree('<link z="1">\n<box width="1" height="1" depth="1">\n<link z="1"/></box></link>'),
            r"robot\.xml:6: <link>: cannot sit inside <box>",
        )
        self._Fails(
            _Tree('<link z="1"><marker name="m"><sphere radius="1"/></marker></link>'),
            "inside <marker>",
        )
        self._Fails(_Tree('<bodypart name="b"/>'), r"<bodypart>: cannot sit inside <bodypart>")
        self._Fails(
            _Tree('<box width="1" height="1" depth="1"/>'),
            r"robot\.xml:4: <box>: <box> must sit inside a <link> or <joint>",
        )
        self._Fails(_Tree('<marker name="m"/>'), r"<marker>: <marker> must sit inside")
        self._Fails(_Tree('<link z="1">hello</link>'), r'robot\.xml:4: <link>: text "hello"')
        self._Fails("<robot/>", r"robot\.xml:1: <robot>: unknown element")
        self._Fails("<link/>", r"<link>: the root element must be <ZeroPositionKinematicTree>")

    def test_names(self):
        for name, why in (
            ("a&lt;b", "is not a name"),
            ("a&quot;b", "is not a name"),
            ("a::b", "is not a name"),
            ("", "is not a name"),
            ("caf\u00e9", "is not a name"),
            ("world", "is reserved"),
            ("__model__", "is reserved"),
            ("base", "is a body's name"),
            ("a_welds_to_b", "Drake's welds"),
        ):
            with self.subTest(name=name):
                self._Fails(_Tree(_Joint(f'name="{name}"')), rf"robot\.xml:4: <joint>: .*{why}")
        # A given name that collides with a generated one: arm_1 is the second unnamed joint's.
        nested = _Joint('name="arm_1"', _Joint())
        self._Fails(_Tree(nested), r"a second joint named 'arm_1' \(a joint without a name")
        # A joint named like another joint's body, in either order.
        self._Fails(_Tree(_Joint("", _Joint('name="arm_0_link"'))), "'arm_0_link' is a body's name")
        self._Fails(
            _Tree(_Joint('name="j_link"', _Joint('name="j"'))),
            "this joint's body 'j_link' would have a joint's name",
        )
        self._Fails(_Tree(_Joint('name="a b"')), r"the joint's name 'a b' is not a name")
        self._Fails(
            _Tree("").replace('name="arm"', 'name="a::b"'), "<bodypart>: the bodypart's name"
        )
        self._Fails(
            HEADER.replace('robotName="r"', 'robotName="my robot"')
            + "</ZeroPositionKinematicTree>",
            "the robot's name",
        )
        self._Fails(_Tree('<link z="1"><marker name="a/b"/></link>'), "the marker's name 'a/b'")
        self._Fails(
            _Tree('<link z="1"><marker name="m"/>\n<marker name="m"/></link>'),
            r"robot\.xml:5: <marker>: every marker needs a unique name, got 'm'",
        )

    def test_encodings(self):
        latin1 = _Tree("<!-- caf\u00e9 -->").encode("latin-1")
        self._Fails(latin1, r"robot\.xml:4: malformed XML: not UTF-8 \(declare the file's encoding")
        self._Fails(b"\x00\x01\x02\xff", r"robot\.xml:1: malformed XML")
        self._Fails(b"", r"robot\.xml:1: malformed XML: no element found")
        self._Fails(b'<?xml version="1.0" encoding="no-such"?><a/>', "unknown encoding")
        # A valid ISO-8859-1 file that says so loads.
        declared = latin1.replace(
            b'<?xml version="1.0"?>', b'<?xml version="1.0" encoding="ISO-8859-1"?>'
        )
        robot = LoadZeroPositionTree(_Write(declared.replace(b"-->", b'--><link z="1"/>')))
        self.assertEqual(robot.name, "r")

    def test_entities_and_nesting(self):
        self._Fails(
            '<?xml version="1.0"?>\n<!DOCTYPE z [<!ENTITY lol "lol">]>\n'
            "<ZeroPositionKinematicTree/>",
            r"robot\.xml:2: entity declarations are not allowed",
        )
        self._Fails(_Tree("&lol;"), r"robot\.xml:4: malformed XML: undefined entity")
        # Three levels are the root, the bodypart and the first link.
        deepest = MAX_DEPTH - 2
        robot = LoadZeroPositionTree(_Write(_Tree('<link z="1">' * deepest + "</link>" * deepest)))
        self.assertEqual(robot.joints, ())
        started = time.perf_counter()
        self._Fails(
            _Tree('<link z="1">' * 1000 + "</link>" * 1000),
            rf"robot\.xml:4: <link>: elements nested deeper than {MAX_DEPTH}",
        )
        self.assertLess(time.perf_counter() - started, HANG_GUARD)

    def test_version_and_length(self):
        self._Fails(
            _Tree("").replace('version="1.0"', 'version="2.0"'),
            r'robot\.xml:2: <ZeroPositionKinematicTree>: version="2.0" is not supported',
        )
        LoadZeroPositionTree(_Write(_Tree("").replace('version="1.0" ', "")))  # absent: 1.0
        self._Fails(_Tree('<link z="1" length="-1"/>'), r"<link>: length must be >= 0")

    def test_many_markers_load_in_linear_time(self):
        markers = "".join(f'<marker name="m{i}"/>' for i in range(20000))
        started = time.perf_counter()
        robot = LoadZeroPositionTree(_Write(_Tree(f'<link z="1">{markers}</link>')))
        self.assertEqual(len(robot.overlay.markers), 20000)
        self.assertLess(time.perf_counter() - started, HANG_GUARD)  # 31 s when it was quadratic

    def test_a_robot_without_a_joint_to_control(self):
        path = _Write(_Tree('<link z="1" radius="0.1"/>'))
        robot = LoadZeroPositionTree(path)  # a valid file, but nothing for MoBeE to move
        with self.assertRaisesRegex(
            ZeroPositionError, f"{path}: no joint for MoBeE to control: the robot has no joints"
        ):
            ZeroPositionConfig(file=str(path)).Joints(robot)

    def test_two_primitives_on_one_line_load(self):
        robot = LoadZeroPositionTree(
            _Write(_Tree('<link z="1"><sphere radius="1"/><sphere radius="2"/></link>'))
        )
        self.assertEqual(
            [p.name for p in robot.overlay.primitives], ["sphere_line4", "sphere_line4_2"]
        )


GOOD_OVERLAY = (MODELS / "three_link_arm_overlay.yaml").read_text()


class TestMalformedOverlays(unittest.TestCase):
    def _Fails(self, text: str | bytes, pattern: str, name: str = "overlay.yaml"):
        path = _Write(text, name)
        started = time.perf_counter()
        with self.assertRaises(ValueError) as caught:
            LoadOverlay(path)
        self.assertLess(time.perf_counter() - started, HANG_GUARD)
        message = str(caught.exception)
        self.assertRegex(message, pattern)
        self.assertTrue(message.startswith(f"{path}"), message)
        self.assertNotIn("\n", message)

    def test_non_finite_and_huge_numbers(self):
        line = (
            GOOD_OVERLAY.splitlines().index(
                next(t for t in GOOD_OVERLAY.splitlines() if "name: link2" in t)
            )
            + 1
        )
        for value, why in ((".nan", "three finite numbers"), ("1e308", r"within \+-1e\+06")):
            with self.subTest(value=value):
                self._Fails(
                    GOOD_OVERLAY.replace("end: [0.6, 0, 0]", f"end: [{value}, 0, 0]"),
                    rf"overlay\.yaml:{line}: 'link2': end must be {why}",
                )
        self._Fails(
            GOOD_OVERLAY.replace(
                "end: [0.6, 0, 0], radius: 0.03", "end: [0.6, 0, 0], radius: 1e300"
            ),
            r"'link2': radius must be <= 1e\+06, got 1e\+300",
        )
        self._Fails(
            GOOD_OVERLAY.replace("position: [0.9, 0, 0]", "position: [0.9, -.inf, 0]"),
            r"'tip': position must be three finite numbers",
        )
        self._Fails(
            GOOD_OVERLAY.replace(
                "direction: [1, 0, 0]}\n  - {name: elbow",
                "direction: [1e300, 1e300, 0]}\n  - {name: elbow",
            ),
            r"'tip': direction must be within",
        )
        self._Fails(
            GOOD_OVERLAY.replace("joint3: -1.0}, offset: 150.0", "joint3: .inf}, offset: 150.0"),
            r"overlay\.yaml:\d+: 'fold': a literal needs finite",
        )
        self._Fails(
            GOOD_OVERLAY.replace("offset: 150.0", "offset: 1e20"),
            r"'fold': offset must be finite and within",
        )
        self._Fails(
            GOOD_OVERLAY.replace("default_field: 0.05", "default_field: .inf"),
            "default_field must be >= 0",
        )

    def test_names(self):
        self._Fails(GOOD_OVERLAY.replace("name: link2", "name: 'a::b'"), r"'a::b' is not a name")
        self._Fails(GOOD_OVERLAY.replace("name: tip", "name: world"), r"'world' is reserved")

    def test_empty_binary_and_non_utf8_files(self):
        self._Fails("", r"overlay\.yaml: empty")
        self._Fails("# nothing\n", r"overlay\.yaml: empty")
        self._Fails(b"\x00\x01\x02", r"overlay\.yaml: not a text file")
        self._Fails(
            "default_field: 0.05 # caf\u00e9\n".encode("latin-1"), r"not a text file \(not UTF-8\)"
        )

    def test_alias_bombs_and_deep_nesting_are_refused_quickly(self):
        self._Fails(_Bomb(), r"overlay\.yaml:\d+: aliases repeat more than 10000 nodes")
        self._Fails(
            "exclude: " + "[" * 5000 + "]" * 5000 + "\n",
            rf"overlay\.yaml:1: nested deeper than {MAX_YAML_DEPTH} levels",
        )
        # Anchors and aliases that repeat a little still work (Drake's documented use).
        text = GOOD_OVERLAY.replace(
            "direction: [1, 0, 0]}\n  - {name: elbow", "direction: &x [1, 0, 0]}\n  - {name: elbow"
        )
        text = text.replace(
            "position: [0.3, 0, 0], direction: [1, 0, 0]", "position: [0.3, 0, 0], direction: *x"
        )
        self.assertIn("*x", text)
        self.assertEqual(LoadOverlay(_Write(text, "overlay.yaml")).markers[1].direction, [1, 0, 0])


class TestMalformedScenarioFiles(unittest.TestCase):
    def _Fails(self, text: str | bytes, pattern: str):
        path = _Write(text, "scenario.yaml")
        started = time.perf_counter()
        with self.assertRaisesRegex(YamlFileError, pattern):
            LoadScenario(path)
        self.assertLess(time.perf_counter() - started, HANG_GUARD)

    def test_alias_bombs_deep_nesting_and_bad_files(self):
        self._Fails(_Bomb(key="objects"), r"scenario\.yaml:\d+: aliases repeat more than")
        self._Fails("duration: " + "[" * 3000 + "]" * 3000, r"scenario\.yaml:1: nested deeper")
        self._Fails("", r"scenario\.yaml: empty")
        self._Fails(b"\xff\xfe duration: 3", r"scenario\.yaml: not a text file")
        self._Fails("duration: .nan\n", r"scenario\.yaml")
        self._Fails("duration: 1e308\n", r"scenario\.yaml")

    def test_an_alias_bomb_in_overrides(self):
        """``--set`` texts are checked as files are, and quoted on one line."""
        started = time.perf_counter()
        with self.assertRaisesRegex(YamlFileError, r"^overrides '_l0: [^\n]*':\d+: aliases repeat"):
            LoadScenario("reach_around_ball", _Bomb(key="objects"))
        self.assertLess(time.perf_counter() - started, HANG_GUARD)


if __name__ == "__main__":
    unittest.main()
