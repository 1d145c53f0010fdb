"""The model-learning experiments of dissertation ch. 7, on the kinematic iCub.

- ``7.1``: the right arm's shoulder-elbow hypercube (16 states, 64 state-actions), no obstacles,
  until every state-action was tried 5 times (320 actions); ``--runs`` runs for each gamma in
  0.5, 0.9, 0.99; the tries and the value function of every state-action after 50 and 320
  actions (Fig. 7.2-7.3).
- ``7.2``: coverage of the rank-3 lattice's state-actions (81 states, 16 nearest: 1296
  state-actions, the space ch. 7.2.1 used) against the number of transitions, for the curious
  agent (AC), random choice (RAND) and least-tried (LT) (Fig. 7.5).
- ``7.2i``: the rank-3 lattice with equidistant neighbours (81 states, 432 state-actions,
  Fig. 7.4), the 50-50 and the 60-40 initialisations, until every state-action was tried 5 times
  (Fig. 7.6-7.7); the tries and values, and the state-actions that do not reliably reach their goal.
- ``7.3``: both rank-4 lattices (256 states, 1536 state-actions; levels 20-80 % and 12.5-87.5 %)
  for ``--transitions`` actions each: the states never entered and why (their centres' shoulder
  cable clearance), and the state-actions with several outcomes (Fig. 7.8-7.9).
- ``7.4``: three agents (both arms, the torso) in front of a table for ``--transitions``
  transitions in all (18,000 in the source); the tries of every state-action of every agent
  (Fig. 7.12).
- ``7.4.1``: planning among a moving obstacle, on the right arm's hypercube: a box jumps at
  random times into the arm's way and out of it; a curious agent learns for
  ``--transitions`` actions among it (1000 by default), another without it; each becomes a
  planner (a reward on a goal state) and solves, ``--runs`` times among the moving box, every
  problem with two shortest routes of which one has a step the first agent found unreliable: the
  plans, and the actions and failed transitions per problem.

Every run is a job of the battery runner (:mod:`mobee_drake.experiments.battery`: ``--workers``
local processes or ``--ray [ADDRESS]``, a progress bar per run, results written atomically and
skipped when they exist, so an interrupted battery resumes), then the experiment writes PNG plots
and a ``report_<experiment>.md``. Run:
``mobee-drake experiment ch7 --experiment 7.1 --output results/ch7``.
"""

import dataclasses as dc
import pathlib
import sys

import numpy as np
from pydrake.geometry import SceneGraph
from pydrake.multibody.plant import MultibodyPlant
from scipy.stats import spearmanr

from mobee_drake.atomic_files import WriteTextAtomically
from mobee_drake.experiments.arguments import CommandParser, PositiveInt
from mobee_drake.experiments.battery import (
    AddBackendArguments,
    Backend,
    BackendOf,
    Job,
    Provenance,
    RunBattery,
    RunFolder,
    StopRequested,
)
from mobee_drake.experiments.exploration import (
    ExplorationScenario,
    Explore,
    Misses,
    StartExploration,
)
from mobee_drake.experiments.plots import Figure, Legend, SaveFigure, StackedBars, plt
from mobee_drake.mobee.constraints import ClauseSet
from mobee_drake.owned_folders import ClaimFolder
from mobee_drake.planning.explorers import ExplorerConfig, LoadAgentModel
from mobee_drake.planning.planner import GreedyPlan
from mobee_drake.planning.state_space import Lattice
from mobee_drake.planning.supervisor import ExploringAgent
from mobee_drake.robots.icub import (
    LEFT_SHOULDER_ELBOW_JOINTS,
    RIGHT_SHOULDER_ELBOW_JOINTS,
    TORSO_JOINTS,
    AddIcub,
    IcubConfig,
)
from mobee_drake.station.runner import Advance
from mobee_drake.world.objects import Box as BoxShape
from mobee_drake.world.objects import SceneObject, WorldEvent

RIGHT_ARM = list(RIGHT_SHOULDER_ELBOW_JOINTS)
LEFT_ARM = list(LEFT_SHOULDER_ELBOW_JOINTS)
TORSO = list(TORSO_JOINTS)
TABLE = SceneObject(
    name="table", shape=BoxShape(size=[0.6, 1.0, 0.04]), position=[-0.40, 0.0, -0.12]
)


@dc.dataclass(frozen=True)
class Stop:
    """When an exploration run ends: once every state-action of the first agent was tried
    ``min_tries`` times, the first agent took ``actions`` actions, or all agents together
    ``total_actions`` (the conditions that are not 0)."""

    min_tries: int = 0
    actions: int = 0
    total_actions: int = 0

    def __call__(self, records) -> bool:
        return (
            (self.min_tries > 0 and records[0].explorer.tries.min() >= self.min_tries)
            or (self.actions > 0 and records[0].actions_done >= self.actions)
            or (
                self.total_actions > 0
                and sum(r.actions_done for r in records) >= self.total_actions
            )
        )


def ExploreJob(
    run: RunFolder,
    *,
    agents: list[ExploringAgent],
    stop: Stop,
    labels: dict,
    objects=(),
    world_events=(),
    random_seed: int = 0,
    snapshots=(),
    chunk: float = 2.0,
    table_contacts: bool = False,
    keep_model: bool = False,
) -> dict:
    """The battery job of one exploration run: ``agents`` explore among ``objects`` until
    ``stop``; the result is :func:`Explore`'s data with ``labels``. With ``keep_model`` the run is
    checkpointed (and resumed after a kill) in ``run.path / "model"``, which keeps the final
    learned models."""
    scenario = ExplorationScenario(agents, objects, random_seed=random_seed)
    scenario.world_events = list(world_events)
    data = Explore(
        scenario,
        stop=stop,
        snapshots=snapshots,
        chunk=chunk,
        observer=_TableContacts if table_contacts else None,
        checkpoint=run.path / "model" if keep_model else None,
        progress=run.Progress,
        should_stop=StopRequested if keep_model else None,
    )
    return dict(**labels, **data)


def _RightArm(levels, **kwargs) -> ExploringAgent:
    return ExploringAgent(name="right_arm", joints=RIGHT_ARM, levels=levels, **kwargs)


def _Run(jobs: list[Job], output: pathlib.Path, backend: Backend, description: str) -> list:
    return list(RunBattery(jobs, output, backend=backend, description=description).values())


def RunHypercube(
    output: pathlib.Path, runs: int, backend: Backend, gammas=(0.5, 0.9, 0.99)
) -> list[dict]:
    jobs = [
        Job(
            f"7.1_gamma{gamma}_run{run}",
            ExploreJob,
            dict(
                agents=[_RightArm([0.25, 0.75], explorer=ExplorerConfig(gamma=gamma))],
                stop=Stop(min_tries=5),
                labels=dict(gamma=gamma, run=run),
                random_seed=run,
                snapshots=(50, 320),
            ),
            total=320,
        )
        for gamma in gammas
        for run in range(runs)
    ]
    return _Run(jobs, output, backend, "7.1")


def RunCoverage(output: pathlib.Path, transitions: int, runs: int, backend: Backend) -> list[dict]:
    jobs = [
        Job(
            f"7.2_{strategy}_run{run}",
            ExploreJob,
            dict(
                agents=[
                    _RightArm(
                        [0.25, 0.5, 0.75], nearest=16, explorer=ExplorerConfig(strategy=strategy)
                    )
                ],
                stop=Stop(actions=transitions),
                labels=dict(strategy=strategy, run=run),
                random_seed=run,
            ),
            total=transitions,
        )
        for strategy in ("curious", "random", "least_tried")
        for run in range(runs)
    ]
    return _Run(jobs, output, backend, "7.2")


def RunInitializations(
    output: pathlib.Path, runs: int, backend: Backend, gammas=(0.5, 0.9, 0.99)
) -> list[dict]:
    jobs = [
        Job(
            f"7.2i_{initialization}_gamma{gamma}_run{run}",
            ExploreJob,
            dict(
                agents=[
                    _RightArm(
                        [0.25, 0.5, 0.75],
                        explorer=ExplorerConfig(initialization=initialization, gamma=gamma),
                    )
                ],
                stop=Stop(min_tries=5),
                labels=dict(initialization=initialization, gamma=gamma, run=run),
                random_seed=run,
            ),
        )
        for initialization in ("50-50", "60-40")
        for gamma in gammas
        for run in range(runs)
    ]
    return _Run(jobs, output, backend, "7.2i")


RANK_4_LATTICES = {"20-80": [0.2, 0.4, 0.6, 0.8], "12.5-87.5": [0.125, 0.375, 0.625, 0.875]}
# The actions the source took on each (Fig. 7.8-7.9).
RANK_4_SOURCE_ACTIONS = {"20-80": 14597, "12.5-87.5": 26963}


def RunRank4(output: pathlib.Path, transitions: int | None, backend: Backend) -> list[dict]:
    """Each rank-4 lattice for ``transitions`` actions (None: the source's number)."""
    jobs = []
    for name, levels in RANK_4_LATTICES.items():
        budget = RANK_4_SOURCE_ACTIONS[name] if transitions is None else transitions
        jobs.append(
            Job(
                f"7.3_{name}_{budget}",
                ExploreJob,
                dict(
                    agents=[_RightArm(levels)],
                    stop=Stop(actions=budget),
                    labels=dict(lattice=name, levels=levels),
                    chunk=5.0,
                ),
                total=budget,
            )
        )
    return _Run(jobs, output, backend, "7.3")


def RunThreeAgents(output: pathlib.Path, transitions: int, backend: Backend) -> dict:
    rank_3 = [0.25, 0.5, 0.75]
    agents = [
        ExploringAgent(name="right_arm", joints=RIGHT_ARM, levels=rank_3, nearest=16),
        ExploringAgent(name="left_arm", joints=LEFT_ARM, levels=rank_3, nearest=16),
        ExploringAgent(name="torso", joints=TORSO, levels=rank_3, nearest=8),
    ]
    job = Job(
        f"7.4_{transitions}",
        ExploreJob,
        dict(
            agents=agents,
            stop=Stop(total_actions=transitions),
            labels={},
            objects=[TABLE],
            random_seed=1,  # the agents' seeds: 1, 2, 3
            chunk=5.0,
            table_contacts=True,
        ),
        total=transitions,
    )
    return _Run([job], output, backend, "7.4")[0]


def _TableContacts(simulation, period: float = 0.1):
    """Counts, every ``period`` seconds, which hand is inside a field with the table, for the
    state-action each agent has in flight: a right-hand contact counts for the right arm's, a
    left-hand contact for the left arm's, either for the torso's (ch. 7.4, Fig. 7.11-7.12)."""
    supervisor = simulation.client
    table = simulation.world.GeometryIdOf(simulation.diagram.CreateDefaultContext(), TABLE.name)
    names = simulation.robot.geometry_names
    hands = {"right_arm": {"r_hand"}, "left_arm": {"l_hand"}, "torso": {"r_hand", "l_hand"}}
    counts, next_sample = None, 0.0

    def Observe(context):
        nonlocal counts, next_sample
        if context.get_time() < next_sample:
            return
        next_sample = context.get_time() + period
        records = supervisor.Records(supervisor.GetMyContextFromRoot(context))
        if counts is None:
            counts = [np.zeros(r.explorer.space.num_state_actions, dtype=int) for r in records]
        pairs = simulation.mobee.GetOutputPort("field_pairs").Eval(
            simulation.mobee.GetMyContextFromRoot(context)
        )
        touching = {names[a] for a, b in zip(pairs.geometry_A, pairs.geometry_B) if b == table}
        for agent, record, count in zip(supervisor.agent_names, records, counts):
            if touching & hands[agent]:
                count[record.state_action] += 1

    return Observe, lambda: dict(table_contacts=[c.tolist() for c in counts or []])


# Ch. 7.4.1 on the right arm's hypercube: a 20 cm box that jumps, at random times, into the arm's
# way (centred on the right hand's pose in state 1: shoulder pitch, roll and yaw at 25 %, elbow at
# 75 %) or out of it (metres, the iCub's root frame). MoBeE lets the arm slip around the box on
# some edges (a hypercube's regions are large); where it does not, the transition fails while the
# box is there (a static box there fails 9 of the 64 state-actions in 25-75 % of their tries).
MOVING_BOX = "moving_box"
BOX_PLACES = {"in the way": [-0.209, 0.217, 0.273], "away": [0.3, -0.6, -0.3]}
# A state-action is unreliable when it reached its goal in fewer than this share of >= 5 tries.
UNRELIABLE = 0.8


def _MovingBox(seed: int, horizon: float) -> tuple[SceneObject, list[WorldEvent]]:
    """The box and its jumps until ``horizon`` (every 4-12 s, to a random place)."""
    rng, time_, events, places = np.random.default_rng(seed), 0.0, [], list(BOX_PLACES.values())
    while time_ < horizon:
        time_ += rng.uniform(4.0, 12.0)
        events.append(
            WorldEvent(
                time=round(time_, 2), object=MOVING_BOX, position=places[rng.integers(len(places))]
            )
        )
    return (
        SceneObject(
            name=MOVING_BOX, shape=BoxShape(size=[0.2, 0.2, 0.2]), position=BOX_PLACES["away"]
        ),
        events,
    )


def _Reliability(explorer) -> np.ndarray:
    """Per state-action, the share of its tries that reached its goal (1 when tried < 5 times)."""
    return np.where(explorer.tries >= 5, 1 - Misses(explorer), 1.0)


def DetourProblems(space, unreliable: np.ndarray) -> list[tuple[int, int]]:
    """(start, goal) two steps apart with exactly two shortest routes, one of them over an
    unreliable state-action and the other not."""
    action = {
        (int(s), int(g)): sa for sa, (s, g) in enumerate(zip(space.action_state, space.action_goal))
    }
    problems = []
    for start in range(space.num_states):
        for goal in range(space.num_states):
            routes = [
                (action[start, m], action[m, goal])
                for m in range(space.num_states)
                if (start, m) in action
                and (m, goal) in action
                and m != goal
                and (start, goal) not in action
                and start != goal
            ]
            risky = [bool(unreliable[list(route)].any()) for route in routes]
            if len(routes) == 2 and sum(risky) == 1:
                problems.append((start, goal))
    return problems


def _Plan(model: pathlib.Path, problems, repeats: int, seed: int) -> dict:
    """The learned model in ``model`` as a planner among the moving box: for each problem, go to
    its start, then plan to its goal and execute; counts actions and failed transitions."""
    box, events = _MovingBox(seed, horizon=40.0 * repeats * len(problems) * 6)
    agent = ExploringAgent(
        name="right_arm",
        joints=RIGHT_ARM,
        levels=[0.25, 0.75],
        model=str(model),
        explorer=ExplorerConfig(strategy="planner", goal_state=problems[0][0]),
    )
    scenario = ExplorationScenario([agent], [box], random_seed=seed)
    scenario.world_events = events
    simulation, simulator, supervisor, supervisor_context = StartExploration(scenario)
    context = simulator.get_context()

    def Go(goal: int, max_actions: int = 12) -> tuple[int, np.ndarray]:
        """Heads for ``goal``; returns the actions taken and the transitions observed."""
        supervisor.SetPlannerGoal(supervisor_context, "right_arm", goal)
        before = supervisor.Records(supervisor_context)[0]
        record = before
        while not record.arrived and record.actions_done - before.actions_done < max_actions:
            Advance(simulation, simulator, context.get_time() + 1.0)
            record = supervisor.Records(supervisor_context)[0]
        observed = record.explorer.transitions.counts - before.explorer.transitions.counts
        return record.actions_done - before.actions_done, observed

    space = supervisor.Records(supervisor_context)[0].explorer.space
    rows = np.arange(space.num_state_actions)
    episodes = []
    for _ in range(repeats):
        for start, goal in problems:
            Go(start)
            actions, observed = Go(goal)
            failed = observed.sum() - observed[rows, space.action_goal].sum()
            episodes.append(
                dict(
                    start=start,
                    goal=goal,
                    actions=actions,
                    failed=int(failed),
                    tried=np.flatnonzero(observed.sum(axis=1)).tolist(),
                )
            )
    report = simulation.monitor.Report(simulation.monitor.GetMyContextFromRoot(context))
    return dict(
        episodes=episodes,
        simulated_seconds=context.get_time(),
        penetrating_steps=report.penetrating_steps,
    )


def PlanJob(run: RunFolder, *, model: str, problems: list, repeats: int, seed: int) -> dict:
    """The battery job of ch. 7.4.1's planning with one learned model (see :func:`_Plan`)."""
    explorer = LoadAgentModel(model, "right_arm", ExplorerConfig())
    return dict(
        reliability=_Reliability(explorer).tolist(),
        plans=[GreedyPlan(explorer, start, goal) for start, goal in problems],
        **(
            _Plan(pathlib.Path(model), problems, repeats, seed=seed)
            if problems
            else dict(episodes=[])
        ),
    )


def RunDynamicPlanning(
    output: pathlib.Path, transitions: int, repeats: int, backend: Backend
) -> dict:
    """Ch. 7.4.1: a curious agent trained among the moving box and one trained without it, each
    turned into a planner (reward on a goal) and run among the moving box on the problems with a
    risky and a safe shortest route (risky as the first agent learned it)."""
    box, events = _MovingBox(seed=0, horizon=12.0 * transitions)
    trainings = {
        "moving_box": Job(
            f"7.4.1_model_moving_box_{transitions}",
            ExploreJob,
            dict(
                agents=[_RightArm([0.25, 0.75])],
                stop=Stop(actions=transitions),
                labels={},
                objects=[box],
                world_events=events,
                chunk=5.0,
                keep_model=True,
            ),
            total=transitions,
        ),
        "no_box": Job(
            f"7.4.1_model_no_box_{transitions}",
            ExploreJob,
            dict(
                agents=[_RightArm([0.25, 0.75])],
                stop=Stop(actions=transitions),
                labels={},
                chunk=5.0,
                keep_model=True,
            ),
            total=transitions,
        ),
    }
    _Run(list(trainings.values()), output, backend, "7.4.1 training")
    models = {
        trained: str(output / "runs" / job.name / "model") for trained, job in trainings.items()
    }
    learned = {
        trained: LoadAgentModel(model, "right_arm", ExplorerConfig())
        for trained, model in models.items()
    }
    space = learned["moving_box"].space
    unreliable = _Reliability(learned["moving_box"]) < UNRELIABLE
    problems = DetourProblems(space, unreliable)
    results = dict(
        unreliable=np.flatnonzero(unreliable).tolist(),
        problems=problems,
        action_state=space.action_state.tolist(),
        action_goal=space.action_goal.tolist(),
    )
    jobs = [
        Job(
            f"7.4.1_plans_{trained}_{transitions}_{repeats}",
            PlanJob,
            dict(model=models[trained], problems=problems, repeats=repeats, seed=1),
        )
        for trained in learned
    ]
    plans = _Run(jobs, output, backend, "7.4.1 planning")
    return dict(results, **dict(zip(learned, plans)))


def _ConstraintClearances(centres: np.ndarray) -> np.ndarray:
    """The smallest clearance (deg) of the right arm's constraint clauses at each state centre
    (fractions of the shoulder-elbow joints' ranges), from the iCub model and its overlay."""
    plant, scene_graph = MultibodyPlant(0.0), SceneGraph()
    plant.RegisterAsSourceForSceneGraph(scene_graph)
    robot = AddIcub(plant, scene_graph, IcubConfig(controlled_joints=RIGHT_ARM))
    plant.Finalize()
    lower = np.array([plant.GetJointByName(j).position_lower_limits()[0] for j in RIGHT_ARM])
    upper = np.array([plant.GetJointByName(j).position_upper_limits()[0] for j in RIGHT_ARM])
    clauses = ClauseSet(robot.overlay.clauses, RIGHT_ARM, robot.frozen_joints)
    return np.array(
        [np.degrees(clauses.Clearances(lower + c * (upper - lower)).min()) for c in centres]
    )


COVERAGE_STATE_ACTIONS = 1296  # 7.2: 81 states x 16 nearest neighbours
TRIES = "tries [count]"
VALUE = "value V(s, a) [nats]"  # expected discounted KL reward (Alg. 6)
STATE_ACTION = "state-action [index]"


def HypercubeFigure(results: list[dict]) -> Figure:
    """Fig. 7.2-7.3 on the hypercube: tries and values per state-action after 320 actions, one
    column per gamma, the runs stacked."""
    gammas = sorted({r["gamma"] for r in results})
    figure, axes = plt.subplots(2, len(gammas), figsize=(6 * len(gammas), 6.5), squeeze=False)
    for column, gamma in enumerate(gammas):
        mine = [r for r in results if r["gamma"] == gamma]
        for row, (key, unit) in enumerate((("tries", TRIES), ("values", VALUE))):
            axis = axes[row, column]
            StackedBars(
                axis,
                np.array([r["snapshots"]["320"][key] for r in mine]),
                [f"run {r['run']}" for r in mine],
            )
            axis.set(
                xlabel=STATE_ACTION,
                ylabel=f"{unit}, runs stacked",
                title=f"gamma {gamma}: {key} after 320 actions, {len(mine)} runs",
            )
    figure.suptitle("7.1, the right arm's hypercube (cf. Fig. 7.2-7.3)")
    return figure


def CoverageFigure(results: list[dict]) -> Figure:
    """Fig. 7.5: state-actions tried against transitions, one line per run."""
    figure, axis = plt.subplots(figsize=(8, 4))
    for strategy, colour in zip(
        ("curious", "random", "least_tried"), ("tab:green", "tab:red", "tab:blue")
    ):
        for r in [r for r in results if r["strategy"] == strategy]:
            coverage = np.array(r["coverage"])
            axis.plot(
                coverage[:, 0],
                coverage[:, 1],
                color=colour,
                label=strategy if r["run"] == 0 else None,
            )
    axis.axhline(COVERAGE_STATE_ACTIONS, color="0.5", linestyle=":", label="all state-actions")
    runs = len({r["run"] for r in results})
    axis.set(
        xlabel="transitions [count]",
        ylabel=f"state-actions tried [count, of {COVERAGE_STATE_ACTIONS}]",
        title=f"7.2, coverage of the rank-3 lattice (16 nearest neighbours), {runs} runs "
        "per strategy (cf. Fig. 7.5)",
    )
    Legend(axis, title="strategy (one line per run)")
    return figure


def Rank4Figure(r: dict, space: Lattice, never: np.ndarray) -> Figure:
    """Fig. 7.8-7.9 on a rank-4 lattice: tries and values per state-action, coloured by their
    outcomes, and the actions taken from each state, the states never entered shaded."""
    tries, misses = np.array(r["tries"][0]), np.array(r["misses"][0])
    outcomes = {
        "several outcomes (>= 3 tries)": ("tab:red", (misses > 0) & (misses < 1) & (tries >= 3)),
        "never reaches its goal (>= 3 tries)": ("tab:orange", (misses == 1) & (tries >= 3)),
    }
    colours = np.full(len(tries), "tab:blue", dtype=object)
    for colour, chosen in outcomes.values():
        colours[chosen] = colour
    legend = {label: colour for label, (colour, _) in outcomes.items()}
    legend["reaches its goal, or tried < 3 times"] = "tab:blue"
    figure, axes = plt.subplots(3, 1, figsize=(13, 9))
    caption = f"{r['lattice']} % lattice after {r['actions'][0]} actions"
    for axis, heights, unit, what in (
        (axes[0], tries, TRIES, "tries"),
        (axes[1], r["values"][0], VALUE, "value"),
    ):
        axis.bar(np.arange(len(tries)), heights, width=1.0, color=colours)
        axis.set(xlabel=STATE_ACTION, ylabel=unit, title=f"{caption}: {what} per state-action")
        Legend(axis, legend)
    visits = np.bincount(space.action_state, weights=tries, minlength=space.num_states)
    axes[2].bar(np.arange(space.num_states), visits, width=1.0, label="actions from the state")
    for state in never:
        axes[2].axvspan(state - 0.5, state + 0.5, color="grey", alpha=0.4)
    axes[2].set(
        xlabel="state [index]",
        ylabel="actions taken [count]",
        title=f"{caption}: actions taken from each state",
    )
    Legend(axes[2], {"never entered": ("grey", 0.4)})
    return figure


def InitializationFigure(results: list[dict], initialization: str) -> Figure:
    """Fig. 7.6-7.7: tries and values per state-action after every state-action was tried 5
    times, one pair of rows per gamma, the runs stacked."""
    mine = [r for r in results if r["initialization"] == initialization]
    gammas = sorted({r["gamma"] for r in mine})
    figure, axes = plt.subplots(2 * len(gammas), 1, figsize=(13, 5.2 * len(gammas)), squeeze=False)
    for row, gamma in enumerate(gammas):
        runs = [r for r in mine if r["gamma"] == gamma]
        for offset, (key, unit) in enumerate((("tries", TRIES), ("values", VALUE))):
            axis = axes[2 * row + offset, 0]
            StackedBars(
                axis, np.array([r[key][0] for r in runs]), [f"run {r['run']}" for r in runs]
            )
            axis.set(
                xlabel=STATE_ACTION,
                ylabel=f"{unit}, runs stacked",
                title=f"{initialization} initialisation, gamma {gamma}: {key} per state-action "
                f"once each was tried 5 times, {len(runs)} runs",
            )
    return figure


def MovingBoxFigure(results: dict) -> Figure:
    """Ch. 7.4.1: the share of tries reaching the goal per state-action, learned among the
    moving box and without it, the state-actions found unreliable shaded."""
    figure, axis = plt.subplots(figsize=(13, 4))
    for offset, (trained, label) in enumerate(
        (("moving_box", "learned among the moving box"), ("no_box", "learned without it"))
    ):
        reliability = results[trained]["reliability"]
        axis.bar(np.arange(len(reliability)) + 0.4 * offset, reliability, width=0.4, label=label)
    for sa in results["unreliable"]:
        axis.axvspan(sa - 0.3, sa + 0.7, color="red", alpha=0.15)
    axis.set(
        xlabel=STATE_ACTION,
        ylabel="tries reaching the goal [fraction]",
        title="7.4.1, the right arm's hypercube: reliability of each state-action "
        "(1 when tried < 5 times)",
    )
    Legend(axis, {f"unreliable (< {UNRELIABLE:.0%} among the box)": ("red", 0.15)})
    return figure


def ThreeAgentsFigure(results: dict) -> Figure:
    """Fig. 7.10-7.12: each agent's tries per state-action, exploring together by a table."""
    figure, axes = plt.subplots(3, 1, figsize=(13, 9))
    for axis, name, tries, actions in zip(
        axes, results["agents"], results["tries"], results["actions"]
    ):
        axis.bar(np.arange(len(tries)), tries, label=f"{name}, {actions} actions")
        axis.set(
            xlabel=STATE_ACTION,
            ylabel=TRIES,
            title=f"7.4, three agents by a table ({sum(results['actions'])} transitions in "
            f"all): {name}'s tries per state-action",
        )
        Legend(axis)
    return figure


def _HypercubeReport(output: pathlib.Path, results) -> list[str]:
    """The hypercube of ch. 7.1: tries and values after 320 actions, per gamma."""
    lines = []
    SaveFigure(HypercubeFigure(results), output / "7.1_hypercube.png")
    for gamma in sorted({r["gamma"] for r in results}):
        mine = [r for r in results if r["gamma"] == gamma]
        tries = np.array([r["snapshots"]["320"]["tries"] for r in mine])
        values = np.array([r["snapshots"]["320"]["values"] for r in mine])
        lines.append(
            f"| {gamma} | {len(mine)} | {tries.mean():.2f} | "
            f"{tries.std(axis=1).mean():.2f} | {values.mean():.4f} | "
            f"{np.mean([r['wall_seconds'] for r in mine]):.1f} |"
        )
    header = [
        "| gamma | runs | mean tries per state-action after 320 actions | "
        "spread of tries (std over state-actions, mean over runs) | mean V(s, a) | "
        "wall s per run |",
        "|---:|---:|---:|---:|---:|---:|",
    ]
    return header + lines


def _CoverageReport(output: pathlib.Path, results) -> list[str]:
    """Coverage (ch. 7.2): transitions until every state-action was tried."""
    lines = []
    SaveFigure(CoverageFigure(results), output / "7.2_coverage.png")
    for strategy in ("curious", "random", "least_tried"):
        for r in [r for r in results if r["strategy"] == strategy]:
            coverage = np.array(r["coverage"])
            full = coverage[coverage[:, 1] >= COVERAGE_STATE_ACTIONS, 0]
            lines.append(
                f"| {strategy} | {r['run']} | {coverage[-1, 0]} | "
                f"{coverage[-1, 1]} | {full[0] if len(full) else '-'} |"
            )
    return [
        "| strategy | run | transitions | state-actions tried | transitions to try all |",
        "|---|---:|---:|---:|---:|",
    ] + lines


def _Rank4Report(output: pathlib.Path, results) -> list[str]:
    """The rank-4 lattices (ch. 7.3): states never entered, several outcomes."""
    lines = []
    header = [
        "| lattice | actions | states never entered (clearance of the tightest "
        "constraint clause at their centres, deg of joint space) | state-actions with "
        "several outcomes (tried >= 3 times) | most-tried state-action: tries, share "
        "ending in its goal |",
        "|---|---:|---|---:|---|",
    ]
    for r in results:
        space = Lattice(r["levels"], 4)
        tries, misses = np.array(r["tries"][0]), np.array(r["misses"][0])
        entered = np.zeros(space.num_states, dtype=bool)
        entered[space.action_state[tries > 0]] = True  # an action was tried from it
        never = np.flatnonzero(~entered)
        clearance = _ConstraintClearances(space.centres[never])
        clearances = [f"{s_}: {c:.0f}" for s_, c in zip(never, clearance)]
        several = int(np.sum((misses > 0) & (misses < 1) & (tries >= 3)))
        top = int(np.argmax(tries))
        lines.append(
            f"| {r['lattice']} | {r['actions'][0]} | {len(never)}: "
            f"{', '.join(clearances) or '-'} | {several} | "
            f"{space.action_state[top]}->{space.action_goal[top]}: {tries[top]}, "
            f"{100 * (1 - misses[top]):.0f} % |"
        )
        SaveFigure(Rank4Figure(r, space, never), output / f"7.3_{r['lattice']}.png")
    return header + lines


def _InitializationReport(output: pathlib.Path, results) -> list[str]:
    """The initialisations (ch. 7.2): state-actions that miss their goal."""
    lines = []
    space = Lattice([0.25, 0.5, 0.75], 4)
    header = [
        "| initialisation | gamma | run | actions | state-actions missing their goal "
        "in more than 10 % of >= 3 tries (state -> goal: misses/tries) |",
        "|---|---:|---:|---:|---|",
    ]
    for initialization in ("50-50", "60-40"):
        SaveFigure(
            InitializationFigure(results, initialization),
            output / f"7.2i_{initialization}.png",
        )
        for gamma in sorted({r["gamma"] for r in results}):
            for r in results:
                if r["initialization"] != initialization or r["gamma"] != gamma:
                    continue
                tries, misses = np.array(r["tries"][0]), np.array(r["misses"][0])
                unreliable = np.flatnonzero((misses > 0.1) & (tries >= 3))
                listed = ", ".join(
                    f"{space.action_state[i]}->{space.action_goal[i]}: "
                    f"{round(misses[i] * tries[i])}/{tries[i]}"
                    for i in unreliable
                )
                lines.append(
                    f"| {initialization} | {gamma} | {r['run']} | "
                    f"{r['actions'][0]} | {listed or '-'} |"
                )
    return header + lines


def _MovingBoxReport(output: pathlib.Path, results) -> list[str]:
    """The moving box (ch. 7.4.1): plans and executions over risky steps."""
    lines = []
    SaveFigure(MovingBoxFigure(results), output / "7.4.1_moving_box.png")
    unreliable = np.array(results["unreliable"], dtype=int)
    risky = {(results["action_state"][sa], results["action_goal"][sa]) for sa in unreliable}
    header = [
        f"- unreliable state-actions learned among the moving box (reached their goal "
        f"in < {UNRELIABLE:.0%} of >= 5 tries), state -> goal: "
        + (", ".join(f"{s_}->{g}" for s_, g in sorted(risky)) or "none"),
        f"- problems with one risky and one safe shortest route: {len(results['problems'])}",
        "",
        "| trained | greedy plans over a risky step | executed problems | actions per "
        "problem | failed transitions per problem | problems that tried a risky "
        "state-action | penetrating control periods |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for trained in ("moving_box", "no_box"):
        r = results[trained]
        crossing = sum(any(step in risky for step in zip(path, path[1:])) for path in r["plans"])
        episodes = r["episodes"] or [dict(actions=0, failed=0, tried=[])]
        lines.append(
            f"| {trained} | {crossing} of {len(r['plans'])} | {len(r['episodes'])} | "
            f"{np.mean([e['actions'] for e in episodes]):.2f} | "
            f"{np.mean([e['failed'] for e in episodes]):.2f} | "
            f"{np.mean([bool(set(e['tried']) & set(unreliable)) for e in episodes]):.0%} | "
            f"{r.get('penetrating_steps', 0)} |"
        )
    return header + lines


def _ThreeAgentsReport(output: pathlib.Path, results) -> list[str]:
    """Three agents (ch. 7.4): tries, contacts and surprises per agent."""
    SaveFigure(ThreeAgentsFigure(results), output / "7.4_three_agents.png")
    right, left = (np.array(t, dtype=float) for t in results["tries"][:2])
    correlation = float(np.corrcoef(right, left)[0, 1])
    lines = [
        f"- transitions: {sum(results['actions'])} ({results['actions']} per agent), "
        f"{results['simulated_seconds']:.0f} s simulated in {results['wall_seconds']:.0f} s "
        f"wall",
        f"- correlation of the right and the left arm's tries per state-action: {correlation:.3f}",
        f"- penetrating control periods: {results['penetrating_steps']}",
    ]
    for name, tries, contacts in zip(
        results["agents"], results["tries"], results.get("table_contacts", [])
    ):
        tries, contacts = np.array(tries), np.array(contacts)
        top = np.argsort(tries)[::-1][:20]
        # Undefined when either is constant (e.g. no contact at all in a short run).
        constant = np.ptp(tries) == 0 or np.ptp(contacts) == 0
        correlation = "n/a" if constant else f"{spearmanr(tries, contacts).statistic:.2f}"
        lines.append(
            f"- {name}: hand-table contact (samples every 0.1 s with a hand inside a field with "
            f"the table) during {contacts.sum()} samples; the 20 most-tried state-actions "
            f"({100 * tries[top].sum() / tries.sum():.0f} % of the tries) hold "
            f"{100 * contacts[top].sum() / max(contacts.sum(), 1):.0f} % of them; rank "
            f"correlation of tries and contact samples per state-action: "
            f"{correlation}; state-actions with contact: "
            f"{int((contacts > 0).sum())} of {len(tries)}"
        )
    for name, tries, misses, goals in zip(
        results["agents"], results["tries"], results["misses"], results["goals"]
    ):
        tries, misses, goals = np.array(tries), np.array(misses), np.array(goals)
        top = np.argsort(tries)[::-1][:20]
        surprising = misses > 0.1
        tried_surprising = tries[surprising].mean() if surprising.any() else 0.0
        lines.append(
            f"- {name}: the 20 most-tried state-actions (mean {tries[top].mean():.0f} tries, "
            f"median of all {np.median(tries):.0f}) miss their goal in "
            f"{100 * misses[top].mean():.0f} % of their tries (all: "
            f"{100 * misses.mean():.0f} %); state-actions missing their goal more than 10 % of "
            f"the time: {surprising.sum()}, tried {tried_surprising:.0f} times on average "
            f"against {tries[~surprising].mean():.0f}; mean goal of the 20 "
            f"most-tried, in fractions of range: {np.round(goals[top].mean(axis=0), 2).tolist()}"
        )
    return lines


# Each experiment's figures, written into the output folder; each returns its report's lines.
_REPORTS = {
    "7.1": _HypercubeReport,
    "7.2": _CoverageReport,
    "7.3": _Rank4Report,
    "7.2i": _InitializationReport,
    "7.4.1": _MovingBoxReport,
    "7.4": _ThreeAgentsReport,
}


def _Parser() -> CommandParser:
    """The command line of ``mobee-drake experiment ch7``."""
    parser = CommandParser(
        prog="mobee-drake experiment ch7",
        description=__doc__,
    )
    parser.add_argument(
        "--experiment",
        choices=["7.1", "7.2", "7.2i", "7.3", "7.4", "7.4.1"],
        required=True,
        help="which experiment of ch. 7",
    )
    parser.add_argument(
        "--output", default="results/ch7", help="the battery folder (runs, plots, report)"
    )
    parser.add_argument("--runs", type=PositiveInt, default=5, help="runs (seeds) per setting")
    parser.add_argument(
        "--transitions",
        type=PositiveInt,
        default=None,
        help="7.2: per run (default 2500); 7.3: per lattice (default: the "
        "source's 14,597 and 26,963); 7.4: in all (default 18,000)",
    )
    AddBackendArguments(parser)
    return parser


def main(argv=None) -> None:
    parser = _Parser()
    argv = sys.argv[1:] if argv is None else argv
    args = parser.parse_args(argv)
    output = ClaimFolder(args.output, "battery")  # (a file or a user's folder refused)
    backend = BackendOf(args)
    if args.experiment == "7.1":
        results = RunHypercube(output, args.runs, backend)
    elif args.experiment == "7.2":
        results = RunCoverage(output, args.transitions or 2500, args.runs, backend)
    elif args.experiment == "7.2i":
        results = RunInitializations(output, args.runs, backend)
    elif args.experiment == "7.3":
        results = RunRank4(output, args.transitions, backend)
    elif args.experiment == "7.4":
        results = RunThreeAgents(output, args.transitions or 18000, backend)
    else:
        results = RunDynamicPlanning(output, args.transitions or 1000, args.runs, backend)
    table = _REPORTS[args.experiment](output, results)
    text = (
        f"# Experiment {args.experiment}\n\n`mobee-drake experiment ch7 "
        f"{' '.join(argv)}` ({Provenance(output)})\n\n" + "\n".join(table) + "\n"
    )
    WriteTextAtomically(output / f"report_{args.experiment}.md", text)
    print(text)


if __name__ == "__main__":
    main()
