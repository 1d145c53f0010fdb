"""Every figure the experiments draw reads alone: on small synthetic results, each axes of each
figure has x and y labels, a title, and a legend or a colour bar, and every colour of its bars
and spans is named in its legend."""

import pathlib
import tempfile
import types
import unittest

from matplotlib.colors import to_rgba
from matplotlib.text import Text
import numpy as np

from mobee_drake.experiments import (
    bench_forces,
    ch7_figures,
    ch8_figures,
    saggriac,
    saggriac_figures,
    trm_roadmaps,
)
from mobee_drake.experiments.ch7_model_learning import MovingBoxResult, PlanningRun
from mobee_drake.experiments.ch8_reaching import ReachRun
from mobee_drake.experiments.exploration import ExplorationRun
from mobee_drake.experiments.plots import SaveFigure, plt
from mobee_drake.planning.state_space import Lattice
from mobee_drake.reaching.learner import LOG_COLUMNS

RNG = np.random.default_rng(0)


def _IsColorbar(axis) -> bool:
    return getattr(axis, "_colorbar", None) is not None


def _HasColorbar(axis) -> bool:
    return any(m.colorbar is not None for m in [*axis.images, *axis.collections])


def _ExplorationRun(**fields) -> ExplorationRun:
    """A constructed exploration run: empty but for ``fields``."""
    defaults = dict(
        agents=[], tries=[], values=[], misses=[], goals=[], actions=[], snapshots={},
        coverage=[], simulated_seconds=0.0, wall_seconds=0.0, penetrating_steps=0,
    )  # fmt: skip
    return ExplorationRun(**(defaults | fields))


def _BabblingRun(spec, **fields) -> saggriac.BabblingRun:
    """A constructed SAGG-RIAC run: empty but for ``fields``."""
    defaults = dict(
        config={}, wall_time_s=1.0, time_steps=0, curve=[], final_reaching_errors=[],
        diagnostics={}, tip_sample=[],
    )  # fmt: skip
    return saggriac.BabblingRun(spec=spec, **(defaults | fields))


def _LegendColours(legend) -> set:
    colours = set()
    for handle in legend.legend_handles:
        colour = handle.get_facecolor() if hasattr(handle, "get_facecolor") else None
        colours.add(to_rgba(colour if colour is not None else handle.get_color()))
    return colours


def PlottedValues(figure) -> np.ndarray:
    """Every number a figure draws: its lines' and scatters' coordinates, its bars' extents and
    its images' pixels (what a figure that plots the wrong data would not contain)."""
    values = []
    for axis in figure.axes:
        for line in axis.lines:
            data = line.get_data_3d() if hasattr(line, "get_data_3d") else line.get_data()
            values += [np.ravel(np.asarray(d, dtype=float)) for d in data]
        for patch in axis.patches:
            if hasattr(patch, "get_height"):
                values.append([patch.get_x(), patch.get_y(), patch.get_width(), patch.get_height()])
        for collection in axis.collections:
            values.append(np.ravel(collection.get_offsets()))
            if hasattr(collection, "_offsets3d"):
                values += [np.ravel(np.asarray(c, dtype=float)) for c in collection._offsets3d]
            if collection.get_array() is not None:
                values.append(np.ravel(collection.get_array()))
            for path in getattr(collection, "get_segments", lambda: [])():
                values.append(np.ravel(path))
        for image in axis.images:
            values.append(np.ravel(image.get_array()))
    return np.concatenate([np.ravel(np.asarray(v, dtype=float)) for v in values])


# A series shows when at least this share of the pixels in its colour when it is drawn alone
# keep its colour with the other series drawn.
VISIBLE_SHARE = 0.25


def _Pixels(figure) -> np.ndarray:
    figure.canvas.draw()
    return np.asarray(figure.canvas.buffer_rgba()).copy()


def _PixelsOfColour(figure, lines) -> int:
    """How many pixels of ``figure`` show the colour of ``lines`` (a series shares one)."""
    colour = 255 * np.array(to_rgba(lines[0].get_color())[:3])
    rgb = _Pixels(figure)[..., :3].astype(float)
    return int((np.abs(rgb - colour).max(axis=2) < 30).sum())


class FigureTest(unittest.TestCase):
    def assertDrawsLine(self, figure, x, y, name: str):
        """Some line of ``figure`` is exactly (``x``, ``y``)."""
        lines = [line.get_data() for axis in figure.axes for line in axis.lines]
        self.assertTrue(
            any(np.array_equal(lx, x) and np.array_equal(ly, y) for lx, ly in lines), name
        )

    def assertPlots(self, figure, expected, name: str):
        """Every number of ``expected`` (computed from the synthetic input) is drawn."""
        plotted = PlottedValues(figure)
        for value in np.ravel(expected):
            self.assertTrue(np.isclose(plotted, value, rtol=1e-9, atol=1e-12).any(), (name, value))

    def assertReadable(self, figure, name: str):
        """Checks every axes of ``figure``, then draws and saves it (small)."""
        axes = [axis for axis in figure.axes if not _IsColorbar(axis)]
        self.assertTrue(axes, name)
        for i, axis in enumerate(axes):
            where = f"{name}, axes {i} ({axis.get_title()!r})"
            self.assertTrue(axis.get_xlabel(), where)
            self.assertTrue(axis.get_ylabel(), where)
            self.assertTrue(axis.get_title(), where)
            if hasattr(axis, "get_zlabel"):
                self.assertTrue(axis.get_zlabel(), where)
            legend = axis.get_legend()
            self.assertTrue(legend is not None or _HasColorbar(axis), where)
            if legend is None:
                continue
            self.assertTrue(all(t.get_text() for t in legend.get_texts()), where)
            # Every colour of a bar or a shaded span has a legend entry.
            named = _LegendColours(legend)
            for patch in axis.patches:
                self.assertIn(to_rgba(patch.get_facecolor()), named, where)
            # Every labelled artist (a line, a tick, a bar) is named in the legend.
            legend_texts = {t.get_text() for t in legend.get_texts()}
            for artist in [*axis.lines, *axis.collections, *axis.patches]:
                label = artist.get_label()
                if label and not label.startswith("_"):
                    self.assertIn(label, legend_texts, where)
            self.assertSeriesVisible(axis, where)
        self.assertTextInside(figure, name)
        with tempfile.TemporaryDirectory() as folder:
            SaveFigure(figure, pathlib.Path(folder) / f"{name}.png", dpi=20)

    def assertTextInside(self, figure, name: str):
        """Laid out as saved, everything ``figure`` draws (titles, labels, ticks, legends) lies
        inside its canvas."""
        figure.tight_layout()
        figure.canvas.draw()
        renderer = figure.canvas.get_renderer()
        drawn = figure.get_tightbbox(renderer)  # inches; only what is drawn
        width, height = figure.get_size_inches()
        slack = 1.0 / figure.dpi  # a pixel
        inside = (
            drawn.x0 >= -slack
            and drawn.y0 >= -slack
            and drawn.x1 <= width + slack
            and drawn.y1 <= height + slack
        )
        if not inside:
            boxes = {t.get_text(): t.get_window_extent(renderer) for t in figure.findobj(Text)}
            outside = [
                text
                for text, box in boxes.items()
                if text.strip() and (box.x0 < -1 or box.y0 < -1 or box.x1 > figure.bbox.x1 + 1)
            ]
            self.fail(f"{name}: drawn over {drawn} of a {width} x {height} canvas: {outside}")

    def assertSeriesVisible(self, axis, where: str):
        """Each labelled series of lines in ``axis`` changes the drawn pixels (another series
        does not hide it entirely), unless its label says it overlaps."""
        figure = axis.figure
        series = {}
        for line in axis.lines:
            series.setdefault(line.get_label(), []).append(line)
        # Unlabelled lines continue the labelled series drawn before them (a run per line).
        label = None
        for line in axis.lines:
            if line.get_label().startswith("_"):
                if label is not None:
                    series[label].append(line)
            else:
                label = line.get_label()
        for label, lines in series.items():
            if label.startswith("_") or "overlap" in label:
                continue
            others = [line for line in axis.lines if line not in lines and line.get_visible()]
            shown = _PixelsOfColour(figure, lines)
            for line in others:
                line.set_visible(False)
            alone = _PixelsOfColour(figure, lines)
            for line in others:
                line.set_visible(True)
            self.assertGreater(shown, VISIBLE_SHARE * alone, f"{where}: {label!r} is hidden")


class TestTheChecks(FigureTest):
    """The figure checks catch what they name."""

    def _Figure(self):
        figure, axis = plt.subplots()
        axis.plot([0, 1], [0, 1], label="a")
        axis.set(xlabel="x [m]", ylabel="y [m]", title="t")
        return figure, axis

    def test_text_outside_the_canvas(self):
        figure, axis = self._Figure()
        axis.legend()
        figure.text(1.05, 0.5, "beyond the right edge")
        with self.assertRaisesRegex(AssertionError, "beyond the right edge"):
            self.assertTextInside(figure, "outside")

    def test_a_hidden_series(self):
        figure, axis = self._Figure()
        axis.plot([0, 1], [0, 1], label="b", linewidth=4)  # drawn over "a"
        axis.legend()
        with self.assertRaisesRegex(AssertionError, "'a' is hidden"):
            self.assertSeriesVisible(axis, "hidden")

    def test_an_unnamed_artist(self):
        figure, axis = self._Figure()
        axis.legend()
        axis.hlines([0.5], 0, 1, label="unexplained")
        with self.assertRaisesRegex(AssertionError, "'unexplained' not found"):
            self.assertReadable(figure, "unnamed")


class TestCh7Figures(FigureTest):
    def test_hypercube_and_initializations(self):
        runs = [
            _ExplorationRun(
                labels=dict(gamma=gamma, run=run, initialization=initialization),
                snapshots={320: dict(tries=RNG.integers(4, 7, 16), values=RNG.random(16))},
                tries=[RNG.integers(4, 9, 40)],
                values=[RNG.random(40)],
            )
            for initialization in ("50-50", "60-40")
            for gamma in (0.5, 0.9)
            for run in range(3)
        ]
        self.assertReadable(ch7_figures.HypercubeFigure(runs), "7.1")
        self.assertReadable(ch7_figures.InitializationFigure(runs, "60-40"), "7.2i")

    def test_coverage(self):
        runs = [
            _ExplorationRun(
                labels=dict(strategy=strategy, run=run),
                coverage=[[0, 0], [50, 40 + 3 * k + run], [100, 70]],
            )
            for k, strategy in enumerate(("curious", "random", "least_tried"))
            for run in range(2)
        ]
        figure = ch7_figures.CoverageFigure(runs)
        for run in runs:  # each run's own line
            coverage = np.array(run.coverage)
            self.assertDrawsLine(figure, coverage[:, 0], coverage[:, 1], f"7.2 {run}")
        self.assertReadable(figure, "7.2")
        # Strategies that cover alike: each still shows.
        for run in runs:
            run.coverage = [[0, 0], [50, 40], [100, 70]]
        self.assertReadable(ch7_figures.CoverageFigure(runs), "7.2, coinciding")

    def test_rank_4(self):
        space = Lattice([0.2, 0.8], 4)
        n = space.num_state_actions
        misses = np.zeros(n)
        misses[[1, 2]], misses[[3, 4]] = 0.5, 1.0  # several outcomes; never the goal
        run = _ExplorationRun(
            labels=dict(lattice="20-80"),
            actions=[200],
            tries=[RNG.integers(3, 9, n)],
            misses=[misses],
            values=[RNG.random(n)],
        )
        figure = ch7_figures.Rank4Figure(run, space, np.array([5, 6]))
        self.assertPlots(figure, run.values[0], "7.3")
        self.assertReadable(figure, "7.3")

    def test_moving_box_and_three_agents(self):
        moving = MovingBoxResult(
            unreliable=[3, 9],
            problems=[],
            action_state=[],
            action_goal=[],
            planners=dict(
                moving_box=PlanningRun(reliability=RNG.random(64), plans=[]),
                no_box=PlanningRun(reliability=np.ones(64), plans=[]),
            ),
        )
        figure = ch7_figures.MovingBoxFigure(moving)
        self.assertPlots(figure, moving.planners["moving_box"].reliability, "7.4.1")
        self.assertReadable(figure, "7.4.1")
        agents = _ExplorationRun(
            agents=["right_arm", "left_arm", "torso"],
            tries=[RNG.integers(0, 9, 30) for _ in range(3)],
            actions=[10, 11, 12],
        )
        figure = ch7_figures.ThreeAgentsFigure(agents)
        for axis, tries in zip(figure.axes, agents.tries, strict=True):  # each agent's own
            np.testing.assert_array_equal([bar.get_height() for bar in axis.patches], tries)
        self.assertReadable(figure, "7.4")


class TestCh8Figures(FigureTest):
    K, M, PROBLEMS, STAGES = 12, 4, 5, [0, 10]

    def Run(self, strategy: str, seed: int) -> ReachRun:
        """A run of 10 problem-tries, each a transition (some failing) then a reach."""
        log = []
        for attempt in range(10):
            state = int(RNG.integers(self.M))
            transition = [attempt, attempt % self.PROBLEMS, RNG.integers(self.K), state, 0, 0]
            reach = [attempt, attempt % self.PROBLEMS, self.K + state, state, 0, 0]
            log += [transition + [-10.0 * (attempt % 3 == 0), 0, 0, 0], reach + [0.9, 0, 0, 0]]
        self.assertEqual(len(log[0]), len(LOG_COLUMNS))
        evaluations = {
            str(stage): [
                [
                    dict(
                        problem=p,
                        reach=self.K + int(RNG.integers(self.M)),
                        reward=RNG.random(),
                        failed_transitions=int(RNG.integers(2)),
                    )
                    for p in range(self.PROBLEMS)
                ]
                for _ in range(2)
            ]
            for stage in self.STAGES
        }
        return ReachRun.FromJson(
            dict(
                settings=dict(
                    strategy=strategy, seed=seed, problem_tries=10, stages=self.STAGES,
                    evaluations=2, checkpoint_every=5,
                ),
                log=log,
                evaluations=evaluations,
                simulated_seconds=1.0, wall_seconds=1.0, penetrating_steps=0,
                num_transitions=self.K, num_states=self.M,
            )
        )  # fmt: skip

    def test_figures(self):
        by_strategy = {s: [self.Run(s, seed) for seed in range(2)] for s in ("random", "intrinsic")}
        self.assertReadable(ch8_figures.CumulativeRewardFigure(by_strategy, self.STAGES), "8.2")
        self.assertReadable(
            ch8_figures.ReachesFigure("random", by_strategy["random"], self.STAGES, self.K, self.M),
            "8.4-8.6",
        )
        self.assertReadable(
            ch8_figures.ProblemTriesFigure(by_strategy, self.STAGES, self.K, self.M), "8.7"
        )
        self.assertReadable(ch8_figures.FailedTransitionsFigure(by_strategy, self.K), "8.8")

    def test_each_seed_of_a_stacked_bar_has_its_colour(self):
        by_strategy = {"greedy": [self.Run("greedy", seed) for seed in range(3)]}
        figure = ch8_figures.CumulativeRewardFigure(by_strategy, self.STAGES)
        legend = figure.axes[0].get_legend()
        self.assertEqual(
            [t.get_text() for t in legend.get_texts()],
            ["sum with the -10 penalties", "seed 0", "seed 1", "seed 2"],
        )
        self.assertEqual(len(_LegendColours(legend)), 4)  # three seeds and the black tick
        SaveFigure(figure, pathlib.Path(tempfile.mkdtemp()) / "8.2.png", dpi=20)


class TestOtherFigures(FigureTest):
    def test_saggriac(self):
        curve = [
            dict(time_step=t, reaching_error=10 / (1 + t), prediction_error=5 / (1 + t))
            for t in (0, 100, 200)
        ]
        runs = [
            _BabblingRun(saggriac.RunSpec(1, method, seed, 200, 2), curve=curve)
            for method in ("SAGG-RIAC", "ACTUATOR-Random")
            for seed in range(2)
        ]
        figure = saggriac_figures.CurvesFigure(runs, ["SAGG-RIAC", "ACTUATOR-Random"], 1)
        self.assertPlots(figure, [10 / 101, 10 / 201, 5 / 201], "saggriac curves")
        self.assertReadable(figure, "saggriac curves")
        goals = np.zeros((40, 7))
        goals[:, 1:3] = RNG.uniform([0, -100], [100, 100], (40, 2))
        goals[:, 4] = 1  # a goal, not a subgoal
        run = _BabblingRun(
            saggriac.RunSpec(2, "SAGG-RIAC", 0, 1000, 2),
            config=dict(
                goal_space_low=[0, -100], goal_space_high=[100, 100], arm=dict(total_length=50)
            ),
            goal_log=goals.tolist(),
            region_snapshots=[
                dict(first_goal=10 * i, end_goal=10 * i + 10, regions=[[0, -100, 50, 100]])
                for i in range(4)
            ],
        )
        figure = saggriac_figures.GoalsFigure(run)
        # The last panel: every goal's bin, counted.
        counts, *_ = np.histogram2d(goals[:, 1], goals[:, 2], 30, [[0, 100], [-100, 100]])
        drawn = [a for a in figure.axes if not _IsColorbar(a)][-1].collections[0].get_array()
        np.testing.assert_array_equal(np.sort(np.ravel(drawn)), np.sort(counts.ravel()))
        self.assertEqual(np.sum(drawn), 40)
        self.assertReadable(figure, "saggriac goals")
        # A run too short to set a goal (subgoals only): one panel that says so, not empty
        # histograms titled "goals 1-0".
        goals[:, 4] = 0
        run.goal_log = goals.tolist()
        run.region_snapshots = [dict(s, first_goal=0, end_goal=0) for s in run.region_snapshots]
        figure = saggriac_figures.GoalsFigure(run)
        (axis,) = figure.axes
        self.assertEqual(axis.get_title(), "no goals (subgoals only)")
        self.assertReadable(figure, "saggriac goals, none")

    def test_roadmap_and_scalability(self):
        points = RNG.uniform(-0.3, 0.0, (6, 3))
        roadmap = types.SimpleNamespace(edges=[(0, 1), (1, 2), (3, 4)])
        figure = trm_roadmaps.RoadmapFigure(points, roadmap, "reach_into", boxes=True)
        self.assertPlots(figure, points, "trm")
        self.assertReadable(figure, "trm")
        curves = {"katana": [(0, 2e4, 1.9e4), (10, 3e3, 2e3)], "icub": [(0, 7e3, 6e3)]}
        figure = bench_forces.ScalabilityFigure(curves, churn=True)
        self.assertPlots(figure, [2e4, 1.9e4, 3e3, 2e3, 7e3, 6e3], "2.4")
        self.assertReadable(figure, "2.4")


if __name__ == "__main__":
    unittest.main()
