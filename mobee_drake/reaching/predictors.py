"""Per state-action reward histories and their predictions (dissertation ch. 8.1-8.2).

Every state-action keeps a history ``H_{s,a}`` of the reach targets ``x*_i`` it was tried for,
the reward it was expected to give and the reward it gave (eq. 8.2). A prediction for a new target
weighs each past reward by ``1 / (1 + |x* - x*_i|)``:

- state transitions, eq. 8.1: ``sum w_i r_i / sum w_i``, and 0 with no history (eq. 8.3: no news
  is good news: a transition is expected to work, for no reward);
- reaches, eq. 8.5: ``(1 + sum w_i r_i) / (1 + sum w_i)``, optimistic both with no history and
  for targets far from every one tried (the rewards of eq. 8.4 lie in (0, 1]);
- intrinsic, eq. 8.7: eq. 8.5 over the past prediction errors ``e_i - r_i`` (eq. 8.6).
"""

import numpy as np

# The reward of a state transition that does not climb the value function (ch. 8.1).
FAILED_TRANSITION_REWARD = -10.0


def ReachReward(x: np.ndarray, target: np.ndarray) -> float:
    """Eq. 8.4: ``1 / (1 + |x - x*|)`` for the marker's final position ``x``."""
    return 1.0 / (1.0 + float(np.linalg.norm(np.asarray(x) - np.asarray(target))))


def TransitionReward(value_before: float, value_after: float) -> float:
    """Ch. 8.1: 0 when the transition climbed the value function, else the failure penalty."""
    return 0.0 if value_after > value_before else FAILED_TRANSITION_REWARD


def WeightedEstimate(target: np.ndarray, targets: np.ndarray, values: np.ndarray,
                     prior: float) -> float:
    """``(prior + sum w_i v_i) / (prior + sum w_i)`` with ``w_i = 1 / (1 + |x* - x*_i|)``;
    with ``prior`` 0 this is eq. 8.1 (0 with no history, eq. 8.3), with 1 eq. 8.5 and 8.7."""
    if len(values) == 0:
        return 1.0 if prior else 0.0
    weights = 1.0 / (1.0 + np.linalg.norm(targets - target, axis=1))
    return float((prior + weights @ values) / (prior + weights.sum()))


class RewardHistories:
    """The histories ``H_{s,a}`` (eq. 8.2) of every state-action, and the predictions from them.

    ``reaching[sa]`` says whether a state-action is a reach (eq. 8.5, 8.7) or a state transition
    (eq. 8.1).
    """

    def __init__(self, reaching: np.ndarray):
        self.reaching = np.asarray(reaching, dtype=bool)
        n = len(self.reaching)
        self._targets = [np.zeros((0, 3)) for _ in range(n)]
        self._estimates = [np.zeros(0) for _ in range(n)]
        self._rewards = [np.zeros(0) for _ in range(n)]

    def __len__(self) -> int:
        return len(self.reaching)

    def Copy(self) -> "RewardHistories":
        """An independent copy (records replace a history's arrays, never change them)."""
        twin = RewardHistories.__new__(RewardHistories)
        twin.reaching = self.reaching
        twin._targets, twin._estimates = list(self._targets), list(self._estimates)
        twin._rewards = list(self._rewards)
        return twin

    def History(self, state_action: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(targets, estimates, rewards) of one state-action, oldest first."""
        return (self._targets[state_action], self._estimates[state_action],
                self._rewards[state_action])

    def Predict(self, state_action: int, target) -> float:
        """The expected reward (eq. 8.1 for transitions, 8.5 for reaches)."""
        prior = 1.0 if self.reaching[state_action] else 0.0
        return WeightedEstimate(np.asarray(target, dtype=float), self._targets[state_action],
                                self._rewards[state_action], prior)

    def PredictIntrinsic(self, state_action: int, target) -> float:
        """The expected prediction error of a reach (eq. 8.7 over eq. 8.6)."""
        errors = self._estimates[state_action] - self._rewards[state_action]
        return WeightedEstimate(np.asarray(target, dtype=float), self._targets[state_action],
                                errors, 1.0)

    def Record(self, state_action: int, target, estimate: float, reward: float) -> None:
        """Appends ``{x*, e, r}`` to ``H_{s,a}`` (eq. 8.2)."""
        self._targets[state_action] = np.vstack([self._targets[state_action],
                                                  np.asarray(target, dtype=float)[None]])
        self._estimates[state_action] = np.append(self._estimates[state_action], estimate)
        self._rewards[state_action] = np.append(self._rewards[state_action], reward)
