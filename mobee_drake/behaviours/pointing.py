"""A marker kept pointed at a target by the joints a behaviour owns (dissertation ch. 9.4.2): the
head's gaze by the neck, the palm's normal by the wrist, beside a reach planner on the arm.

The law. The marker sits at p and points along d (MoBeE's ``marker_positions`` and
``marker_directions``, in world); the target is at t. The pointing error is the rotation that takes
d onto u = (t - p) / |t - p|: about the axis d x u by the angle theta = atan2(|d x u|, d . u).
With J (3 x k) the angular Jacobian of the marker's body on the k owned joints, the damped
least-squares step

    dq = J^T (J J^T + lambda^2 I)^-1 (gain theta axis)

turns the marker towards the target, and the attractor of the owned joints is q + dq, clipped to
their limits: MoBeE's spring pulls the joints along the step, and its fields, limits and
constraints still apply. The other joints' entries are home (the composition reads only the owned
ones). The error theta is in the data log (``<system>.error_deg``), and the run's summary gives its
value at the end and its mean over the run (sampled every control period).
"""

import dataclasses as dc

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.multibody.tree import JacobianWrtVariable
from pydrake.systems.framework import BasicVector, LeafSystem, ValueProducer

from mobee_drake.behaviours.world_target import AddTargetPosition
from mobee_drake.station.parts import DATA_LOG_PORT, ClientPorts, StationParts


def PointingError(d: np.ndarray, u: np.ndarray) -> tuple[float, np.ndarray]:
    """(theta, unit axis): the rotation that takes the unit direction ``d`` onto ``u``; the axis
    is any unit vector normal to d when they are (anti)parallel."""
    cross = np.cross(d, u)
    sine = float(np.linalg.norm(cross))
    theta = float(np.arctan2(sine, float(np.dot(d, u))))
    if sine > 1e-12:
        return theta, cross / sine
    normal = np.cross(d, [1.0, 0.0, 0.0] if abs(d[0]) < 0.9 else [0.0, 1.0, 0.0])
    return theta, normal / np.linalg.norm(normal)


class PointingController(LeafSystem):
    """Turns a marker towards a target with the joints it owns (see the module).

    .. pydrake_system::

        name: PointingController

        input_ports:
        - state
        - marker_positions
        - marker_directions
        - target

        output_ports:
        - attractor
        - error_deg
        - data_log
    """

    def __init__(
        self, *, plant, mobee, joints: list[str], marker: str, gain: float, damping: float, period
    ):
        super().__init__()
        n, m = len(mobee.joints), len(mobee.marker_names)
        self._plant, self._mobee, self._gain, self._damping = plant, mobee, gain, damping
        self._home = mobee.home
        self._owned = np.array([mobee.joint_index(j) for j in joints], dtype=int)
        self._marker = mobee.marker_index(marker)
        self._body = mobee.marker_body(marker)
        S, _ = mobee.PlantStateMap()
        # The owned joints' columns of the map from MoBeE's joint velocities to the plant's.
        self._velocity_map = S[plant.num_positions() :, n:][:, self._owned]
        limits = [plant.GetJointByName(j) for j in joints]
        self._lower = np.array([j.position_lower_limits()[0] for j in limits])
        self._upper = np.array([j.position_upper_limits()[0] for j in limits])
        self._state = self.DeclareVectorInputPort("state", 2 * n)
        self._positions = self.DeclareVectorInputPort("marker_positions", 3 * m)
        self._directions = self.DeclareVectorInputPort("marker_directions", 3 * m)
        self._target = self.DeclareVectorInputPort("target", 3)
        self._plant_context = self.DeclareCacheEntry(
            description="the plant at the robot's state",
            value_producer=ValueProducer(
                allocate=lambda: AbstractValue.Make(plant.CreateDefaultContext()),
                calc=self._CalcPlantContext,
            ),
            prerequisites_of_calc={self._state.ticket()},
        )
        # The error's sum over the control periods so far, and their count.
        self._error_sum = self.DeclareDiscreteState(2)
        self.DeclarePeriodicDiscreteUpdateEvent(period, 0.0, self._Accumulate)
        self.DeclareVectorOutputPort("attractor", n, self._CalcAttractor)
        self._error_port = self.DeclareVectorOutputPort("error_deg", 1, self._CalcError)
        self.DeclareVectorOutputPort(DATA_LOG_PORT, 1, self._CalcError)

    def _CalcPlantContext(self, context, value) -> None:
        q = self._state.Eval(context)[: len(self._home)]
        self._plant.SetPositions(value.get_mutable_value(), self._mobee.PlantPositions(q))

    def _Error(self, context) -> tuple[float, np.ndarray]:
        i = self._marker
        p = self._positions.Eval(context)[3 * i : 3 * i + 3]
        d = self._directions.Eval(context)[3 * i : 3 * i + 3]
        to_target = self._target.Eval(context) - p
        distance = float(np.linalg.norm(to_target))
        if distance < 1e-9:  # (the target at the marker: no direction to point)
            return 0.0, np.zeros(3)
        return PointingError(d, to_target / distance)

    def _CalcError(self, context, output: BasicVector) -> None:
        output.SetAtIndex(0, np.degrees(self._Error(context)[0]))

    def _CalcAttractor(self, context, output: BasicVector) -> None:
        theta, axis = self._Error(context)
        plant = self._plant
        frame = self._body.body_frame()
        J_v = plant.CalcJacobianAngularVelocity(
            self._plant_context.Eval(context),
            JacobianWrtVariable.kV,
            frame,
            plant.world_frame(),
            plant.world_frame(),
        )
        J = J_v @ self._velocity_map  # (3, k)
        step = J.T @ np.linalg.solve(
            J @ J.T + self._damping**2 * np.eye(3), self._gain * theta * axis
        )
        q = self._state.Eval(context)[: len(self._home)]
        q_star = self._home.copy()
        if self._gain > 0:  # (gain 0: the error measured, the joints held at home)
            q_star[self._owned] = np.clip(q[self._owned] + step, self._lower, self._upper)
        output.SetFromVector(q_star)

    def _Accumulate(self, context, discrete_state) -> None:
        total, count = context.get_discrete_state(self._error_sum).value()
        error = self._error_port.Eval(context)[0]
        discrete_state.set_value(self._error_sum, [total + error, count + 1])

    def Outcome(self, context) -> dict:
        """The pointing error at the end and its mean over the control periods (degrees)."""
        total, count = context.get_discrete_state(self._error_sum).value()
        return {
            "final_error_deg": float(self._error_port.Eval(context)[0]),
            "mean_error_deg": float(total / count) if count else None,
        }

    def DataLogColumns(self) -> list[tuple[str, str]]:
        return [(f"{self.get_name()}.error_deg", "deg")]


@dc.dataclass
class PointAt:
    """A client that keeps a marker pointed at a target with the joints it owns (see the
    module), e.g. ``!PointAt {marker: head, target: ball}`` on the neck joints."""

    # The marker that points (its overlay direction): "head" (gaze), "r_palm" (palm normal).
    marker: str = "head"
    # A world object's name, or "" to point at the "target" another behaviour offers.
    target: str = ""
    # The step per radian of error (rad of attractor per rad; 0: only measure the error, the
    # joints held at home) and the damping (rad) of the least-squares step near a singular
    # Jacobian.
    gain: float = 1.0
    damping: float = 0.05

    def Validate(self) -> None:
        if not (np.isfinite(self.gain) and self.gain >= 0):
            raise ValueError(f"PointAt: gain must be finite and >= 0, got {self.gain}")
        if not (np.isfinite(self.damping) and self.damping >= 0):
            raise ValueError(f"PointAt: damping must be finite and >= 0, got {self.damping}")

    def AddToBuilder(self, parts: StationParts) -> ClientPorts:
        mobee, builder = parts.mobee, parts.builder
        controller = builder.AddNamedSystem(
            f"{parts.prefix}pointing",
            PointingController(
                plant=parts.plant,
                mobee=mobee,
                joints=parts.OwnedJoints(),
                marker=self.marker,
                gain=self.gain,
                damping=self.damping,
                period=parts.period,
            ),
        )
        builder.Connect(parts.robot_state, controller.GetInputPort("state"))
        for name in ("marker_positions", "marker_directions"):
            builder.Connect(mobee.GetOutputPort(name), controller.GetInputPort(name))
        needs = {}
        if self.target:
            position = AddTargetPosition(parts, self.target)
            builder.Connect(position, controller.GetInputPort("target"))
        else:
            needs["target"] = controller.GetInputPort("target")
        return ClientPorts(
            system=controller,
            attractor=controller.GetOutputPort("attractor"),
            outcome=controller,
            data_log=controller,
            needs=needs,
        )
