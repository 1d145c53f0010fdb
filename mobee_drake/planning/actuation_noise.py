"""A stochastic robot for the MDP agents (issue 33): actuation noise on every transition.

The source's robot was stochastic (dissertation ch. 7.2.5 and 7.3: a state-action of the real
iCub does not always end in the same state), ours is not: a kinematic robot under MoBeE settles
where its attractor is. The model: a transition's commanded posture is its goal state's centre
plus independent Gaussian noise of standard deviation ``sd`` times each joint's range, clipped to
the joint limits, so the robot sometimes settles in a neighbouring state. On the rank-3 lattice,
whose centres are a quarter of the range apart, a joint sent to the middle level leaves its state
with probability 2 Phi(-0.125 / sd), to an end level (the limit clips the far side's noise)
Phi(-0.125 / sd): 1.2 % and 0.6 % at sd 0.05, 21 % and 11 % at sd 0.1; a state of 4 joints
changes when any of them does. The noise of one action is drawn from a
generator seeded with the run's seed, the agent's index and the action's start time in
milliseconds: the same run draws the same noise, and a run resumed from a checkpoint (which
keeps the time) continues exactly.
"""

import numpy as np


def NoisyPosture(
    centre: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    sd: float,
    seed: int,
    agent: int,
    started: float,
) -> np.ndarray:
    """``centre`` plus the actuation noise of the action started at ``started`` (s), clipped to
    [``lower``, ``upper``]; ``centre`` itself when ``sd`` is 0."""
    if sd == 0:
        return centre
    rng = np.random.default_rng([seed, agent, round(started * 1000)])
    noisy = centre + rng.normal(0.0, sd, len(centre)) * (upper - lower)
    return np.clip(noisy, lower, upper)


def ValidateNoise(sd: float) -> None:
    """Refuses a standard deviation that is negative, not finite, or a full range or more."""
    if not (np.isfinite(sd) and 0 <= sd < 1):
        raise ValueError(
            f"transition_noise must be in [0, 1) (a fraction of each joint's range), got {sd}"
        )
