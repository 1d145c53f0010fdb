"""MoBeE 2.0 as a Drake LeafSystem: the forces of dissertation eq. 5.7-5.17, one port per term."""

import math

import numpy as np
from pydrake.common.containers import namedview
from pydrake.common.value import AbstractValue
from pydrake.geometry import QueryObject
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import LeafSystem, ValueProducer
from pydrake.systems.primitives import MatrixGain

from mobee_drake.mobee.barrier import BarrierForce, Room, StepModel
from mobee_drake.mobee.constraints import ClauseSet
from mobee_drake.mobee.fields import NO_FIELD_PAIRS, FieldPairs, RobotFields, ToFieldContacts
from mobee_drake.mobee.flow import ModulatedFlow
from mobee_drake.mobee.joint_limits import JointLimits
from mobee_drake.mobee.joint_screws import JointScrews
from mobee_drake.mobee.params import MobeeParams
from mobee_drake.mobee.squash import Squash
from mobee_drake.mobee.support_points import SupportPoints
from mobee_drake.robots.controlled_robot import ControlledRobot
from mobee_drake.robots.couplings import JointCoupling
from mobee_drake.robots.overlay import MarkerStates, RobotOverlay

# The force terms of eq. 5.7 and the safety barrier (ours; :mod:`mobee_drake.mobee.barrier`), in
# the order of the rows of the force cache; "total" is their sum.
FORCE_TERMS = (
    "spring",
    "damping",
    "f_lim",
    "f_cst",
    "f_coll",
    "f_config",
    "f_work",
    "f_flow",
    "f_barrier",
)
# The rows of MoBeE's "forces" output, named: each term of FORCE_TERMS, then their total.
ForceRows = namedview("ForceRows", FORCE_TERMS + ("total",))
# The rows from f_lim on (zero unless something pushes), and the barrier's row.
_PUSHED_ROWS = slice(FORCE_TERMS.index("f_lim"), None)
_BARRIER_ROW = FORCE_TERMS.index("f_barrier")


class Mobee(LeafSystem):
    """MoBeE 2.0: the forces of the dynamical system that moves the robot (eq. 5.7).

    ``M q'' + C q' + L(K(q - q*)) = f_config + f_work + f_lim + f_cst + f_coll``

    .. pydrake_system::

        name: Mobee
        input_ports:
        - state
        - attractor
        - config_force
        - marker_forces
        - geometry_query
        - reference_state
        output_ports:
        - spring
        - damping
        - f_lim
        - f_cst
        - f_coll
        - f_config
        - f_work
        - f_flow
        - f_barrier
        - total
        - forces
        - marker_positions
        - marker_directions
        - marker_jacobians
        - field_contacts
        - field_pairs

    Inputs (n = number of controlled joints, m = number of markers):

    - ``state`` (2n): positions (rad) and velocities (rad/s) of the controlled joints.
    - ``attractor`` (n): the attractor q* (rad). Unconnected: the plant's default positions.
    - ``config_force`` (n): the client's configuration-space force f_qRPC (eq. 5.9). Optional.
    - ``marker_forces`` (3m): a workspace force (world frame) on each marker (eq. 5.10). Optional.
    - ``geometry_query``: SceneGraph's query object, posed at the same configuration.
    - ``reference_state`` (2n): the virtual trajectory (q_r, v_r) a dynamic robot's joint
      controller tracks, for the safety barrier's prediction of the plant's lag (``step``'s
      ``tracking``). Unconnected: the measured state.

    Outputs (each n, the terms of eq. 5.7 moved to the right-hand side, so that
    ``M q'' = total``):

    - ``spring`` = -L(K(q - q*)), ``damping`` = -C q', ``f_lim``, ``f_cst``, ``f_coll``,
      ``f_config``, ``f_work``, the obstacle-aware flow ``f_flow`` (ours, ``params.flow``: on by
      default, off in the dissertation's preset; the goal-directed forces bent around the fields
      they push into, :mod:`mobee_drake.mobee.flow`), the safety barrier ``f_barrier`` (ours:
      zero unless the others would close a gap between solids too fast in the next period; needs
      ``step``, see :mod:`mobee_drake.mobee.barrier`), and ``total``, their sum; ``forces``
      (10n) all ten, in that order (the evaluation: the other ports read it).
    - ``marker_positions`` (3m) and ``marker_directions`` (3m): in world, marker after marker.
    - ``marker_jacobians`` (3mn): the translational Jacobians dp_WM/dq, marker after marker, each
      3 x n in row-major order (reshape with ``(m, 3, n)``).
    - ``field_contacts``: the list of :class:`~mobee_drake.mobee.fields.FieldContact` pairs
      inside their fields, witness points in world.
    - ``field_pairs``: the same pairs as arrays (:class:`~mobee_drake.mobee.fields.FieldPairs`):
      cheaper, for monitors that run every step.

    The robot's kinematics are evaluated in a plant context held in a cache entry; the system
    keeps no state of its own. ``step`` says how the next period integrates ``total`` (the
    station gives it); without it there is no barrier.
    """

    def __init__(
        self,
        plant: MultibodyPlant,
        robot: RobotOverlay,
        *,
        joints: list[str],
        params: MobeeParams | None = None,
        step: StepModel | None = None,
    ):
        super().__init__()
        self._plant = plant
        self._params = params = params or MobeeParams()
        self._joints = list(joints)
        params.Validate(self._joints)
        self._SetUpJointTerms(plant, robot, params, step)
        self._SetUpFieldsAndMarkers(plant, robot)
        self._DeclareInputs()
        self._DeclareCaches(plant)
        self._DeclareOutputs()

    def _SetUpJointTerms(self, plant, robot: RobotOverlay, params: MobeeParams, step) -> None:
        """The constants of the joint-space terms: eq. 5.7's mass, damping and spring, the
        joint limits (eq. 5.12) and constraints (eq. 5.15), and the barrier's step."""
        self._robot = controlled = ControlledRobot.Of(plant, robot, self._joints, "MoBeE")
        # Generalized forces over the plant's velocities onto the controlled joints (their
        # followers' included: robots/couplings.py).
        self._to_joints = controlled.velocity_map
        self._q_min, self._q_max = controlled.lower, controlled.upper
        per_joint = params.PerJoint(self._joints)
        mass, damping = per_joint.mass, per_joint.damping
        self._mass, self._damping, self._stiffness = mass, damping, per_joint.stiffness
        self._negative_damping = -damping
        self._squash = per_joint.squash  # eq. 5.8's (m_i, k_i) of each sigmoid
        self._barrier = params.barrier.enabled and step is not None
        if self._barrier:
            self._displacement = step.Displacement(mass, damping)
        self._limits = JointLimits(
            self._q_min, self._q_max, per_joint.limit_delta, per_joint.limit_force
        )
        self._clauses = ClauseSet(
            robot.overlay.clauses,
            self._joints,
            robot.frozen_joints,
            source="MoBeE",
            followers=controlled.followers,
        )
        # f_lim and f_cst push only inside a band (eq. 5.12, 5.15): one product gives the depth of
        # every joint and literal into its band, and in most evaluations none is inside one.
        bands = [self._limits.Bands(), self._clauses.Bands(params.constraint_delta)]
        self._band_rows = np.vstack([R for R, _ in bands])
        self._band_offsets = np.concatenate([c for _, c in bands])
        self._default_positions = plant.GetPositions(plant.CreateDefaultContext())
        self._home = controlled.home
        self._state_names = [f"{j} position" for j in self._joints] + [
            f"{j} velocity" for j in self._joints
        ]

    def _SetUpFieldsAndMarkers(self, plant, robot: RobotOverlay) -> None:
        """The robot's fields (eq. 5.11), the screws every Jacobian comes from, the barrier's
        support points and the markers a client may push (eq. 5.10)."""
        controlled = self._robot
        self._fields = RobotFields(robot.field_margins)
        self._geometry_names = dict(robot.geometry_names)
        # Every Jacobian below comes from the joints' screws, through the body of each point.
        self._screws = JointScrews(plant, self._to_joints)
        # Which velocities move each field geometry's body; a last row of zeros for obstacles
        # (FieldPairs.row_B is -1).
        field_bodies = [
            int(plant.get_frame(robot.geometry_frames[g]).body().index())
            for g in self._fields.geometries
        ]
        moves = self._screws.Moves(np.array(field_bodies, dtype=int))
        self._field_moves = np.vstack([moves, np.zeros(moves.shape[1])])
        # The barrier also watches the support points of each robot solid with a field, and
        # watches pairs as far beyond their fields as the next period may move them.
        if self._barrier:
            primitives = {p.name: p for p in robot.overlay.primitives}
            frames = [plant.get_frame(robot.geometry_frames[g]) for g in self._fields.geometries]
            self._support = SupportPoints(
                plant,
                [primitives[self._geometry_names[g]] for g in self._fields.geometries],
                field_bodies,
                [f.GetFixedPoseInBodyFrame().GetAsMatrix4() for f in frames],
                self._screws,
                self._field_moves,
            )
        self._markers, self._marker_bodies = controlled.markers, controlled.marker_bodies
        self._marker_moves = self._screws.Moves(
            np.array([int(b.index()) for b in self._marker_bodies], dtype=int)
        )
        self._marker_force_names = [f"{m.name}[{axis}]" for m in self._markers for axis in "xyz"]

    def _DeclareInputs(self) -> None:
        n, num_markers = len(self._joints), len(self._markers)
        self._state_port = self.DeclareVectorInputPort("state", 2 * n)
        self._attractor_port = self.DeclareVectorInputPort("attractor", n)
        self._config_force_port = self.DeclareVectorInputPort("config_force", n)
        self._marker_forces_port = self.DeclareVectorInputPort("marker_forces", 3 * num_markers)
        self._query_port = self.DeclareAbstractInputPort(
            "geometry_query", AbstractValue.Make(QueryObject())
        )
        self._reference_port = self.DeclareVectorInputPort("reference_state", 2 * n)

    def _DeclareCaches(self, plant) -> None:
        """Scratch data shared by the outputs: the checked attractor, the plant context at the
        input configuration, the joints' screws there and the markers' poses."""
        n, num_markers = len(self._joints), len(self._markers)
        # The attractor changes rarely: it is checked once per change, not once per evaluation.
        self._attractor_entry = self.DeclareCacheEntry(
            description="checked attractor",
            value_producer=ValueProducer(
                allocate=lambda: AbstractValue.Make(np.zeros(n)), calc=self._CalcAttractor
            ),
            prerequisites_of_calc={self._attractor_port.ticket()},
        )
        state_ticket = self._state_port.ticket()
        self._plant_context_entry = self.DeclareCacheEntry(
            description="plant context at the input configuration",
            value_producer=ValueProducer(
                allocate=lambda: AbstractValue.Make(plant.CreateDefaultContext()),
                calc=self._CalcPlantContext,
            ),
            prerequisites_of_calc={state_ticket},
        )
        plant_ticket = self._plant_context_entry.ticket()
        self._screws_entry = self.DeclareCacheEntry(
            description="the joints' screws at the input configuration",
            value_producer=ValueProducer(
                allocate=lambda: AbstractValue.Make(np.zeros(0)),
                calc=lambda context, value: value.set_value(
                    self._screws.Calc(self._plant_context_entry.Eval(context))
                ),
            ),
            prerequisites_of_calc={plant_ticket},
        )
        self._marker_pose_entry = self.DeclareCacheEntry(
            description="marker positions and directions",
            value_producer=ValueProducer(
                allocate=lambda: AbstractValue.Make(np.zeros((2, num_markers, 3))),
                calc=self._CalcMarkerPoses,
            ),
            prerequisites_of_calc={plant_ticket},
        )

    def _DeclareOutputs(self) -> None:
        n, num_markers = len(self._joints), len(self._markers)
        screws_ticket = self._screws_entry.ticket()
        # The forces and the field pairs are computed by their own output ports, whose values Drake
        # caches: the other ports, MoBeE's own terms and every client share one evaluation.
        forces_prerequisites = {
            self._state_port.ticket(),
            screws_ticket,
            self._marker_pose_entry.ticket(),
            self._query_port.ticket(),  # (the field pairs)
            self._attractor_entry.ticket(),
            self._config_force_port.ticket(),
            self._marker_forces_port.ticket(),
            self._reference_port.ticket(),
        }
        for row, term in enumerate(FORCE_TERMS):
            self.DeclareVectorOutputPort(
                term,
                n,
                lambda context, output, row=row: output.SetFromVector(
                    self._forces_port.Eval(context)[row * n : (row + 1) * n]
                ),
                prerequisites_of_calc=forces_prerequisites,
            )
        self.DeclareVectorOutputPort(
            "total",
            n,
            lambda context, output: output.SetFromVector(self._forces_port.Eval(context)[-n:]),
            prerequisites_of_calc=forces_prerequisites,
        )
        # Every term and then the total in one vector (term-major).
        self._forces_port = self.DeclareVectorOutputPort(
            "forces",
            (len(FORCE_TERMS) + 1) * n,
            self._CalcForces,
            prerequisites_of_calc=forces_prerequisites,
        )
        for row, name in enumerate(("marker_positions", "marker_directions")):
            self.DeclareVectorOutputPort(
                name,
                3 * num_markers,
                lambda context, output, row=row: output.SetFromVector(
                    self._marker_pose_entry.Eval(context)[row].ravel()
                ),
                prerequisites_of_calc={self._marker_pose_entry.ticket()},
            )
        self.DeclareVectorOutputPort(
            "marker_jacobians",
            3 * num_markers * n,
            self._CalcMarkerJacobians,
            prerequisites_of_calc={screws_ticket, self._marker_pose_entry.ticket()},
        )
        self.DeclareAbstractOutputPort(
            "field_contacts",
            lambda: AbstractValue.Make([]),
            self._CalcFieldContacts,
            prerequisites_of_calc={self._query_port.ticket()},
        )
        self._field_pairs_port = self.DeclareAbstractOutputPort(
            "field_pairs",
            lambda: AbstractValue.Make(NO_FIELD_PAIRS),
            self._CalcFieldPairs,
            prerequisites_of_calc={self._query_port.ticket()},
        )

    @staticmethod
    def AddToBuilder(
        builder,
        *,
        plant: MultibodyPlant,
        scene_graph,
        robot: RobotOverlay,
        joints: list[str],
        params: MobeeParams | None = None,
        step: StepModel | None = None,
        name: str = "mobee",
        measured_state: bool = True,
    ) -> "Mobee":
        """Adds MoBeE to ``builder`` and connects its geometry query and, with
        ``measured_state``, its state: ``plant``'s state output through a selector of ``joints``
        (the system ``<name>_state_selector``). Without it, the caller connects the state (the
        kinematic robot's: MoBeE's own virtual dynamics, built from MoBeE's constants). The
        attractor and the client's forces are left for the caller to connect or fix. The
        station builds every MoBeE through here.
        """
        mobee = builder.AddNamedSystem(
            name, Mobee(plant, robot, joints=joints, params=params, step=step)
        )
        if measured_state:
            joint_indices = [plant.GetJointByName(j, robot.instance).index() for j in joints]
            selector = builder.AddNamedSystem(
                f"{name}_state_selector", MatrixGain(plant.MakeStateSelectorMatrix(joint_indices))
            )
            builder.Connect(plant.get_state_output_port(), selector.get_input_port())
            builder.Connect(selector.get_output_port(), mobee.GetInputPort("state"))
        builder.Connect(scene_graph.get_query_output_port(), mobee.GetInputPort("geometry_query"))
        return mobee

    # ----------------------------------------------------------------------------------------
    # Lookups for clients.

    @property
    def joints(self) -> list[str]:
        """The controlled joints, in the order of every n-vector of this system."""
        return list(self._joints)

    @property
    def marker_names(self) -> list[str]:
        return self._robot.marker_names

    def marker_index(self, name: str) -> int:
        """The index of marker ``name`` in the marker ports (its force is ``3i:3i+3``)."""
        return self._robot.MarkerIndex(name)

    def marker_body(self, name: str):
        """The plant body that carries marker ``name``."""
        return self._marker_bodies[self.marker_index(name)]

    def joint_index(self, name: str) -> int:
        """The index of joint ``name`` in the n-vectors of this system."""
        return self._robot.JointIndex(name)

    @property
    def home(self) -> np.ndarray:
        """The plant's default positions of the controlled joints (the default attractor)."""
        return self._home.copy()

    def CheckAttractor(self, q_star: np.ndarray) -> None:
        """Raises ValueError naming the first joint whose attractor is outside its limits."""
        outside = (q_star < self._q_min) | (q_star > self._q_max)
        if outside.any():
            i = np.flatnonzero(outside)[0]
            raise ValueError(
                f"MoBeE: attractor for joint '{self._joints[i]}' is {np.degrees(q_star[i]):.6g} "
                f"deg, outside its limits [{np.degrees(self._q_min[i]):.6g}, "
                f"{np.degrees(self._q_max[i]):.6g}] deg"
            )

    @property
    def followers(self) -> tuple[JointCoupling, ...]:
        """The joints that follow the controlled ones (a motor's other joints)."""
        return self._robot.followers

    def PlantPositions(self, q: np.ndarray) -> np.ndarray:
        """The plant's positions with MoBeE's joints at ``q`` (their followers following), the
        other joints at their defaults."""
        return self._robot.PlantPositions(q, self._default_positions.copy())

    def PlantStateMap(self) -> tuple[np.ndarray, np.ndarray]:
        """(S, s0) with ``x_plant = S [q; v] + s0`` for this robot's entries of the plant's state
        (its controlled joints and the joints that follow them)."""
        return self._robot.PlantStateMap(self._plant.num_positions())

    @property
    def position_limits(self) -> tuple[np.ndarray, np.ndarray]:
        return self._q_min.copy(), self._q_max.copy()

    @property
    def mass(self) -> np.ndarray:
        """The diagonal of M (eq. 5.7), for integrating ``M q'' = total``."""
        return self._mass.copy()

    @property
    def damping(self) -> np.ndarray:
        """The diagonal of C (eq. 5.7), for integrating the damping implicitly."""
        return self._damping.copy()

    @property
    def clauses(self) -> ClauseSet:
        return self._clauses

    # ----------------------------------------------------------------------------------------
    # Input checks.

    def _CheckFinite(self, what: str, value: np.ndarray, names: list[str]) -> None:
        if math.isfinite(value.sum()):  # NaN and inf propagate through a sum: all are finite.
            return
        if not np.isfinite(value).all():  # (A finite vector whose sum overflowed passes.)
            i = np.flatnonzero(~np.isfinite(value))[0]
            raise ValueError(f"MoBeE: {what} for '{names[i]}' is not finite: {value[i]}")

    def _ReadState(self, context) -> tuple[np.ndarray, np.ndarray]:
        x = self._state_port.Eval(context)
        n = len(self._joints)
        self._CheckFinite("state", x, self._state_names)
        return x[:n], x[n:]

    def _CalcAttractor(self, context, value) -> None:
        if not self._attractor_port.HasValue(context):
            value.set_value(self._home)
            return
        q_star = self._attractor_port.Eval(context)
        self._CheckFinite("attractor", q_star, self._joints)
        self.CheckAttractor(q_star)
        value.set_value(q_star.copy())

    # ----------------------------------------------------------------------------------------
    # Cache computations.

    def _CalcPlantContext(self, context, value) -> None:
        plant_context = value.get_mutable_value()
        q, _ = self._ReadState(context)
        self._plant.SetPositions(plant_context, self.PlantPositions(q))

    def _CalcFieldPairs(self, context, output) -> None:
        output.set_value(self._fields.FindPairs(self._query_port.Eval(context)))

    def _CalcFieldContacts(self, context, output) -> None:
        output.set_value(
            ToFieldContacts(
                self._field_pairs_port.Eval(context),
                self._query_port.Eval(context),
                self._geometry_names,
            )
        )

    def _FieldNormals(self, context, pairs: FieldPairs) -> np.ndarray:
        """(k, n): each pair's generalized normal over the controlled joints, the gradient of
        its signed distance (``d' = n . v``): the separating direction at the robot geometry's
        witness point projected onto the joints, less the same at the other witness point when
        that is the robot's too (a self-collision). The two witness points lie on one line along
        the direction, so both are one projection with the difference of the bodies' motions."""
        moves = self._field_moves[pairs.row_A] - self._field_moves[pairs.row_B]
        return self._screws.Project(
            self._screws_entry.Eval(context), moves, pairs.p_WCa, pairs.nhat_BA_W
        )

    def _CalcForces(self, context, output) -> None:
        p = self._params
        q, v = self._ReadState(context)
        q_star = self._attractor_entry.Eval(context)
        f = ForceRows(output.get_mutable_value().reshape(len(FORCE_TERMS) + 1, len(q)))  # (views)

        # -L(K(q - q*)) as L(K(q* - q)): L is odd (the same numbers, one operation fewer).
        f.spring = Squash(self._stiffness * (q_star - q), *self._squash["spring"])
        np.multiply(self._negative_damping, v, out=f.damping)
        f[_PUSHED_ROWS] = 0.0
        depths = self._band_rows @ q + self._band_offsets
        if depths.max() > 0.0:
            n = len(q)
            f.f_lim = self._limits.ForceAtDepths(depths[: 2 * n].reshape(2, n))  # eq. 5.12
            f.f_cst = self._clauses.ForceAtDepths(  # eq. 5.15
                depths[2 * n :], p.constraint_delta, p.constraint_force
            )

        pairs = self._field_pairs_port.Eval(context)
        normals = None
        if len(pairs):
            normals = self._FieldNormals(context, pairs)
            # Eq. 5.11: the gain times the field penetration along each pair's normal, summed.
            collision = (p.collision_gain * (pairs.margin - pairs.distance)) @ normals
            f.f_coll = Squash(collision, *self._squash["collision"])

        if self._config_force_port.HasValue(context):
            f_q = self._config_force_port.Eval(context)
            self._CheckFinite("config_force", f_q, self._joints)
            f.f_config = Squash(f_q, *self._squash["config"])  # eq. 5.9

        if self._markers and self._marker_forces_port.HasValue(context):
            f_m = self._marker_forces_port.Eval(context).reshape(-1, 3)
            self._CheckFinite("marker_forces", f_m.ravel(), self._marker_force_names)
            loaded = np.flatnonzero(np.any(f_m != 0.0, axis=1))
            if loaded.size:
                generalized = self._screws.Project(
                    self._screws_entry.Eval(context),
                    self._marker_moves[loaded],
                    self._marker_pose_entry.Eval(context)[0][loaded],
                    f_m[loaded],
                ).sum(axis=0)
                f.f_work = Squash(generalized, *self._squash["work"])  # eq. 5.10

        if p.flow.enabled and normals is not None:
            goal_directed = f.spring + f.f_config + f.f_work  # the spring and the client's forces
            f.f_flow = (
                ModulatedFlow(
                    goal_directed, normals, pairs.distance, pairs.margin, p.barrier.clearance
                )
                - goal_directed
            )

        if self._barrier:
            others = f[:_BARRIER_ROW].sum(axis=0)
            f.f_barrier = self._Barrier(context, q, v, others, pairs, normals)
        np.sum(f[: len(FORCE_TERMS)], axis=0, out=f.total)

    def _Barrier(self, context, q, v, total, pairs: FieldPairs, normals) -> np.ndarray:
        """The safety barrier's force (:mod:`mobee_drake.mobee.barrier`) for the pairs inside
        their fields and, if the period could move two solids from beyond their field to within
        the clearance, for those pairs too (docs/mobee.md, "The safety guarantee", condition 1).
        """
        params, gain = self._params.barrier, self._displacement.gain
        offset = self._NextOffset(context, q, v)
        change = np.zeros_like(total)
        room = Room(q, self._q_min, self._q_max, params.max_step)
        rows, gaps = self._BarrierRows(context, pairs, normals, offset + gain * total)
        if rows is not None:
            change = BarrierForce(rows, gaps, offset, total, self._mass, gain, params, room)
        # How far each solid may move (the largest lever of any of its points, any posture);
        # two solids close by at most the two largest together.
        reach = self._support.Lookahead(np.abs(offset + gain * (total + change)))
        if params.clearance + np.sort(reach)[-2:].sum() <= self._fields.min_margin:
            return change  # No solid can cross its field in the period.
        far = self._fields.FindApproaching(self._query_port.Eval(context), reach, params.clearance)
        if not len(far):
            return change
        # Their witness points only: a turn is caught by the support points once in the field.
        far_rows, far_gaps = self._FieldNormals(context, far), far.distance
        if rows is not None:
            far_rows, far_gaps = np.vstack([rows, far_rows]), np.concatenate([gaps, far_gaps])
        return BarrierForce(far_rows, far_gaps, offset, total, self._mass, gain, params, room)

    def _BarrierRows(self, context, pairs: FieldPairs, normals, displacement: np.ndarray):
        """(normals (r, n), gaps (r,)) of the barrier's rows for ``pairs``, or (None, None) if
        there are none: each pair's witness point and the support points of its robot solids
        (:mod:`mobee_drake.mobee.support_points`) that the joints' ``displacement`` could bring
        into the pair's field."""
        if not len(pairs):
            return None, None
        lookahead = self._support.Lookahead(np.abs(displacement))
        rows, gaps = self._support.BarrierRows(self._screws_entry.Eval(context), pairs, lookahead)
        if rows is None:
            return normals, pairs.distance
        return np.vstack([normals, rows]), np.concatenate([pairs.distance, gaps])

    def _NextOffset(self, context, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The next period's displacement without force (:class:`Displacement`), from the
        reference state where one is connected."""
        q_r, v_r = q, v
        if self._reference_port.HasValue(context):
            x_r = self._reference_port.Eval(context)
            self._CheckFinite("reference_state", x_r, self._state_names)
            q_r, v_r = x_r[: len(q)], x_r[len(q) :]
        return self._displacement.Offset(q, v, q_r, v_r)

    def _CalcMarkerPoses(self, context, value) -> None:
        MarkerStates(
            self._markers,
            self._marker_bodies,
            self._plant_context_entry.Eval(context),
            out=value.get_mutable_value(),
        )

    def _CalcMarkerJacobians(self, context, output) -> None:
        jacobians = self._screws.Jacobians(
            self._screws_entry.Eval(context),
            self._marker_moves,
            self._marker_pose_entry.Eval(context)[0],
        )
        output.SetFromVector(jacobians.ravel())
