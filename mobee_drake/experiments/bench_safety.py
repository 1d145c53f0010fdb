"""Benchmark: can a client push the robot through an obstacle? MoBeE's safety guarantee under
saturated client forces (docs/mobee.md, "The safety guarantee").

A client's channels all push one marker along a direction, far beyond MoBeE's squash maxima:
the attractor (the scenario's), a configuration-space force ``c J^T u`` (eq. 5.9) and a workspace
force ``f u`` on the marker (eq. 5.10), with c = f = 1000.

- ``scenes``: fixed pushes into a table, a ball and the robot's own body, for the kinematic robot
  and the dynamic robot's three control modalities, with MoBeE's safety barrier on and off;
- ``babbling``: ``motor_babbling`` (random attractors every 4 s above a table) with the push's
  direction drawn anew every second, for ``--seconds`` (600: ten simulated minutes), beside the
  same run without client forces.

Each row: the closest approach of the robot's solids to the obstacle and to itself, and the
control periods in which solid geometry penetrated, with the deepest penetration.

Run: ``mobee-drake bench safety [--seconds 600] [--part scenes babbling]``.
"""

import dataclasses as dc

import numpy as np
from pydrake.systems.framework import BasicVector, LeafSystem

from mobee_drake.experiments.arguments import CommandParser, PositiveFloat
from mobee_drake.scenario import LoadScenario, Scenario
from mobee_drake.station.builder import MakeMobeeStation
from mobee_drake.station.parts import ClientPorts, StationParts
from mobee_drake.station.runner import RunStation, RunSummary

# Far beyond every squash maximum (20-40): the client's forces are saturated.
PUSH = 1000.0


class SaturatedPush(LeafSystem):
    """Pushes one marker along a unit direction u with a configuration-space force
    ``PUSH J^T u`` and a workspace force ``PUSH u``; with ``every`` > 0 it draws u anew,
    uniformly on the sphere, every ``every`` seconds (u is its discrete state; the k-th draw is
    seeded by ``(seed, k)``, so that every context draws the same directions).

    .. pydrake_system::

        name: SaturatedPush
        input_ports:
        - marker_jacobians
        output_ports:
        - config_force
        - marker_forces
    """

    def __init__(
        self,
        *,
        num_joints: int,
        num_markers: int,
        marker: int,
        direction,
        every: float = 0.0,
        seed: int = 0,
    ):
        super().__init__()
        self._n, self._m, self._marker = num_joints, num_markers, marker
        u = np.asarray(direction, dtype=float)
        self._jacobians = self.DeclareVectorInputPort(
            "marker_jacobians", 3 * num_markers * num_joints
        )
        self._u = self.DeclareDiscreteState(BasicVector(u / np.linalg.norm(u)))
        self.DeclareVectorOutputPort(
            "config_force",
            num_joints,
            self._CalcConfigForce,
            prerequisites_of_calc={self._jacobians.ticket(), self.discrete_state_ticket(self._u)},
        )
        self.DeclareVectorOutputPort(
            "marker_forces",
            3 * num_markers,
            self._CalcMarkerForces,
            prerequisites_of_calc={self.discrete_state_ticket(self._u)},
        )
        self._every, self._seed = every, seed
        if every > 0:
            self.DeclarePeriodicDiscreteUpdateEvent(every, every, self._Draw)

    def _Direction(self, context) -> np.ndarray:
        return context.get_discrete_state(self._u).value()

    def _Draw(self, context, discrete_state) -> None:
        draw = round(context.get_time() / self._every)
        u = np.random.default_rng([self._seed, draw]).normal(size=3)
        discrete_state.get_mutable_vector(self._u).SetFromVector(u / np.linalg.norm(u))

    def _CalcConfigForce(self, context, output) -> None:
        J = self._jacobians.Eval(context).reshape(self._m, 3, self._n)[self._marker]
        output.SetFromVector(PUSH * self._Direction(context) @ J)

    def _CalcMarkerForces(self, context, output) -> None:
        forces = np.zeros((self._m, 3))
        forces[self._marker] = PUSH * self._Direction(context)
        output.SetFromVector(forces.ravel())


@dc.dataclass
class Scene:
    """A scenario's overrides and the push: on a marker, along a direction (world)."""

    name: str
    overrides: str
    marker: str
    direction: tuple[float, float, float]
    obstacle: str


# The shipped reach_around_ball (the right palm at (-0.31, 0.14, 0.01), a table whose top is at
# z = -0.15, a ball of 4 cm at (-0.33, 0.08, -0.05)), pushed three ways.
SCENES = (
    Scene("table", "{objects: [{name: table, shape: !Box {size: [0.5, 0.9, 0.04]}, "
          "position: [-0.38, 0.0, -0.17]}]}", "r_palm", (0.0, 0.0, -1.0), "table"),
    Scene("ball", "{}", "r_palm", (-0.02, -0.06, -0.06), "ball"),
    Scene("self", "{objects: []}", "r_palm", (0.5, -1.0, -0.5), "(self)"),
)  # fmt: skip
MOVERS = {
    "kinematic": "!Kinematic {}",
    "position": "!Dynamic {control: position}",
    "velocity": "!Dynamic {control: velocity}",
    "force": "!Dynamic {control: force}",
}


def PushedRun(
    scenario: Scenario,
    *,
    marker: str,
    direction,
    every: float = 0.0,
    push: bool = True,
) -> RunSummary:
    """Runs ``scenario`` with its own client, plus (with ``push``) a :class:`SaturatedPush` on
    ``marker``; returns the run's summary."""

    def ClientAndPush(parts: StationParts) -> ClientPorts:
        client = scenario.attractor.AddToBuilder(parts)
        if not push:
            return client
        mobee = parts.mobee
        adversary = parts.builder.AddNamedSystem(
            "saturated_push",
            SaturatedPush(
                num_joints=len(mobee.joints),
                num_markers=len(mobee.marker_names),
                marker=mobee.marker_index(marker),
                direction=direction,
                every=every,
                seed=parts.random_seed,
            ),
        )
        parts.builder.Connect(
            mobee.GetOutputPort("marker_jacobians"), adversary.GetInputPort("marker_jacobians")
        )
        return dc.replace(
            client,
            config_force=adversary.GetOutputPort("config_force"),
            marker_forces=adversary.GetOutputPort("marker_forces"),
        )

    station = MakeMobeeStation(scenario, prebuild_callback=ClientAndPush)
    return RunStation(station, scenario.duration, simulator_config=scenario.simulator_config)


# MoBeE's constants under test, as a scenario's YAML tags them (mobee_drake/mobee/params.py).
PRESETS = {"defaults": "!MobeeParams", "dissertation": "!Dissertation"}


def SceneRun(
    scene: Scene,
    mover: str,
    *,
    barrier: bool = True,
    seconds: float = 4.0,
    preset: str = "defaults",
) -> RunSummary:
    """One fixed push of ``scene`` on the robot ``mover`` (a key of MOVERS), with MoBeE's
    constants ``preset`` (a key of PRESETS)."""
    scenario = LoadScenario(
        "reach_around_ball",
        [
            scene.overrides,
            f"{{mover: {MOVERS[mover]}, duration: {seconds}, data_log: {{enabled: false}}, "
            f"mobee: {PRESETS[preset]} {{barrier: {{enabled: {str(barrier).lower()}}}}}}}",
        ],
    )
    return PushedRun(scenario, marker=scene.marker, direction=scene.direction)


def _Row(label: str, summary: RunSummary, obstacle: str) -> str:
    safety = summary.safety

    def Closest(name: str) -> str:
        value = safety.closest_approach.get(name)
        return "-" if value is None else f"{1000 * value:+.1f}"

    return (
        f"| {label} | {Closest(obstacle)} | {Closest('(self)')} | {safety.penetrating_steps} | "
        f"{1000 * safety.deepest_penetration:.1f} |"
    )


def main(argv=None) -> None:
    parser = CommandParser(prog="mobee-drake bench safety", description=__doc__)
    parser.add_argument(
        "--seconds", type=PositiveFloat, default=600.0, help="simulated time of the babbling runs"
    )
    parser.add_argument(
        "--part",
        nargs="*",
        choices=["scenes", "babbling"],
        default=["scenes", "babbling"],
        help="which parts to run",
    )
    parser.add_argument(
        "--preset", choices=sorted(PRESETS), default="defaults", help="MoBeE's constants (scenes)"
    )
    args = parser.parse_args(argv)
    header = (
        "| run | closest to the obstacle (mm) | closest to itself (mm) | penetrating periods "
        "| deepest (mm) |\n|---|---:|---:|---:|---:|"
    )
    if "scenes" in args.part:
        print(
            f"Saturated pushes (c = f = {PUSH:g}) for 4 s, MoBeE's {args.preset}, barrier off "
            f"and on:\n{header}"
        )
        for scene in SCENES:
            for mover in MOVERS:
                for barrier in (False, True):
                    summary = SceneRun(scene, mover, barrier=barrier, preset=args.preset)
                    label = f"{scene.name}, {mover}, barrier {'on' if barrier else 'off'}"
                    print(_Row(label, summary, scene.obstacle), flush=True)
    if "babbling" in args.part:
        print(f"\nmotor_babbling for {args.seconds:g} s, kinematic robot:\n{header}")
        scenario = LoadScenario(
            "motor_babbling", f"{{duration: {args.seconds}, data_log: {{enabled: false}}}}"
        )
        for label, push in (("no client forces", False), ("random saturated pushes", True)):
            summary = PushedRun(
                scenario, marker="r_palm", direction=(0, 0, -1), every=1.0, push=push
            )
            print(_Row(label, summary, "table"), flush=True)


if __name__ == "__main__":
    main()
