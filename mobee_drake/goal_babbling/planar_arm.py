"""The n-joint planar arm of Baranes & Oudeyer (IROS 2010), Sec. III-C, controlled by joint
micro-actions.
"""

import numpy as np

from mobee_drake.goal_babbling.config import ArmConfig


def ForwardKinematics(joint_angles: np.ndarray, link_lengths: np.ndarray) -> np.ndarray:
    """X = f(theta) of a planar serial arm, relative joint angles, base at the origin (Sec. III-A).

    Link i points along the sum of joint angles 0..i, so theta = 0 is the straight arm along +x.

    Args:
        joint_angles: (..., n) relative joint angles in rad.
        link_lengths: (n,) link lengths.

    Returns:
        (..., 2) end-effector positions.
    """
    absolute_angles = np.cumsum(joint_angles, axis=-1)
    return np.stack(
        [np.cos(absolute_angles) @ link_lengths, np.sin(absolute_angles) @ link_lengths], axis=-1
    )


def LinkLengths(config: ArmConfig) -> np.ndarray:
    """N equal links of total length L (equal lengths: our choice; the paper gives n and L)."""
    return np.full(config.num_joints, config.total_length / config.num_joints)


class PlanarArm:
    """A planar arm whose state is its joint angles, moved by micro-actions dtheta in time steps.

    The learner sees only joint angles and (optionally noisy) end-effector positions; it never reads
    the link lengths or calls ForwardKinematics itself.
    """

    def __init__(self, config: ArmConfig, rng: np.random.Generator):
        """Builds the arm at rest (straight along +x).

        Args:
            config: Arm parameters.
            rng: Generator for the sensor noise (the learner's own).
        """
        self.config = config
        self.link_lengths = LinkLengths(config)
        self.rest_angles = np.zeros(config.num_joints)
        self._rng = rng
        self.joint_angles = self.rest_angles.copy()
        self.position = self._Observe()

    def _Observe(self) -> np.ndarray:
        position = ForwardKinematics(self.joint_angles, self.link_lengths)
        if self.config.sensor_noise_std > 0.0:
            position = position + self._rng.normal(0.0, self.config.sensor_noise_std, 2)
        return position

    def Reset(self) -> None:
        """Puts the arm back at rest without any planning (Sec. II-D-4)."""
        self.joint_angles = self.rest_angles.copy()
        self.position = self._Observe()

    def SetJointAngles(self, joint_angles: np.ndarray) -> None:
        """Puts the arm in a posture without any planning, as Reset does for the rest posture (the
        "set" reading of the actuator baselines); angles are clipped to the joint limits.

        Args:
            joint_angles: (n,) relative joint angles in rad.
        """
        limit = self.config.joint_limit
        self.joint_angles = np.clip(np.asarray(joint_angles, dtype=float), -limit, limit)
        self.position = self._Observe()

    def Move(self, joint_step: np.ndarray) -> np.ndarray:
        """Performs one micro-action; joints are clipped to their limits.

        Args:
            joint_step: (n,) desired change of the joint angles.

        Returns:
            (n,) the joint change actually performed.
        """
        limit = self.config.joint_limit
        new_angles = np.clip(self.joint_angles + joint_step, -limit, limit)
        performed = new_angles - self.joint_angles
        self.joint_angles = new_angles
        self.position = self._Observe()
        return performed
