"""The station's own attractor programs: fixed (with optional workspace goals for markers),
random for motor babbling (ch. 4.1.1), or moved by hand with Meshcat sliders. Each config is a
client of the station (see :mod:`mobee_drake.station.parts`)."""

import dataclasses as dc

import numpy as np
from pydrake.systems.framework import BasicVector, LeafSystem
from pydrake.systems.primitives import ConstantVectorSource

from mobee_drake.station.parts import ClientPorts, StationParts

# How often the attractor sliders are read (s).
SLIDER_PERIOD = 0.05


@dc.dataclass
class MarkerGoal:
    """A workspace goal for one of MoBeE's markers: a spring that pulls the marker to a point,
    MoBeE's workspace forcing (eq. 5.10), ``f = gain (position - p_marker)``."""

    marker: str = "r_palm"
    # The goal (world, m).
    position: list[float] = dc.field(default_factory=lambda: [0.0, 0.0, 0.0])
    # The spring's gain: workspace force (M rad/s^2 per m of lever) per metre of error.
    gain: float = 200.0

    def Validate(self) -> None:
        if len(self.position) != 3 or not np.isfinite(self.position).all():
            raise ValueError(f"marker goal position must be 3 finite numbers, got {self.position}")
        if not (np.isfinite(self.gain) and self.gain > 0):
            raise ValueError(f"marker goal gain must be > 0, got {self.gain}")


@dc.dataclass
class FixedAttractor:
    """One attractor for the whole run: the home posture with the given joints changed; and
    optionally workspace goals for markers (the goal a differential-IK controller is given)."""

    joints_deg: dict[str, float] = dc.field(default_factory=dict)
    marker_goals: list[MarkerGoal] = dc.field(default_factory=list)

    def Validate(self) -> None:
        """The goals' values (the joints and markers are checked when built)."""
        for goal in self.marker_goals:
            goal.Validate()

    def AddToBuilder(self, parts: StationParts) -> ClientPorts:
        mobee = parts.mobee
        q_star = mobee.home
        for joint, value in self.joints_deg.items():
            q_star[mobee.joint_index(joint)] = np.radians(value)
        mobee.CheckAttractor(q_star)
        source = parts.builder.AddNamedSystem(
            f"{parts.prefix}fixed_attractor", ConstantVectorSource(q_star)
        )
        marker_forces = None
        if self.marker_goals:
            springs = parts.builder.AddNamedSystem(
                f"{parts.prefix}marker_goals",
                MarkerGoalSprings(
                    num_markers=len(mobee.marker_names),
                    goals={mobee.marker_index(g.marker): g for g in self.marker_goals},
                ),
            )
            parts.builder.Connect(mobee.GetOutputPort("marker_positions"), springs.get_input_port())
            marker_forces = springs.get_output_port()
        return ClientPorts(
            system=source, attractor=source.get_output_port(), marker_forces=marker_forces
        )


class MarkerGoalSprings(LeafSystem):
    """The forces of :class:`MarkerGoal` springs on MoBeE's markers (zero on the others).

    .. pydrake_system::

        name: MarkerGoalSprings
        input_ports:
        - marker_positions
        output_ports:
        - marker_forces
    """

    def __init__(self, *, num_markers: int, goals: dict[int, MarkerGoal]):
        super().__init__()
        self._rows = np.array(sorted(goals), dtype=int)
        self._targets = np.array([goals[i].position for i in self._rows], dtype=float)
        self._gains = np.array([goals[i].gain for i in self._rows], dtype=float)[:, None]
        positions = self.DeclareVectorInputPort("marker_positions", 3 * num_markers)
        self.DeclareVectorOutputPort(
            "marker_forces",
            3 * num_markers,
            self._CalcForces,
            prerequisites_of_calc={positions.ticket()},
        )

    def _CalcForces(self, context, output) -> None:
        p = self.get_input_port().Eval(context).reshape(-1, 3)
        forces = np.zeros_like(p)
        forces[self._rows] = self._gains * (self._targets - p[self._rows])
        output.SetFromVector(forces.ravel())


@dc.dataclass
class RandomAttractors:
    """Motor babbling (ch. 4.1.1): a new attractor drawn uniformly inside the joint limits."""

    # Seconds between two attractors.
    period: float = 5.0
    # The joints that babble (empty: every controlled joint); the others stay at home.
    joints: list[str] = dc.field(default_factory=list)
    # Draw from this fraction of each joint's range, centred in the range (1: the whole range).
    range_fraction: float = 0.8

    def Validate(self) -> None:
        if not self.period > 0:
            raise ValueError(f"attractor period must be > 0, got {self.period}")
        if not 0 < self.range_fraction <= 1:
            raise ValueError(
                f"attractor range_fraction must be in (0, 1], got {self.range_fraction}"
            )

    def AddToBuilder(self, parts: StationParts) -> ClientPorts:
        self.Validate()
        mobee = parts.mobee
        babbling = np.ones(len(mobee.joints), dtype=bool)
        if self.joints:
            babbling[:] = False
            for joint in self.joints:
                babbling[mobee.joint_index(joint)] = True
        lower, upper = mobee.position_limits
        source = parts.builder.AddNamedSystem(
            f"{parts.prefix}random_attractor",
            RandomAttractorSource(
                lower=lower,
                upper=upper,
                home=mobee.home,
                babbling=babbling,
                range_fraction=self.range_fraction,
                period=self.period,
                seed=parts.random_seed,
            ),
        )
        return ClientPorts(system=source, attractor=source.get_output_port())


@dc.dataclass
class SliderAttractor:
    """Interactive: one Meshcat slider per controlled joint moves the attractor (needs Meshcat)."""

    def Validate(self) -> None:
        """Nothing to check: the sliders span each joint's limits."""

    def AddToBuilder(self, parts: StationParts) -> ClientPorts:
        if parts.meshcat is None:
            raise ValueError("the slider attractor needs Meshcat (run with --meshcat)")
        mobee = parts.mobee
        lower, upper = mobee.position_limits
        source = parts.builder.AddNamedSystem(
            f"{parts.prefix}slider_attractor",
            SliderAttractorSource(
                meshcat=parts.meshcat,
                joints=mobee.joints,
                lower=lower,
                upper=upper,
                home=mobee.home,
                period=SLIDER_PERIOD,
            ),
        )
        return ClientPorts(system=source, attractor=source.get_output_port())


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
