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

import numpy as np

from mobee_drake.experiments.battery import (
    Backend,
    Job,
    RunBattery,
    RunFolder,
    StopRequested,
)
from mobee_drake.experiments.exploration import (
    ExplorationRun,
    ExplorationScenario,
    Explore,
    StartExploration,
)
from mobee_drake.planning.explorers import ExplorerConfig, LoadAgentModel, MissShares
from mobee_drake.planning.planner import GreedyPlan
from mobee_drake.planning.supervisor import ExploringAgent
from mobee_drake.robots.icub import (
    LEFT_SHOULDER_ELBOW_JOINTS,
    RIGHT_SHOULDER_ELBOW_JOINTS,
    TORSO_JOINTS,
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
    transition_noise: float = 0.0,
    robot=None,
) -> dict:
    """The battery job of one exploration run: ``agents`` explore among ``objects`` until
    ``stop``; the result is :func:`Explore`'s data with ``labels``. With ``keep_model`` the run is
    checkpointed (and resumed after a kill) in ``run.path / "model"``, which keeps the final
    learned models. ``transition_noise`` makes the robot stochastic (see
    :mod:`mobee_drake.planning.actuation_noise`); ``robot`` is the scenario's robot (the iCub's
    upper body by default)."""
    scenario = ExplorationScenario(agents, objects, robot=robot, random_seed=random_seed)
    scenario.world_events = list(world_events)
    scenario.attractor.transition_noise = transition_noise
    explored = Explore(
        scenario,
        stop=stop,
        snapshots=snapshots,
        chunk=chunk,
        observer=_TableContacts if table_contacts else None,
        checkpoint=run.path / "model" if keep_model else None,
        progress=run.Progress,
        should_stop=StopRequested if keep_model else None,
    )
    explored.labels = labels
    return explored.ToJson()


def _RightArm(levels, **kwargs) -> ExploringAgent:
    return ExploringAgent(name="right_arm", joints=RIGHT_ARM, levels=levels, **kwargs)


def _Run(
    jobs: list[Job],
    output: pathlib.Path,
    backend: Backend,
    description: str,
    transition_noise: float = 0.0,
) -> list[ExplorationRun]:
    """Runs the exploration jobs (on a stochastic robot, named ``..._noise<sd>``, with
    ``transition_noise``) and returns their runs."""
    if transition_noise:
        jobs = [
            dc.replace(
                job,
                name=f"{job.name}_noise{transition_noise:g}",
                kwargs=dict(job.kwargs, transition_noise=transition_noise),
            )
            for job in jobs
        ]
    results = RunBattery(jobs, output, backend=backend, description=description)
    return [ExplorationRun.FromJson(result) for result in results.values()]


def RunHypercube(
    output: pathlib.Path,
    runs: int,
    backend: Backend,
    gammas=(0.5, 0.9, 0.99),
    transition_noise: float = 0.0,
) -> list[ExplorationRun]:
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
    return _Run(jobs, output, backend, "7.1", transition_noise)


def RunCoverage(
    output: pathlib.Path,
    transitions: int,
    runs: int,
    backend: Backend,
    transition_noise: float = 0.0,
) -> list[ExplorationRun]:
    """Ch. 7.2's coverage race: each strategy until every one of the 1296 state-actions was
    tried, or ``transitions`` (a cap; a run stopped by it is censored in the report)."""
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
                stop=Stop(min_tries=1, actions=transitions),
                labels=dict(strategy=strategy, run=run, cap=transitions),
                random_seed=run,
            ),
            total=transitions,
        )
        # (Least-tried before random: the claim compares it with the curious agent.)
        for strategy in ("curious", "least_tried", "random")
        for run in range(runs)
    ]
    return _Run(jobs, output, backend, "7.2", transition_noise)


def RunInitializations(
    output: pathlib.Path,
    runs: int,
    backend: Backend,
    gammas=(0.5, 0.9, 0.99),
    transition_noise: float = 0.0,
) -> list[ExplorationRun]:
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
    return _Run(jobs, output, backend, "7.2i", transition_noise)


RANK_4_LATTICES = {"20-80": [0.2, 0.4, 0.6, 0.8], "12.5-87.5": [0.125, 0.375, 0.625, 0.875]}
# The actions the source took on each (Fig. 7.8-7.9).
RANK_4_SOURCE_ACTIONS = {"20-80": 14597, "12.5-87.5": 26963}


def RunRank4(
    output: pathlib.Path,
    transitions: int | None,
    backend: Backend,
    transition_noise: float = 0.0,
) -> list[ExplorationRun]:
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
    return _Run(jobs, output, backend, "7.3", transition_noise)


def _ThreeAgents() -> list[ExploringAgent]:
    rank_3 = [0.25, 0.5, 0.75]
    return [
        ExploringAgent(name="right_arm", joints=RIGHT_ARM, levels=rank_3, nearest=16),
        ExploringAgent(name="left_arm", joints=LEFT_ARM, levels=rank_3, nearest=16),
        ExploringAgent(name="torso", joints=TORSO, levels=rank_3, nearest=8),
    ]


def RunThreeAgents(
    output: pathlib.Path, transitions: int, backend: Backend, transition_noise: float = 0.0
) -> ExplorationRun:
    job = Job(
        f"7.4_{transitions}",
        ExploreJob,
        dict(
            agents=_ThreeAgents(),
            stop=Stop(total_actions=transitions),
            labels={},
            objects=[TABLE],
            random_seed=1,  # the agents' seeds: 1, 2, 3
            chunk=5.0,
            table_contacts=True,
        ),
        total=transitions,
    )
    return _Run([job], output, backend, "7.4", transition_noise)[0]


# Each arm's share of 7.4's transitions (5,420 and 5,428 of 18,000): an arm alone explores as
# long as it did beside the others.
ARM_SHARE = 0.3


def RunThreeAgentsControls(
    output: pathlib.Path, transitions: int, backend: Backend, transition_noise: float = 0.0
) -> list[ExplorationRun]:
    """Controls for 7.4's arm-to-arm correlation (issue 34): the three agents without the
    table, and each arm alone by the table (the torso at home) for its share of the
    transitions."""
    agents = _ThreeAgents()
    alone = round(ARM_SHARE * transitions)
    settings = [
        ("no_table", agents, [], Stop(total_actions=transitions), transitions),
        ("right_alone", agents[:1], [TABLE], Stop(total_actions=alone), alone),
        ("left_alone", agents[1:2], [TABLE], Stop(total_actions=alone), alone),
    ]
    jobs = [
        Job(
            f"7.4c_{name}_{budget}",
            ExploreJob,
            dict(
                agents=chosen,
                stop=stop,
                labels=dict(control=name),
                objects=objects,
                random_seed=1,  # (as 7.4: the agents' seeds 1, 2, 3)
                chunk=5.0,
            ),
            total=budget,
        )
        for name, chosen, objects, stop, budget in settings
    ]
    return _Run(jobs, output, backend, "7.4c", transition_noise)


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

    return Observe, lambda: [c.tolist() for c in counts or []]


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
    return np.where(explorer.tries >= 5, 1 - MissShares(explorer), 1.0)


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


@dc.dataclass
class PlanningRun:
    """A learned model run as a planner among the moving box (ch. 7.4.1, :func:`PlanJob`).

    Attributes:
        reliability: Per state-action, the share of its tries that reached its goal (1 when
            tried fewer than 5 times).
        plans: Per problem, the greedy plan's states.
        episodes: Per executed problem: ``start``, ``goal``, ``actions``, ``failed`` (failed
            transitions) and ``tried`` (the state-actions tried).
        simulated_seconds: Simulated time of the executions.
        penetrating_steps: Control periods in which two solids penetrated.
    """

    reliability: list[float]
    plans: list[list[int]]
    episodes: list[dict] = dc.field(default_factory=list)
    simulated_seconds: float = 0.0
    penetrating_steps: int = 0


@dc.dataclass
class MovingBoxResult:
    """Ch. 7.4.1: the problems and the planners (:func:`RunDynamicPlanning`).

    Attributes:
        unreliable: The state-actions unreliable as the moving box's agent learned them.
        problems: (start, goal) with one risky and one safe shortest route.
        action_state: Each state-action's state.
        action_goal: Each state-action's goal state.
        planners: Per training ("moving_box", "no_box"), its model's planning run.
    """

    unreliable: list[int]
    problems: list[tuple[int, int]]
    action_state: list[int]
    action_goal: list[int]
    planners: dict[str, PlanningRun]


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
    """The battery job of ch. 7.4.1's planning with one learned model: its
    :class:`PlanningRun` as written (see :func:`_Plan`)."""
    explorer = LoadAgentModel(model, "right_arm", ExplorerConfig())
    planned = PlanningRun(
        reliability=_Reliability(explorer).tolist(),
        plans=[GreedyPlan(explorer, start, goal) for start, goal in problems],
        **(_Plan(pathlib.Path(model), problems, repeats, seed=seed) if problems else {}),
    )
    return dc.asdict(planned)


def RunDynamicPlanning(
    output: pathlib.Path, transitions: int, repeats: int, backend: Backend
) -> MovingBoxResult:
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
    jobs = [
        Job(
            f"7.4.1_plans_{trained}_{transitions}_{repeats}",
            PlanJob,
            dict(model=models[trained], problems=problems, repeats=repeats, seed=1),
        )
        for trained in learned
    ]
    plans = RunBattery(jobs, output, backend=backend, description="7.4.1 planning")
    return MovingBoxResult(
        unreliable=np.flatnonzero(unreliable).tolist(),
        problems=problems,
        action_state=space.action_state.tolist(),
        action_goal=space.action_goal.tolist(),
        planners={
            trained: PlanningRun(**planned)
            for trained, planned in zip(learned, plans.values(), strict=True)
        },
    )
