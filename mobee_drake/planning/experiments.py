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

Each run writes its data as JSON (atomically, skipped when it exists, so an interrupted battery
resumes), then the experiment writes PNG plots and a ``report.md``. Run:
``python -m mobee_drake.planning.experiments --experiment 7.1 --output results/ch7``.
"""

import argparse
import json
import os
import pathlib
import sys
import time

import numpy as np
from pydrake.geometry import SceneGraph
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.analysis import Simulator

from mobee_drake.mobee.constraints import ClauseSet
from mobee_drake.planning.explorers import INITIALIZATIONS, ExplorerConfig, LoadAgentModel
from mobee_drake.planning.planner import GreedyPlan
from mobee_drake.planning.state_space import Lattice
from mobee_drake.robots.icub import AddIcub, IcubConfig
from mobee_drake.simulation.builder import BuildSimulation
from mobee_drake.simulation.checkpoint import SaveCheckpoint
from mobee_drake.simulation.runner import Advance
from mobee_drake.simulation.scenario import Box as BoxShape
from mobee_drake.simulation.scenario import (
    ExploreAttractor,
    ExploringAgent,
    Scenario,
    SceneObject,
    WorldEvent,
)

RIGHT_ARM = ["r_shoulder_pitch", "r_shoulder_roll", "r_shoulder_yaw", "r_elbow"]
LEFT_ARM = ["l_shoulder_pitch", "l_shoulder_roll", "l_shoulder_yaw", "l_elbow"]
TORSO = ["torso_pitch", "torso_roll", "torso_yaw"]
TABLE = SceneObject(
    name="table", shape=BoxShape(size=[0.6, 1.0, 0.04]), position=[-0.40, 0.0, -0.12]
)


def ExplorationScenario(agents: list[ExploringAgent], objects=(), robot=None) -> Scenario:
    """A headless kinematic scenario in which ``agents`` explore (``robot``: the iCub's
    configuration, by default the upper body's joints)."""
    scenario = Scenario()
    scenario.robot = robot or scenario.robot
    scenario.objects = list(objects)
    scenario.attractor = ExploreAttractor(agents=agents)
    scenario.time_step = 0.02
    scenario.visualization.meshcat = False
    return scenario


def _Start(scenario: Scenario):
    """The scenario built and initialised: the simulation, its simulator, the exploration
    supervisor and the supervisor's context."""
    simulation = BuildSimulation(scenario)
    simulator = Simulator(simulation.diagram)
    simulator.Initialize()
    supervisor = simulation.diagram.GetSubsystemByName("attractor")
    return (
        simulation,
        simulator,
        supervisor,
        supervisor.GetMyContextFromRoot(simulator.get_context()),
    )


def Explore(
    scenario: Scenario,
    stop,
    snapshots=(),
    chunk: float = 2.0,
    keep: pathlib.Path | None = None,
    observer=None,
) -> dict:
    """Runs until ``stop(records)``; returns per-agent tries (and values at ``snapshots``); with
    ``keep``, saves the final checkpoint there (the learned models, for a planner to reuse);
    ``observer(simulation)``, if given, returns a callable run on the root context after every
    step of the simulation and a function giving its data for the result."""
    simulation, simulator, supervisor, supervisor_context = _Start(scenario)
    context = simulator.get_context()
    observe, observed = observer(simulation) if observer else (None, dict)
    taken, coverage, start = {}, [], time.perf_counter()
    while True:
        Advance(simulation, simulator, context.get_time() + chunk, after_chunk=observe)
        records = supervisor.Records(supervisor_context)
        done = sum(r.actions_done for r in records)
        coverage.append([done] + [int((r.explorer.tries > 0).sum()) for r in records])
        for count in snapshots:
            if count not in taken and records[0].actions_done >= count:
                taken[count] = dict(
                    tries=records[0].explorer.tries.tolist(),
                    values=records[0].explorer.Values()[0].tolist(),
                )
        if stop(records):
            break
    if keep is not None:
        SaveCheckpoint(simulation, context, keep)
    report = simulation.monitor.Report(simulation.monitor.GetMyContextFromRoot(context))
    return dict(
        agents=supervisor.agent_names,
        tries=[r.explorer.tries.tolist() for r in records],
        values=[r.explorer.Values()[0].tolist() for r in records],
        misses=[_Misses(r.explorer).tolist() for r in records],
        goals=[r.explorer.space.centres[r.explorer.space.action_goal].tolist() for r in records],
        actions=[r.actions_done for r in records],
        snapshots=taken,
        coverage=coverage,
        simulated_seconds=context.get_time(),
        wall_seconds=time.perf_counter() - start,
        penetrating_steps=report.penetrating_steps,
        **observed(),
    )


def _Misses(explorer) -> np.ndarray:
    """Per state-action, the share of its tries that did not end in its goal state (0 untried)."""
    space, counts = explorer.space, explorer.transitions.counts
    initial = 1 + INITIALIZATIONS[explorer.config.initialization]  # goal counts before tries
    hits = counts[np.arange(space.num_state_actions), space.action_goal] - initial
    return np.where(explorer.tries > 0, 1 - hits / np.maximum(explorer.tries, 1), 0.0)


def SaveJson(path: pathlib.Path, data: dict) -> None:
    """Writes ``data`` as JSON beside ``path`` and renames it into place."""
    temporary = path.with_suffix(".tmp")
    temporary.write_text(json.dumps(data))
    os.replace(temporary, path)


def RunHypercube(output: pathlib.Path, runs: int, gammas=(0.5, 0.9, 0.99)) -> list[dict]:
    results = []
    for gamma in gammas:
        for run in range(runs):
            path = output / f"7.1_gamma{gamma}_run{run}.json"
            if not path.exists():
                agent = ExploringAgent(
                    name="right_arm",
                    joints=RIGHT_ARM,
                    levels=[0.25, 0.75],
                    explorer=ExplorerConfig(gamma=gamma, seed=run),
                )
                data = Explore(
                    ExplorationScenario([agent]),
                    stop=lambda records: records[0].explorer.tries.min() >= 5,
                    snapshots=(50, 320),
                )
                SaveJson(path, dict(gamma=gamma, run=run, **data))
            results.append(json.loads(path.read_text()))
    return results


def RunCoverage(output: pathlib.Path, transitions: int, runs: int) -> list[dict]:
    results = []
    for strategy in ("curious", "random", "least_tried"):
        for run in range(runs):
            path = output / f"7.2_{strategy}_run{run}.json"
            if not path.exists():
                agent = ExploringAgent(
                    name="right_arm",
                    joints=RIGHT_ARM,
                    levels=[0.25, 0.5, 0.75],
                    nearest=16,
                    explorer=ExplorerConfig(strategy=strategy, seed=run),
                )
                data = Explore(
                    ExplorationScenario([agent]),
                    stop=lambda records: records[0].actions_done >= transitions,
                )
                SaveJson(path, dict(strategy=strategy, run=run, **data))
            results.append(json.loads(path.read_text()))
    return results


def RunInitializations(output: pathlib.Path, runs: int, gammas=(0.5, 0.9, 0.99)) -> list[dict]:
    results = []
    for initialization in ("50-50", "60-40"):
        for gamma in gammas:
            for run in range(runs):
                path = output / f"7.2i_{initialization}_gamma{gamma}_run{run}.json"
                if not path.exists():
                    agent = ExploringAgent(
                        name="right_arm",
                        joints=RIGHT_ARM,
                        levels=[0.25, 0.5, 0.75],
                        explorer=ExplorerConfig(
                            initialization=initialization, gamma=gamma, seed=run
                        ),
                    )
                    data = Explore(
                        ExplorationScenario([agent]),
                        stop=lambda records: records[0].explorer.tries.min() >= 5,
                    )
                    SaveJson(
                        path, dict(initialization=initialization, gamma=gamma, run=run, **data)
                    )
                results.append(json.loads(path.read_text()))
    return results


RANK_4_LATTICES = {"20-80": [0.2, 0.4, 0.6, 0.8], "12.5-87.5": [0.125, 0.375, 0.625, 0.875]}
# The actions the source took on each (Fig. 7.8-7.9).
RANK_4_SOURCE_ACTIONS = {"20-80": 14597, "12.5-87.5": 26963}


def RunRank4(output: pathlib.Path, transitions: int | None) -> list[dict]:
    """Each rank-4 lattice for ``transitions`` actions (None: the source's number)."""
    results = []
    for name, levels in RANK_4_LATTICES.items():
        budget = RANK_4_SOURCE_ACTIONS[name] if transitions is None else transitions
        path = output / f"7.3_{name}_{budget}.json"
        if not path.exists():
            agent = ExploringAgent(
                name="right_arm", joints=RIGHT_ARM, levels=levels, explorer=ExplorerConfig(seed=0)
            )
            data = Explore(
                ExplorationScenario([agent]),
                chunk=5.0,
                stop=lambda records, budget=budget: records[0].actions_done >= budget,
            )
            SaveJson(path, dict(lattice=name, levels=levels, **data))
        results.append(json.loads(path.read_text()))
    return results


def RunThreeAgents(output: pathlib.Path, transitions: int) -> dict:
    path = output / f"7.4_{transitions}.json"
    if not path.exists():
        agents = [
            ExploringAgent(
                name="right_arm",
                joints=RIGHT_ARM,
                levels=[0.25, 0.5, 0.75],
                nearest=16,
                explorer=ExplorerConfig(seed=1),
            ),
            ExploringAgent(
                name="left_arm",
                joints=LEFT_ARM,
                levels=[0.25, 0.5, 0.75],
                nearest=16,
                explorer=ExplorerConfig(seed=2),
            ),
            ExploringAgent(
                name="torso",
                joints=TORSO,
                levels=[0.25, 0.5, 0.75],
                nearest=8,
                explorer=ExplorerConfig(seed=3),
            ),
        ]
        data = Explore(
            ExplorationScenario(agents, [TABLE]),
            chunk=5.0,
            observer=_TableContacts,
            stop=lambda records: sum(r.actions_done for r in records) >= transitions,
        )
        SaveJson(path, data)
    return json.loads(path.read_text())


def _TableContacts(simulation, period: float = 0.1):
    """Counts, every ``period`` seconds, which hand is inside a field with the table, for the
    state-action each agent has in flight: a right-hand contact counts for the right arm's, a
    left-hand contact for the left arm's, either for the torso's (ch. 7.4, Fig. 7.11-7.12)."""
    supervisor = simulation.diagram.GetSubsystemByName("attractor")
    table = simulation.world.geometry_id(TABLE.name)
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
    return np.where(explorer.tries >= 5, 1 - _Misses(explorer), 1.0)


def _DetourProblems(space, unreliable: np.ndarray) -> list[tuple[int, int]]:
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
        explorer=ExplorerConfig(strategy="planner", goal_state=problems[0][0], seed=seed),
    )
    scenario = ExplorationScenario([agent], [box])
    scenario.world_events = events
    simulation, simulator, supervisor, supervisor_context = _Start(scenario)
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


def RunDynamicPlanning(output: pathlib.Path, transitions: int, repeats: int) -> dict:
    """Ch. 7.4.1: a curious agent trained among the moving box and one trained without it, each
    turned into a planner (reward on a goal) and run among the moving box on the problems with a
    risky and a safe shortest route (risky as the first agent learned it)."""
    models = {}
    for trained in ("moving_box", "no_box"):
        models[trained] = output / f"7.4.1_model_{trained}_{transitions}"
        if not models[trained].exists():
            agent = ExploringAgent(
                name="right_arm",
                joints=RIGHT_ARM,
                levels=[0.25, 0.75],
                explorer=ExplorerConfig(seed=0),
            )
            box, events = _MovingBox(seed=0, horizon=12.0 * transitions)
            scenario = ExplorationScenario([agent], [box] if trained == "moving_box" else [])
            scenario.world_events = events if trained == "moving_box" else []
            Explore(
                scenario,
                chunk=5.0,
                keep=models[trained],
                stop=lambda records: records[0].actions_done >= transitions,
            )
    learned = {
        trained: LoadAgentModel(str(model), "right_arm", ExplorerConfig())
        for trained, model in models.items()
    }
    space = learned["moving_box"].space
    unreliable = _Reliability(learned["moving_box"]) < UNRELIABLE
    problems = _DetourProblems(space, unreliable)
    results = dict(
        unreliable=np.flatnonzero(unreliable).tolist(),
        problems=problems,
        action_state=space.action_state.tolist(),
        action_goal=space.action_goal.tolist(),
    )
    for trained, explorer in learned.items():
        path = output / f"7.4.1_plans_{trained}_{transitions}_{repeats}.json"
        if not path.exists():
            plans = [GreedyPlan(explorer, start, goal) for start, goal in problems]
            SaveJson(
                path,
                dict(
                    reliability=_Reliability(explorer).tolist(),
                    plans=plans,
                    **(
                        _Plan(models[trained], problems, repeats, seed=1)
                        if problems
                        else dict(episodes=[])
                    ),
                ),
            )
        results[trained] = json.loads(path.read_text())
    return results


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


def _StackedBars(axis, stack: np.ndarray, title: str) -> None:
    """One bar per state-action, the runs (rows of ``stack``) stacked in colours (Fig. 7.2-7.7)."""
    bottom = np.zeros(stack.shape[1])
    for values in stack:
        axis.bar(np.arange(len(values)), values, bottom=bottom, width=1.0)
        bottom += values
    axis.set_title(title)


def _Plots(output: pathlib.Path, experiment: str, results) -> list[str]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    lines = []
    if experiment == "7.1":
        gammas = sorted({r["gamma"] for r in results})
        figure, axes = plt.subplots(2, len(gammas), figsize=(5 * len(gammas), 6), squeeze=False)
        for column, gamma in enumerate(gammas):
            mine = [r for r in results if r["gamma"] == gamma]
            for row, key in enumerate(("tries", "values")):
                _StackedBars(
                    axes[row, column],
                    np.array([r["snapshots"]["320"][key] for r in mine]),
                    f"gamma {gamma}: {key} after 320 actions",
                )
            tries = np.array([r["snapshots"]["320"]["tries"] for r in mine])
            values = np.array([r["snapshots"]["320"]["values"] for r in mine])
            lines.append(
                f"| {gamma} | {len(mine)} | {tries.mean():.2f} | "
                f"{tries.std(axis=1).mean():.2f} | {values.mean():.4f} | "
                f"{np.mean([r['wall_seconds'] for r in mine]):.1f} |"
            )
        figure.tight_layout()
        figure.savefig(output / "7.1_hypercube.png", dpi=80)
        header = [
            "| gamma | runs | mean tries per state-action after 320 actions | "
            "spread of tries (std over state-actions, mean over runs) | mean V(s, a) | "
            "wall s per run |",
            "|---:|---:|---:|---:|---:|---:|",
        ]
        return header + lines
    if experiment == "7.2":
        figure, axis = plt.subplots(figsize=(7, 4))
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
                full = coverage[coverage[:, 1] >= 1296, 0]
                lines.append(
                    f"| {strategy} | {r['run']} | {coverage[-1, 0]} | "
                    f"{coverage[-1, 1]} | {full[0] if len(full) else '-'} |"
                )
        axis.set_xlabel("transitions")
        axis.set_ylabel("state-actions tried (of 1296)")
        axis.legend()
        figure.tight_layout()
        figure.savefig(output / "7.2_coverage.png", dpi=80)
        return [
            "| strategy | run | transitions | state-actions tried | transitions to try all |",
            "|---|---:|---:|---:|---:|",
        ] + lines
    if experiment == "7.3":
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
            # Like Fig. 7.8-7.9: tries, values and visits; state-actions that sometimes miss
            # their goal in red, the states never entered shaded.
            figure, axes = plt.subplots(3, 1, figsize=(12, 7))
            colours = np.where((misses > 0) & (tries >= 3), "tab:red", "tab:blue")
            axes[0].bar(np.arange(len(tries)), tries, width=1.0, color=colours)
            axes[0].set_title(
                f"{r['lattice']} lattice, {r['actions'][0]} actions: tries per "
                "state-action (red: sometimes ends elsewhere)"
            )
            axes[1].bar(np.arange(len(tries)), r["values"][0], width=1.0, color=colours)
            axes[1].set_title("value V(s, a)")
            visits = np.bincount(space.action_state, weights=tries, minlength=space.num_states)
            axes[2].bar(np.arange(space.num_states), visits, width=1.0)
            for state in never:
                axes[2].axvspan(state - 0.5, state + 0.5, color="grey", alpha=0.4)
            axes[2].set_title("actions taken from each state (grey: never entered)")
            figure.tight_layout()
            figure.savefig(output / f"7.3_{r['lattice']}.png", dpi=80)
        return header + lines
    if experiment == "7.2i":
        space = Lattice([0.25, 0.5, 0.75], 4)
        gammas = sorted({r["gamma"] for r in results})
        header = [
            "| initialisation | gamma | run | actions | state-actions missing their goal "
            "in more than 10 % of >= 3 tries (state -> goal: misses/tries) |",
            "|---|---:|---:|---:|---|",
        ]
        for initialization in ("50-50", "60-40"):
            figure, axes = plt.subplots(
                2 * len(gammas), 1, figsize=(12, 3 * len(gammas)), squeeze=False
            )
            for row, gamma in enumerate(gammas):
                mine = [
                    r
                    for r in results
                    if r["initialization"] == initialization and r["gamma"] == gamma
                ]
                for offset, key in enumerate(("tries", "values")):
                    _StackedBars(
                        axes[2 * row + offset, 0],
                        np.array([r[key][0] for r in mine]),
                        f"{initialization}, gamma {gamma}: {key} per state-action, "
                        f"{len(mine)} runs stacked",
                    )
                for r in mine:
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
            figure.tight_layout()
            figure.savefig(output / f"7.2i_{initialization}.png", dpi=80)
        return header + lines
    if experiment == "7.4.1":
        unreliable = np.array(results["unreliable"], dtype=int)
        risky = {(results["action_state"][sa], results["action_goal"][sa]) for sa in unreliable}
        figure, axis = plt.subplots(figsize=(12, 4))
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
        for offset, trained in enumerate(("moving_box", "no_box")):
            r = results[trained]
            axis.bar(
                np.arange(len(r["reliability"])) + 0.4 * offset,
                r["reliability"],
                width=0.4,
                label=f"trained: {trained}",
            )
            crossing = sum(
                any(step in risky for step in zip(path, path[1:])) for path in r["plans"]
            )
            episodes = r["episodes"] or [dict(actions=0, failed=0, tried=[])]
            lines.append(
                f"| {trained} | {crossing} of {len(r['plans'])} | {len(r['episodes'])} | "
                f"{np.mean([e['actions'] for e in episodes]):.2f} | "
                f"{np.mean([e['failed'] for e in episodes]):.2f} | "
                f"{np.mean([bool(set(e['tried']) & set(unreliable)) for e in episodes]):.0%} | "
                f"{r.get('penetrating_steps', 0)} |"
            )
        for sa in unreliable:
            axis.axvspan(sa - 0.3, sa + 0.7, color="red", alpha=0.15)
        axis.set_xlabel("state-action (unreliable ones shaded)")
        axis.set_ylabel("share of tries reaching the goal")
        axis.legend()
        figure.tight_layout()
        figure.savefig(output / "7.4.1_moving_box.png", dpi=80)
        return header + lines
    figure, axes = plt.subplots(3, 1, figsize=(12, 8))
    for axis, name, tries in zip(axes, results["agents"], results["tries"]):
        axis.bar(np.arange(len(tries)), tries)
        axis.set_title(f"{name}: tries per state-action")
    figure.tight_layout()
    figure.savefig(output / "7.4_three_agents.png", dpi=80)
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
        from scipy.stats import spearmanr

        lines.append(
            f"- {name}: hand-table contact (samples every 0.1 s with a hand inside a field with "
            f"the table) during {contacts.sum()} samples; the 20 most-tried state-actions "
            f"({100 * tries[top].sum() / tries.sum():.0f} % of the tries) hold "
            f"{100 * contacts[top].sum() / max(contacts.sum(), 1):.0f} % of them; rank "
            f"correlation of tries and contact samples per state-action: "
            f"{spearmanr(tries, contacts).statistic:.2f}; state-actions with contact: "
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


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        "--experiment", choices=["7.1", "7.2", "7.2i", "7.3", "7.4", "7.4.1"], required=True
    )
    parser.add_argument("--output", default="results/ch7")
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument(
        "--transitions",
        type=int,
        default=None,
        help="7.2: per run (default 2500); 7.3: per lattice (default: the "
        "source's 14,597 and 26,963); 7.4: in all (default 18,000)",
    )
    argv = sys.argv[1:] if argv is None else argv
    args = parser.parse_args(argv)
    output = pathlib.Path(args.output)
    output.mkdir(parents=True, exist_ok=True)
    if args.experiment == "7.1":
        results = RunHypercube(output, args.runs)
    elif args.experiment == "7.2":
        results = RunCoverage(output, args.transitions or 2500, args.runs)
    elif args.experiment == "7.2i":
        results = RunInitializations(output, args.runs)
    elif args.experiment == "7.3":
        results = RunRank4(output, args.transitions)
    elif args.experiment == "7.4":
        results = RunThreeAgents(output, args.transitions or 18000)
    else:
        results = RunDynamicPlanning(output, args.transitions or 1000, args.runs)
    table = _Plots(output, args.experiment, results)
    report = output / f"report_{args.experiment}.md"
    report.write_text(
        f"# Experiment {args.experiment}\n\n`python -m mobee_drake.planning."
        f"experiments {' '.join(argv)}`\n\n" + "\n".join(table) + "\n"
    )
    print(report.read_text())


if __name__ == "__main__":
    main()
