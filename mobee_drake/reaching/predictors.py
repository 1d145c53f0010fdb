"""Per state-action reward histories and their predictions (dissertation ch. 8.1-8.2).

Every state-action keeps a history ``H_{s,a}`` of the reach targets ``x*_i`` it was tried for,
the reward it was expected to give and the reward it gave (eq. 8.2). A prediction for a new target
weighs each past reward by ``1 / (1 + |x* - x*_i|)``:

- state transitions, eq. 8.1: ``sum w_i r_i / sum w_i``, and 0 with no history (eq. 8.3: no news is
  good news: a transition is expected to work, for no reward). The formula as printed predicts a
  single record's reward for every target however far; the prose describes a prediction that fades
  with distance (8.1: after a failure the estimate is negative but small for targets far from it;
  8.4.4: far problems get a much smaller penalty than near ones). ``PredictorConfig.eq81`` chooses:
  ``printed`` (the default) or ``prose``, eq. 8.5's form with eq. 8.3's prior, ``sum w_i r_i / (1 +
  sum w_i)``: a prior record of reward 0 at weight 1, as eq. 8.5 has one of reward 1 (one -10 record
  predicts -10 w / (1 + w): -5 at its own target, -10 / 12 = -0.83 ten units away);
- reaches, eq. 8.5: ``(1 + sum w_i r_i) / (1 + sum w_i)``, optimistic both with no history and
  for targets far from every one tried (the rewards of eq. 8.4 lie in (0, 1]);
- intrinsic, eq. 8.7: eq. 8.5 over the past prediction errors ``e_i - r_i`` (eq. 8.6).

A stronger predictor, asked for in ch. 8.5 and 9.4.4 (``PredictorConfig(kind="gaussian_process")``):
Gaussian-process regression over the workspace with the same priors (0 for transitions, 1 for
reaches and their errors) as its mean, so it is optimistic far from experience as eq. 8.5 is, but
follows the data closely near it instead of averaging over every target ever tried (the failing
of eq. 8.1-8.7 that ch. 8.5 describes: one large reward soon predicted for all problems). The
kernel is squared-exponential, ``exp(-|x - x'|^2 / (2 l^2))``, with independent noise of
``noise_ratio`` times the signal variance per record; the posterior mean does not depend on the
signal variance. Records at the same target are pooled (their mean, with noise divided by their
count: exact for this model), so a history over the 27 grid targets is a 27-point GP however long
it is.

Distances in eq. 8.1-8.7 are counted in ``PredictorConfig.distance_unit`` (the source gives no
unit; metres by default). The unit sets how much the pre-reach state matters: a transition costs
the factor gamma = 0.9, so moving to reach from elsewhere pays only where eq. 8.4 predicts more
than 1/0.9 times the reward here; in metres the measured reaches' misses of 1.3-32.5 cm earn
0.755-0.987 (docs/reaching_history.md, issue 23).
"""

import dataclasses as dc

import numpy as np
from scipy.linalg import cho_factor, cho_solve

from mobee_drake.planning.value_iteration import VALUE_TIE

PREDICTORS = ("weighted", "gaussian_process")
# The readings of eq. 8.1 (see the module's docstring).
EQ81_READINGS = ("printed", "prose")


@dc.dataclass
class PredictorConfig:
    """Which predictor (eq. 8.1-8.7, or a Gaussian process) and the process's settings."""

    kind: str = "weighted"
    # The length (m) that counts as 1 in eq. 8.1-8.7 and in the reward of eq. 8.4.
    distance_unit: float = 1.0
    # The kernel's length scale (m) and the noise variance relative to the signal's.
    length_scale: float = 0.1
    noise_ratio: float = 0.25
    # Eq. 8.1 as printed, or as its prose describes it (one of EQ81_READINGS).
    eq81: str = "printed"

    def Validate(self) -> None:
        if self.kind not in PREDICTORS:
            raise ValueError(
                f"unknown reward predictor '{self.kind}'; predictors are " + ", ".join(PREDICTORS)
            )
        if self.eq81 not in EQ81_READINGS:
            raise ValueError(
                f"unknown reading of eq. 8.1 '{self.eq81}'; readings are "
                + ", ".join(EQ81_READINGS)
            )
        if not self.distance_unit > 0:
            raise ValueError(f"the predictor's distance_unit must be > 0, got {self.distance_unit}")
        if not (self.length_scale > 0 and self.noise_ratio > 0):
            raise ValueError(
                f"the predictor's length_scale and noise_ratio must be > 0, got "
                f"{self.length_scale} and {self.noise_ratio}"
            )


# The reward of a state transition that does not climb the value function (ch. 8.1).
FAILED_TRANSITION_REWARD = -10.0


def Closeness(a, b, unit: float = 1.0):
    """``1 / (1 + |a - b|)`` over the last axis, the distance counted in ``unit`` (m): the reward
    of eq. 8.4 and the weights of eq. 8.1, 8.5 and 8.7."""
    return 1.0 / (1.0 + np.linalg.norm(np.asarray(a) - np.asarray(b), axis=-1) / unit)


def ReachReward(x: np.ndarray, target: np.ndarray, unit: float = 1.0) -> float:
    """Eq. 8.4 for the marker's final position ``x``."""
    return float(Closeness(x, target, unit))


def TransitionReward(value_before: float, value_after: float) -> float:
    """Ch. 8.1: 0 when the transition climbed the value function, else the failure penalty;
    values equal but for rounding (``VALUE_TIE``) did not climb."""
    return 0.0 if value_after > value_before + VALUE_TIE else FAILED_TRANSITION_REWARD


def WeightedEstimate(
    target: np.ndarray,
    targets: np.ndarray,
    values: np.ndarray,
    prior: float,
    unit: float = 1.0,
    prior_weight: float | None = None,
) -> float:
    """``(c prior + sum w_i v_i) / (c + sum w_i)`` with ``w_i = 1 / (1 + |x* - x*_i|)``, the
    distance counted in ``unit`` (m), and ``prior`` with no history; the prior's weight ``c`` is
    ``prior_weight``, by default ``prior`` itself. With ``prior`` 0 this is eq. 8.1 as printed
    (0 with no history, eq. 8.3), with 1 eq. 8.5 and 8.7, with ``prior`` 0 at weight 1 eq. 8.1
    as its prose reads."""
    if len(values) == 0:
        return prior
    weight = prior if prior_weight is None else prior_weight
    weights = Closeness(targets, target, unit)
    return float((weight * prior + weights @ values) / (weight + weights.sum()))


class GaussianProcessFit:
    """The posterior mean of a GP with constant prior mean fitted to (targets, values)."""

    def __init__(
        self, targets: np.ndarray, values: np.ndarray, prior: float, config: PredictorConfig
    ):
        self.prior, self._scale = prior, 2.0 * config.length_scale**2
        unique, inverse, counts = np.unique(
            targets, axis=0, return_inverse=True, return_counts=True
        )
        means = np.bincount(inverse.ravel(), weights=values) / counts
        gram = self._Kernel(unique, unique) + np.diag(config.noise_ratio / counts)
        self._points = unique
        self._alpha = cho_solve(cho_factor(gram), means - prior)

    def _Kernel(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        squared = np.sum((a[:, None, :] - b[None, :, :]) ** 2, axis=2)
        return np.exp(-squared / self._scale)

    def __call__(self, target: np.ndarray) -> float:
        return float(self.prior + self._Kernel(target[None], self._points)[0] @ self._alpha)


class RewardHistories:
    """The histories ``H_{s,a}`` (eq. 8.2) of every state-action, and the predictions from them.

    ``reaching[sa]`` says whether a state-action is a reach (eq. 8.5, 8.7) or a state transition
    (eq. 8.1); ``predictor`` chooses the weighted averages of the source or a Gaussian process.
    """

    def __init__(self, reaching: np.ndarray, predictor: PredictorConfig | None = None):
        self.reaching = np.asarray(reaching, dtype=bool)
        self.predictor = predictor or PredictorConfig()
        self.predictor.Validate()
        n = len(self.reaching)
        self._targets = [np.zeros((0, 3)) for _ in range(n)]
        self._estimates = [np.zeros(0) for _ in range(n)]
        self._rewards = [np.zeros(0) for _ in range(n)]
        # Gaussian-process fits by (state-action, intrinsic?), dropped when a history grows.
        self._fits: dict[tuple[int, bool], GaussianProcessFit] = {}

    def _Estimate(
        self, state_action: int, target, values: np.ndarray, prior: float, intrinsic: bool
    ) -> float:
        target = np.asarray(target, dtype=float)
        if self.predictor.kind == "weighted" or len(values) == 0:
            prose = self.predictor.eq81 == "prose" and not self.reaching[state_action]
            return WeightedEstimate(
                target,
                self._targets[state_action],
                values,
                prior,
                self.predictor.distance_unit,
                prior_weight=1.0 if prose else None,
            )
        fit = self._fits.get((state_action, intrinsic))
        if fit is None:
            fit = GaussianProcessFit(self._targets[state_action], values, prior, self.predictor)
            self._fits[state_action, intrinsic] = fit
        return fit(target)

    def __len__(self) -> int:
        return len(self.reaching)

    def Copy(self) -> "RewardHistories":
        """An independent copy (records replace a history's arrays, never change them)."""
        twin = RewardHistories.__new__(RewardHistories)
        twin.reaching, twin.predictor, twin._fits = self.reaching, self.predictor, dict(self._fits)
        twin._targets, twin._estimates = list(self._targets), list(self._estimates)
        twin._rewards = list(self._rewards)
        return twin

    def Moved(self, new_index: np.ndarray, reaching: np.ndarray) -> "RewardHistories":
        """The histories renumbered for a reshaped space (ch. 9.4.5): state-action i's goes to
        ``new_index[i]`` (-1: dropped with its state-action); the new space's state-actions
        are ``reaching`` (a reach or not), those no old one moved to start empty."""
        moved = RewardHistories(reaching, self.predictor)
        for old, new in enumerate(new_index):
            if new >= 0:
                moved._targets[new] = self._targets[old]
                moved._estimates[new] = self._estimates[old]
                moved._rewards[new] = self._rewards[old]
        return moved

    def History(self, state_action: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(targets, estimates, rewards) of one state-action, oldest first."""
        return (
            self._targets[state_action],
            self._estimates[state_action],
            self._rewards[state_action],
        )

    def Records(self, state_action: int) -> tuple[np.ndarray, np.ndarray]:
        """``H_{s,a}``'s targets (n, 3) and rewards (n) so far."""
        return self._targets[state_action], self._rewards[state_action]

    def Predict(self, state_action: int, target) -> float:
        """The expected reward (eq. 8.1 for transitions, 8.5 for reaches)."""
        prior = self._Prior(state_action)
        return self._Estimate(state_action, target, self._rewards[state_action], prior, False)

    def _Prior(self, state_action: int) -> float:
        """A prediction's prior: eq. 8.5's 1 for a reach, eq. 8.1's 0 for a transition."""
        return float(self.reaching[state_action])

    def PredictEach(self, state_actions, target) -> np.ndarray:
        """:meth:`Predict` of each of ``state_actions``, an empty history's prior read without
        the call (eq. 8.3; most transitions of a grown space have none)."""
        return np.array(
            [
                self.Predict(sa, target) if len(self._rewards[sa]) else self._Prior(sa)
                for sa in state_actions
            ]
        )

    def PredictIntrinsic(self, state_action: int, target) -> float:
        """The expected prediction error of a reach (eq. 8.7 over eq. 8.6)."""
        errors = self._estimates[state_action] - self._rewards[state_action]
        return self._Estimate(state_action, target, errors, 1.0, True)

    def Record(self, state_action: int, target, estimate: float, reward: float) -> None:
        """Appends ``{x*, e, r}`` to ``H_{s,a}`` (eq. 8.2)."""
        self._targets[state_action] = np.vstack(
            [self._targets[state_action], np.asarray(target, dtype=float)[None]]
        )
        self._estimates[state_action] = np.append(self._estimates[state_action], estimate)
        self._rewards[state_action] = np.append(self._rewards[state_action], reward)
        self._fits.pop((state_action, False), None)
        self._fits.pop((state_action, True), None)
