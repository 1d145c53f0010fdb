"""The arms the experiments beyond the sources run on (issue 38): the iCub's right shoulder and
elbow (ch. 7-8) and the Katana's first four joints among its shipped scenario's obstacles (App.
B). Each names its scenario's robot, the joints an agent or the reach learner moves, the marker a
reach forces toward its target (ch. 8.2), the world's objects and the reach targets (ch. 8.3).

The iCub's targets are the source's grid (``models/reach_targets.yaml``: each axis's 20th, 50th
and 80th percentiles of the palm's positions more than 10 cm in front of the robot over random
valid poses). An arm without such a file gets the same rule over its marker's positions at its
valid configurations (:func:`ReachTargets`), in front meaning along the arm's ``front``: for the
Katana, the side its home posture reaches to (+x), so that the grid lies beside its base and
not through the column its arm rises from.
"""

import dataclasses as dc
import pathlib

import numpy as np

from mobee_drake.experiments.battery import Job, RunFolder
from mobee_drake.ngik.kinematic_model import KinematicModel
from mobee_drake.planning.state_space import StateActionSpace
from mobee_drake.planning.supervisor import RoadmapStateSpace
from mobee_drake.reaching.targets import LoadTargetGrid, TargetGrid
from mobee_drake.robots.icub import RIGHT_SHOULDER_ELBOW_JOINTS, IcubConfig
from mobee_drake.robots.zero_position import ZeroPositionConfig
from mobee_drake.scenario import LoadScenario
from mobee_drake.trm.configuration import BuildConfigurationRoadmap

# Valid configurations drawn for a measure or a target grid (uniform draws, then filtered).
VALID_SAMPLES = 2000
# Ch. 8.3's grid: each axis's levels are these percentiles of the marker's positions.
TARGET_PERCENTILES = (20, 50, 80)
TARGET_RADIUS = 0.05  # (m; ch. 8.3's 10 cm spheres)
FRONT_DISTANCE = 0.1  # (m; the marker's positions this far in front count)


@dc.dataclass(frozen=True)
class Arm:
    """A robot's arm: the scenario's robot, the moved joints, the reaching marker, the world's
    objects, and the reach targets' file or, without one, the direction in front of the robot
    (world frame) for :func:`ReachTargets`'s rule."""

    robot: object
    joints: tuple[str, ...]
    marker: str
    objects: tuple = ()
    targets: str = ""
    front: tuple[float, float, float] = (1.0, 0.0, 0.0)


def Arms() -> dict[str, Arm]:
    """The arms by name: the iCub's right shoulder and elbow (ch. 7-8), and the Katana's first
    four joints among the shipped Katana scenario's obstacles, whose states inside them are
    never entered, reaching with its wrist."""
    joints = tuple(RIGHT_SHOULDER_ELBOW_JOINTS)
    return {
        "icub": Arm(
            IcubConfig(controlled_joints=list(joints)),
            joints,
            "r_palm",
            targets="package://mobee_drake/reach_targets.yaml",
        ),
        "katana": Arm(
            ZeroPositionConfig(file="katana.xml"),
            ("arm_0", "arm_1", "arm_2", "arm_3"),
            "wrist",
            tuple(LoadScenario("katana").objects),
        ),
    }


def _Poses(arm: Arm, fractions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """At each configuration of ``fractions`` ((k, joints): fractions of each joint's range,
    the other joints at home), the arm's marker position ((k, 3), m) and whether it is valid
    (within the limits, every constraint clause satisfied, no collision, objects included)."""
    model = KinematicModel(arm.robot, list(arm.objects))
    columns = [model.JointIndex(j) for j in arm.joints]
    lower, upper = model.lower[columns], model.upper[columns]
    marker = model.MarkerIndex(arm.marker)
    positions, valid = [], []
    for f in fractions:
        q = model.home.copy()
        q[columns] = lower + f * (upper - lower)
        pose = model.Evaluate(q)
        positions.append(pose.marker_positions[marker])
        valid.append(model.IsValid(q) and not pose.collision_pairs)
    return np.reshape(positions, (-1, 3)), np.array(valid, dtype=bool)


def _ValidPoses(arm: Arm, count: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(the valid configurations among ``count`` uniform draws, as fractions of each joint's
    range (see :func:`_Poses`); the marker's position at each)."""
    draws = np.random.default_rng(seed).random((count, len(arm.joints)))
    positions, valid = _Poses(arm, draws)
    return draws[valid], positions[valid]


def ValidConfigurations(arm: Arm, count: int = VALID_SAMPLES, seed: int = 0) -> np.ndarray:
    """(k, joints): the valid configurations of ``arm``'s joints (see :func:`_Poses`) among
    ``count`` uniform draws, as fractions of each joint's range."""
    return _ValidPoses(arm, count, seed)[0]


def TargetGaps(arm: Arm, centres: np.ndarray) -> np.ndarray:
    """Per reach target, the distance (m) from it to the nearest marker position of a valid
    one of the states' ``centres`` ((k, joints), fractions of range): how near a pre-reach state
    can put the marker before the reach."""
    positions, valid = _Poses(arm, centres)
    targets = ReachTargets(arm).Centres()
    return np.linalg.norm(targets[:, None] - positions[valid][None], axis=2).min(axis=1)


def ReachTargets(arm: Arm) -> TargetGrid:
    """The arm's reach targets: its file's grid, or the 3 x 3 x 3 grid of each axis's
    :data:`TARGET_PERCENTILES` of the marker's positions (rounded to 1 cm) at the arm's valid
    configurations (:func:`ValidConfigurations`, seed 0) that put it more than
    :data:`FRONT_DISTANCE` along ``front``."""
    if arm.targets:
        return LoadTargetGrid(arm.targets)
    _, positions = _ValidPoses(arm, VALID_SAMPLES, seed=0)
    positions = positions[positions @ np.asarray(arm.front) > FRONT_DISTANCE]
    levels = np.round(np.percentile(positions, TARGET_PERCENTILES, axis=0), 2)
    x, y, z = (levels[:, axis].tolist() for axis in range(3))
    return TargetGrid(radius=TARGET_RADIUS, x=x, y=y, z=z)


def RoadmapJobName(robot: str) -> str:
    """The battery job that builds ``robot``'s roadmap (:func:`RoadmapJob`)."""
    return f"{robot}_roadmap"


def RoadmapFolder(runs: pathlib.Path, robot: str) -> pathlib.Path:
    """Where the battery whose runs are in ``runs`` keeps ``robot``'s roadmap."""
    return runs / RoadmapJobName(robot) / "roadmap"


def RoadmapJobOf(robot: str, spacing: float, max_vertices: int) -> Job:
    """The battery's job that builds ``robot``'s roadmap (:func:`RoadmapJob`)."""
    return Job(
        RoadmapJobName(robot),
        RoadmapJob,
        dict(robot=robot, spacing=spacing, max_vertices=max_vertices),
        total=max_vertices,
    )


def RoadmapJob(run: RunFolder, *, robot: str, spacing: float, max_vertices: int) -> dict:
    """The battery job that builds a roadmap over ``robot``'s valid configurations
    (:func:`~mobee_drake.trm.configuration.BuildConfigurationRoadmap`, in ``run.path /
    "roadmap"``): a "trm" space."""
    arm = Arms()[robot]
    roadmap = BuildConfigurationRoadmap(
        arm.robot, list(arm.joints), spacing, max_vertices, objects=arm.objects,
        progress=run.Progress,
    )  # fmt: skip
    roadmap.Save(run.path / "roadmap")
    return dict(
        vertices=len(roadmap.q), edges=len(roadmap.edges), build_seconds=roadmap.build_seconds
    )


def RoadmapLines(roadmaps: dict[str, dict]) -> list[str]:
    """Report lines on the "trm" spaces (``roadmaps``: per robot, its :func:`RoadmapJob`'s
    result); none without any."""
    if not roadmaps:
        return []
    built = "; ".join(
        f"{robot}, {r['vertices']} states and {r['edges']} edges, built in "
        f"{r['build_seconds']:.0f} s"
        for robot, r in roadmaps.items()
    )
    return ["", f"The trm spaces: {built}."]


def RoadmapSpace(arm: Arm, folder: str | pathlib.Path) -> StateActionSpace:
    """The state-action space of the roadmap saved in ``folder`` over ``arm``'s joints."""
    model = KinematicModel(arm.robot, list(arm.objects))
    return RoadmapStateSpace(
        str(folder), list(arm.joints), list(model.joints), model.lower, model.upper
    )
