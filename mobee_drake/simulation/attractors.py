"""Sources of MoBeE's attractor q*: fixed, or random for motor babbling (ch. 4.1.1)."""

import numpy as np
from pydrake.systems.framework import BasicVector, LeafSystem


class RandomAttractorSource(LeafSystem):
    """A new attractor every ``period`` seconds, uniform in a fraction of each joint's range.

    .. pydrake_system::

        name: RandomAttractorSource
        output_ports:
        - attractor

    The k-th attractor is drawn from a generator seeded with ``(seed, k)``, so a run is
    reproducible and resumable from any time without carrying a generator in the state.
    Joints not in ``babbling`` (a boolean mask) stay at ``home``.
    """

    def __init__(
        self,
        *,
        lower: np.ndarray,
        upper: np.ndarray,
        home: np.ndarray,
        babbling: np.ndarray,
        range_fraction: float,
        period: float,
        seed: int,
    ):
        super().__init__()
        center, half = (lower + upper) / 2, range_fraction * (upper - lower) / 2
        self._low, self._high = center - half, center + half
        self._home, self._babbling = np.asarray(home), np.asarray(babbling, dtype=bool)
        self._period, self._seed = period, seed
        state = self.DeclareDiscreteState(BasicVector(self._Draw(0)))
        self.DeclareStateOutputPort("attractor", state)
        self.DeclarePeriodicDiscreteUpdateEvent(
            period_sec=period, offset_sec=period, update=self._Update
        )

    def _Draw(self, k: int) -> np.ndarray:
        rng = np.random.default_rng([self._seed, k])
        return np.where(self._babbling, rng.uniform(self._low, self._high), self._home)

    def _Update(self, context, discrete_state) -> None:
        k = int(round(context.get_time() / self._period))
        discrete_state.get_mutable_vector().SetFromVector(self._Draw(k))


class SliderAttractorSource(LeafSystem):
    """An attractor moved by hand: one Meshcat slider per joint (degrees), sampled every
    ``period`` into the discrete state, so that a change reaches the rest of the diagram.

    .. pydrake_system::

        name: SliderAttractorSource
        output_ports:
        - attractor
    """

    def __init__(
        self,
        *,
        meshcat,
        joints: list[str],
        lower: np.ndarray,
        upper: np.ndarray,
        home: np.ndarray,
        period: float,
    ):
        super().__init__()
        self._meshcat, self._joints = meshcat, list(joints)
        for name, lo, hi, value in zip(
            self._joints, np.degrees(lower), np.degrees(upper), np.degrees(home)
        ):
            meshcat.AddSlider(name, lo, hi, 0.1, value)
        state = self.DeclareDiscreteState(BasicVector(np.asarray(home, dtype=float)))
        self.DeclareStateOutputPort("attractor", state)
        self.DeclarePeriodicDiscreteUpdateEvent(
            period_sec=period, offset_sec=0.0, update=self._Read
        )

    def _Read(self, context, discrete_state) -> None:
        degrees = [self._meshcat.GetSliderValue(name) for name in self._joints]
        discrete_state.get_mutable_vector().SetFromVector(np.radians(degrees))
