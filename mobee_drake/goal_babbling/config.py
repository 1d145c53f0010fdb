"""Typed, serialisable configuration of SAGG-RIAC and its baselines on the planar arm.

Defaults are the values of Baranes & Oudeyer (IROS 2010), Sec. III-IV, where the paper gives one.
Where the paper is silent the value is our choice; every such field says "(our choice)" in its
comment and is listed in docs/saggriac.md.
"""

import dataclasses
import json
import math

from pydrake.common.yaml import yaml_load_typed


@dataclasses.dataclass
class ArmConfig:
    """The planar arm of Sec. III-C and IV-A.

    Attributes:
        num_joints: n, revolute joints in a plane (paper: 15).
        total_length: Sum of the link lengths (paper: 50 units); all links have the same length (our
            choice).
        joint_limit: Each relative joint angle is clipped to [-joint_limit, joint_limit] rad (our
            choice: pi).
        sensor_noise_std: Standard deviation of Gaussian noise added to each observed end-effector
            coordinate (paper: none; 0 disables it).
    """

    num_joints: int = 15
    total_length: float = 50.0
    joint_limit: float = math.pi
    sensor_noise_std: float = 0.0


EXPLORATION_TRIGGERS = ("task", "model")
SPLIT_CRITERIA = ("difference", "weighted")
REGION_MEASURES = ("progress", "variance")
ACTUATOR_READINGS = ("walk", "set")


@dataclasses.dataclass
class LowLevelConfig:
    """The SSA-like low level of Sec. III-D and the local models of Sec. III-B.

    Attributes:
        velocity: v, desired end-effector displacement per reaching micro-action (paper: 0.5
            units/movement).
        exploration_actions: q, random micro-actions in one exploration phase (paper: 20 in exp. 1,
            100 in exp. 2).
        exploration_joint_step: Exploration micro-actions draw each joint step uniformly in
            [-exploration_joint_step, exploration_joint_step] rad (our choice: 0.01 rad, which moves
            the tip of the straight arm by about v). ACTUATOR-Random and ACTUATOR-RIAC use the same
            box.
        max_joint_step: A reaching micro-action J^+ dx is scaled down so that no joint moves more
            than this (our choice: 0.05 rad), which keeps micro-actions small near singular Jacobian
            estimates.
        error_threshold: eps_max; an exploration phase follows a reaching micro-action whose
            performed displacement differs from the desired one by more than this (our choice: 0.1
            units = v / 5, from a pilot on seed 100, see docs/saggriac.md).
        num_neighbours: Size of the neighbourhood in theta-space used to estimate J (our choice: 30
            = 2n, the dimension of (theta, dtheta), from the same pilot).
        neighbour_search_eps: Approximate nearest neighbours, as the paper's ANN [18]: the k-d tree
            search may return neighbours up to (1 + eps) times farther than the exact ones (our
            choice: 1.0, for speed in 15 dimensions; 0 is exact).
        timeout_per_unit: The timeout of a (sub)goal attempt is ceil(timeout_per_unit * D(x_start,
            x_g) / v) + timeout_explorations * q micro-actions, exploration included (our choice:
            2).
        timeout_explorations: See timeout_per_unit (our choice: 1).
        exploration_trigger: What starts an exploration phase after a reaching micro-action:
            "task" (the paper, Sec. III-D-1: the performed tip step differs from the desired one by
            more than eps_max) or "model" (an option of ours: the performed tip step differs from
            the local model's prediction J dtheta by more than eps_max, so a desired step the arm
            cannot make, as against the workspace boundary, does not start one).
        stall_steps: An option of ours; 0 (the paper) disables it. Otherwise a reaching attempt
            ends once this many reaching micro-actions in a row have not brought the tip closer to
            the (sub)goal than it has been in the attempt by at least stall_progress; the check
            comes before the exploration phase the last of them would start.
        stall_progress: See stall_steps (our choice when enabled: 0.05 units = v / 10).
    """

    velocity: float = 0.5
    exploration_actions: int = 20
    exploration_joint_step: float = 0.01
    max_joint_step: float = 0.05
    error_threshold: float = 0.1
    num_neighbours: int = 30
    neighbour_search_eps: float = 1.0
    timeout_per_unit: float = 2.0
    timeout_explorations: int = 1
    exploration_trigger: str = "task"
    stall_steps: int = 0
    stall_progress: float = 0.05

    def __post_init__(self):
        if self.exploration_trigger not in EXPLORATION_TRIGGERS:
            raise ValueError(
                f"exploration_trigger must be one of {EXPLORATION_TRIGGERS}, "
                f"got {self.exploration_trigger!r}"
            )
        if self.stall_steps < 0 or self.stall_progress < 0:
            raise ValueError(
                f"stall_steps and stall_progress must be >= 0, got {self.stall_steps} and "
                f"{self.stall_progress}"
            )


@dataclasses.dataclass
class InterestConfig:
    """Competence, interest and region splitting of Sec. II-D.

    Attributes:
        max_region_goals: g_max; a region holding more goals is split (paper: 50).
        window: zeta, the sliding window of eq. 2 (our choice: 20).
        min_child_goals: Each half of a split holds at least this many goals (our choice: 10 = zeta
            / 2).
        mode_probabilities: p_1, p_2, p_3 of the three goal-selection modes (paper: 0.7, 0.2, 0.1).
        competence_tolerance: eps_C < 0; a goal counts as reached when C > eps_C (our choice: -0.05,
            i.e. within 5 % of the starting distance).
        min_competence: min_C, the lowest competence (our choice: -1, no better than not moving).
        split_criterion: How a region's cut is chosen among the candidates: "difference" (the
            paper, Sec. II-D-3: the largest |interest(lower) - interest(upper)|) or "weighted"
            (explauto's tree: the largest |L| |G| |interest(L) - interest(G)|, |L| and |G| the
            goals on each side, which favours balanced cuts over ones judged on few noisy
            competences).
    """

    max_region_goals: int = 50
    window: int = 20
    min_child_goals: int = 10
    mode_probabilities: list[float] = dataclasses.field(default_factory=lambda: [0.7, 0.2, 0.1])
    competence_tolerance: float = -0.05
    min_competence: float = -1.0
    split_criterion: str = "difference"
    region_measure: str = "progress"

    def __post_init__(self):
        if self.split_criterion not in SPLIT_CRITERIA:
            raise ValueError(
                f"split_criterion must be one of {SPLIT_CRITERIA}, got {self.split_criterion!r}"
            )
        if self.region_measure not in REGION_MEASURES:
            raise ValueError(
                f"region_measure must be one of {REGION_MEASURES}, got {self.region_measure!r}"
            )
        if self.window < 2:
            raise ValueError(f"window (zeta) must be at least 2, got {self.window}")


@dataclasses.dataclass
class EvaluationConfig:
    """The evaluation of Sec. IV-B (Fig. 4-5).

    Attributes:
        num_test_goals: Test goals uniform in the reachable half-disc x >= 0, |x| <= total length
            (paper: 100); even-numbered ones start from rest, odd-numbered ones from where the
            previous test reach ended.
        num_test_configurations: Test joint configurations for the forward-model error, in each
            of its two sets (paper: 100). The main set (issue 23) covers the reachable area: the
            postures that reach goals drawn uniformly (by area) in the reachable half-disc, found
            from rest by the low level's own controller (straight-line tip steps of v, J^+ with
            the same joint-step cap) driven by the arm's true Jacobian (our choice: the posture
            an ideally learnt inverse model would use). The near-rest set is below.
        test_joint_range: The near-rest test configurations (a sensitivity set since issue 23)
            draw each relative joint angle uniformly in [-test_joint_range, test_joint_range] rad
            (our choice: 0.3).
        reached_distance: A test goal counts as reached when the test reach ends this close to it
            (our choice: 1 unit, 2 % of the arm's length).
        num_checkpoints: Evaluations at equally spaced time steps after step 0 (our choice: 20).
        tolerance: A test reach stops once the tip is this close to the goal (our choice: 0.05
            units).
        test_set_seed: Seed of the test set, shared by all learners and seeds (our choice: 12345).
    """

    num_test_goals: int = 100
    num_test_configurations: int = 100
    test_joint_range: float = 0.3
    reached_distance: float = 1.0
    num_checkpoints: int = 20
    tolerance: float = 0.05
    test_set_seed: int = 12345


@dataclasses.dataclass
class ActuatorConfig:
    """How the actuator-space baselines act (the paper does not say how R-IAC acts given the arm's
    state; both readings are ours).

    Attributes:
        reading: "walk": the arm keeps its state; each step adds a small joint change (ACTUATOR-
            Random: uniform in the exploration box; ACTUATOR-RIAC: uniform in the joint-change box
            of a region chosen among those holding the current angles), back to rest every "max"
            steps. "set": each step first sets the joints to a posture drawn in the posture box,
            for free as the rest reset is (ACTUATOR-Random: uniform; ACTUATOR-RIAC: uniform in the
            chosen region of (theta, dtheta), any region), then makes the small joint change; the
            arm cannot drift.
        posture_range: Half-width (rad) of the posture box of the "set" reading (our choice: 0.3,
            about the envelope of ACTUATOR-Random's walks: three times the per-joint standard
            deviation 0.01 sqrt(342 / 3) = 0.107 rad reached at the end of a 342-step episode).
    """

    reading: str = "walk"
    posture_range: float = 0.3

    def __post_init__(self):
        if self.reading not in ACTUATOR_READINGS:
            raise ValueError(f"reading must be one of {ACTUATOR_READINGS}, got {self.reading!r}")
        if not 0.0 < self.posture_range <= math.pi:
            raise ValueError(f"posture_range must be in (0, pi], got {self.posture_range}")


@dataclasses.dataclass
class GoalBabblingConfig:
    """Everything one learning run needs.

    Attributes:
        goal_space_low: Lower corner of S' (paper, exp. 1: (0, -50); exp. 2: (0, -150)).
        goal_space_high: Upper corner of S' (paper, exp. 1: (50, 50); exp. 2: (150, 150)).
        num_subgoals: l, subgoals on the way to each goal, the last one being the goal (paper: 5).
        reset_every_attempts: r, the arm returns to rest every r goal attempts (paper: 2).
        budget: Micro-actions (time steps) of the run (paper: 50,000 in exp. 1, 200,000 in exp. 2).
        seed: Seed of the learner's own numpy Generator.
        arm: Arm parameters.
        low_level: Low-level parameters.
        interest: High-level parameters.
        evaluation: Evaluation parameters.
        actuator: How the actuator-space baselines act.
    """

    goal_space_low: list[float] = dataclasses.field(default_factory=lambda: [0.0, -50.0])
    goal_space_high: list[float] = dataclasses.field(default_factory=lambda: [50.0, 50.0])
    num_subgoals: int = 5
    reset_every_attempts: int = 2
    budget: int = 50_000
    seed: int = 0
    arm: ArmConfig = dataclasses.field(default_factory=ArmConfig)
    low_level: LowLevelConfig = dataclasses.field(default_factory=LowLevelConfig)
    interest: InterestConfig = dataclasses.field(default_factory=InterestConfig)
    evaluation: EvaluationConfig = dataclasses.field(default_factory=EvaluationConfig)
    actuator: ActuatorConfig = dataclasses.field(default_factory=ActuatorConfig)

    def ActuatorResetPeriod(self) -> int:
        """Time steps between resets of the actuator-space baselines (Sec. IV-B-1).

        The paper resets them every "max" steps, the steps needed to reach consecutively the two
        most distant reachable positions. We read this as: from rest (L, 0) to (0, L) (distance L
        sqrt 2), then to (0, -L) (distance 2 L), at v per step.

        Returns:
            ceil((sqrt(2) + 2) L / v).
        """
        length = self.arm.total_length
        return math.ceil((math.sqrt(2.0) + 2.0) * length / self.low_level.velocity)


def Experiment1Config(seed: int = 0, budget: int = 50_000) -> GoalBabblingConfig:
    """Sec. IV-B-1: S' = [0, 50] x [-50, 50], q = 20, 50,000 movements.

    Args:
        seed: Learner seed.
        budget: Micro-actions.

    Returns:
        The configuration.
    """
    return GoalBabblingConfig(
        goal_space_low=[0.0, -50.0],
        goal_space_high=[50.0, 50.0],
        budget=budget,
        seed=seed,
        low_level=LowLevelConfig(exploration_actions=20),
    )


def Experiment2Config(seed: int = 0, budget: int = 200_000) -> GoalBabblingConfig:
    """Sec. IV-B-2: S' = [0, 150] x [-150, 150], q = 100, 200,000 time steps.

    Args:
        seed: Learner seed.
        budget: Micro-actions.

    Returns:
        The configuration.
    """
    return GoalBabblingConfig(
        goal_space_low=[0.0, -150.0],
        goal_space_high=[150.0, 150.0],
        budget=budget,
        seed=seed,
        low_level=LowLevelConfig(exploration_actions=100),
    )


def ConfigToDict(config: GoalBabblingConfig) -> dict:
    """Plain JSON-compatible dict of a configuration."""
    return dataclasses.asdict(config)


def ConfigFromDict(data: dict) -> GoalBabblingConfig:
    """Inverse of :func:`ConfigToDict` by Drake's YAML loader (JSON is YAML); missing fields take
    their defaults.

    Raises:
        RuntimeError: naming a field the configuration does not have.
        ValueError: naming a value no run could use (see CheckConfig).
    """
    config = yaml_load_typed(schema=GoalBabblingConfig, data=json.dumps(data))
    CheckConfig(config)
    return config


def CheckConfig(config: GoalBabblingConfig) -> None:
    """Runs the checks of every part with choices (the loader sets fields one by one, after
    construction).

    Raises:
        ValueError: in one line, naming the field and the value.
    """
    for part in (config.low_level, config.interest, config.actuator):
        part.__post_init__()
