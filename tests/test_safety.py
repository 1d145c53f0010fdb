"""MoBeE's safety guarantee (mobee/barrier.py, docs/mobee.md): closed forms of the barrier's rows
(on the planar arm too: a support point, a self-collision's other solid, a pair beyond its
field), of the lever bounds and of each robot's predicted displacement (the dynamic plant against
its prediction), the parameters that would break the guarantee refused, saturated client pushes
into a table, a ball and the robot itself for 10 s, with both presets on the kinematic robot and
the dynamic robot's three modes, that penetrate without the barrier and never with it, babbling
with random pushes, runs that start in penetration, and the docs' safety tables written by the
benchmark."""

import contextlib
import io
import json
import pathlib
import re
import shutil
import tempfile
import unittest

from arm_diagram import ArmDiagram
import numpy as np
from pydrake.multibody.tree import BodyIndex, JacobianWrtVariable

from mobee_drake.experiments import bench_safety
from mobee_drake.experiments.bench_safety import MOVERS, PRESETS, SCENES, BabblingRun, SceneRun
from mobee_drake.experiments.ch8_reaching import ReachRobot, ReachScenario
from mobee_drake.experiments.doc_tables import GeneratedTable, TableLayout
from mobee_drake.experiments.platform_record import PlatformRecord
from mobee_drake.mobee.barrier import (
    BarrierForce,
    BarrierParams,
    JointTracking,
    Room,
    StepModel,
)
from mobee_drake.mobee.flow import FlowParams
from mobee_drake.mobee.levers import LeverBounds
from mobee_drake.mobee.params import MobeeParams
from mobee_drake.planning.state_space import Lattice
from mobee_drake.scenario import BuildScenario, LoadScenario, RunScenario
from mobee_drake.station.builder import POSITION_GAIN, VELOCITY_GAIN
from mobee_drake.station.safety import Penetrations, StartsInPenetrationError
from mobee_drake.station.world_events import MakeSimulator

PARAMS = BarrierParams(rate=0.2, clearance=0.005)
DOC = pathlib.Path(__file__).resolve().parents[1] / "docs" / "mobee.md"


class TestBarrierForce(unittest.TestCase):
    """The rows ``n . (offset + gain (T + dT)) >= -rate max(d - clearance, -clearance)`` (m
    over the period)."""

    def test_a_gap_closing_too_fast_is_held_at_the_rate_with_the_least_force(self):
        """One pair: the period's closing is cut to the allowed one, by the change of least
        M^-1-norm (along M G n)."""
        n = np.array([[1.0, 0.5]])
        mass, gain, d = np.array([1.0, 4.0]), np.array([1e-4, 1e-4]), 0.015
        total = np.array([-30.0, -20.0])
        dT = BarrierForce(n, np.array([d]), np.zeros(2), total, mass, gain, PARAMS)
        allowed = -PARAMS.rate * (d - PARAMS.clearance)
        self.assertAlmostEqual((n @ (gain * (total + dT)))[0], allowed)
        direction = mass * gain * n[0]
        self.assertAlmostEqual(dT[0] * direction[1] - dT[1] * direction[0], 0.0)  # parallel
        self.assertGreater(dT @ direction, 0)

    def test_no_force_while_the_gap_closes_slowly_enough(self):
        """Allowed: 0.2 (0.02 - 0.005) = 3 mm in the period; the pair closes by 2 mm (and by 4
        mm it would not be allowed)."""
        n = np.array([[1.0, 0.0]])
        for closing, free in ((-0.002, True), (-0.004, False)):
            dT = BarrierForce(
                n, np.array([0.02]), np.array([closing, 0.0]), np.zeros(2), np.ones(2),
                np.full(2, 1e-4), PARAMS,
            )  # fmt: skip
            self.assertEqual(bool(np.all(dT == 0.0)), free)

    def test_below_the_clearance_the_gap_must_open(self):
        """At 3 mm (2 mm short of the clearance) a pair at rest is pushed open by 0.2 of the
        deficit in the period, 0.4 mm: the clearance attracts, it is not only a floor."""
        n = np.array([[2.0, 0.0]])
        gain = np.full(2, 1e-4)
        dT = BarrierForce(n, np.array([0.003]), np.zeros(2), np.zeros(2), np.ones(2), gain, PARAMS)
        self.assertAlmostEqual((n @ (gain * dT))[0], PARAMS.rate * (PARAMS.clearance - 0.003))

    def test_a_pair_the_joints_cannot_move_is_left_out(self):
        n = np.zeros((1, 2))
        dT = BarrierForce(
            n, np.array([-0.01]), np.zeros(2), np.ones(2), np.ones(2), np.ones(2), PARAMS
        )
        np.testing.assert_array_equal(dT, 0.0)

    def test_two_barriers_are_met_together(self):
        n = np.array([[1.0, 0.0], [0.0, 1.0]])
        gain = np.full(2, 1e-4)
        total = np.array([-50.0, -50.0])
        d = np.array([0.006, 0.010])
        dT = BarrierForce(n, d, np.zeros(2), total, np.ones(2), gain, PARAMS)
        closing = n @ (gain * (total + dT))
        np.testing.assert_allclose(closing, -PARAMS.rate * (d - PARAMS.clearance))

    def test_pinched_solids_stand_still(self):
        """Two barriers that ask for opposite motions of one joint cannot both hold."""
        n = np.array([[1.0], [-1.0]])
        dT = BarrierForce(
            n, np.array([-0.01, -0.01]), np.zeros(1), np.zeros(1), np.ones(1), np.ones(1), PARAMS
        )
        np.testing.assert_allclose(dT, 0.0, atol=1e-9)


class TestBarrierRoom(unittest.TestCase):
    """The room: the barrier's change moves no joint by more than a step in a period, nor beyond
    its limits, unless MoBeE's other forces already take it there."""

    def test_an_opening_wider_than_a_step_is_cut_to_the_step(self):
        """A pair 2 mm short of the clearance on a 4 mm/rad lever asks 0.2 * 2 mm / 0.004 =
        0.1 rad; the step (0.05 rad) gives half of it, all in that joint."""
        n, gain = np.array([[0.004, 0.0]]), np.full(2, 1e-4)
        room = (np.full(2, -0.05), np.full(2, 0.05))
        dT = BarrierForce(
            n, np.array([0.003]), np.zeros(2), np.zeros(2), np.ones(2), gain, PARAMS, room
        )
        np.testing.assert_allclose(gain * dT, [0.05, 0.0], atol=1e-12)
        unbounded = BarrierForce(
            n, np.array([0.003]), np.zeros(2), np.zeros(2), np.ones(2), gain, PARAMS
        )
        np.testing.assert_allclose(gain * unbounded, [0.1, 0.0], atol=1e-12)

    def test_a_joint_at_its_limit_is_not_pushed_beyond(self):
        """Two equal levers share the opening (0.4 mm) unbounded; with the first joint at its
        upper limit the second opens it alone."""
        n, gain = np.array([[1.0, 1.0]]), np.full(2, 1e-4)
        d = np.array([0.003])
        shared = BarrierForce(n, d, np.zeros(2), np.zeros(2), np.ones(2), gain, PARAMS)
        np.testing.assert_allclose(gain * shared, [0.0002, 0.0002], atol=1e-12)
        room = (np.full(2, -0.05), np.array([0.0, 0.05]))
        alone = BarrierForce(n, d, np.zeros(2), np.zeros(2), np.ones(2), gain, PARAMS, room)
        np.testing.assert_allclose(gain * alone, [0.0, 0.0004], atol=1e-12)

    def test_a_push_larger_than_a_step_is_still_cancelled(self):
        """The other forces would close the gap by 0.2 m (0.2 rad at a 1 m lever); the room never
        keeps the barrier from cancelling them: the period closes by the allowed 3 mm."""
        n, gain = np.array([[1.0, 0.0]]), np.full(2, 1e-4)
        total = np.array([-2000.0, 0.0])
        room = (np.full(2, -0.05), np.full(2, 0.05))
        dT = BarrierForce(n, np.array([0.02]), np.zeros(2), total, np.ones(2), gain, PARAMS, room)
        self.assertAlmostEqual((n @ (gain * (total + dT)))[0], -PARAMS.rate * 0.015)

    def test_a_row_that_cannot_hold_leaves_the_least_shortfall_within_the_room(self):
        """A pair deep inside asks 1 mm through levers of 0.1 and 0.02 m/rad on two joints:
        unbounded, by (9.6, 1.9) mrad; within a step of 5 mrad it cannot hold, and both joints
        give their whole step (0.5 + 0.1 mm, short by 0.4)."""
        n, gain = np.array([[0.1, 0.02]]), np.full(2, 1e-4)
        d = np.array([-0.02])
        unbounded = BarrierForce(n, d, np.zeros(2), np.zeros(2), np.ones(2), gain, PARAMS)
        np.testing.assert_allclose(gain * unbounded, np.array([0.1, 0.02]) / 10.4, atol=1e-12)
        room = (np.full(2, -0.005), np.full(2, 0.005))
        dT = BarrierForce(n, d, np.zeros(2), np.zeros(2), np.ones(2), gain, PARAMS, room)
        np.testing.assert_allclose(gain * dT, [0.005, 0.005], atol=1e-9)

    def test_the_other_forces_motion_beyond_a_step_is_left_alone(self):
        """The other forces turn the first joint by 0.2 rad, four steps; the pair needs only
        the second: the change leaves the first alone (a room of one step around 0 would cut
        its motion) and holds the pair at the allowed 3 mm."""
        n, gain = np.array([[0.0, 1.0]]), np.full(2, 1e-4)
        total = np.array([2000.0, -300.0])
        room = (np.full(2, -0.05), np.full(2, 0.05))
        dT = BarrierForce(n, np.array([0.02]), np.zeros(2), total, np.ones(2), gain, PARAMS, room)
        self.assertEqual(dT[0], 0.0)
        self.assertAlmostEqual((n @ (gain * (total + dT)))[0], -PARAMS.rate * 0.015)

    def test_a_pair_above_the_clearance_holds_while_a_deep_one_opens_what_it_can(self):
        """One joint: a pair 20 mm deep asks 1 mm through 4 mm/rad; opening it closes a pair
        0.5 mm beyond the clearance, which may close by 0.2 of that, 0.1 mm, in the period. The
        second holds: the joint turns 0.025 rad, the first opens 0.1 mm (a least-squares fit
        of both rows within the step turns it by the whole step, and the second closes 0.2
        mm)."""
        n, gain = np.array([[0.004], [-0.004]]), np.full(1, 1e-4)
        d = np.array([-0.02, 0.0055])
        room = (np.full(1, -0.05), np.full(1, 0.05))
        dT = BarrierForce(n, d, np.zeros(1), np.zeros(1), np.ones(1), gain, PARAMS, room)
        np.testing.assert_allclose(gain * dT, [0.025], atol=1e-9)

    def test_a_pinched_pair_does_not_keep_another_deep_pair_from_opening(self):
        """Two pairs 20 mm deep on 4 mm/rad levers of two joints; the first's joint also closes
        a pair at the clearance (which may not close at all). The first stays; the second
        opens its whole step, 0.2 mm, as it would alone."""
        normals = np.array([[0.004, 0.0], [-0.004, 0.0], [0.0, 0.004]])
        d, gain = np.array([-0.02, 0.005, -0.02]), np.full(2, 1e-4)
        room = (np.full(2, -0.05), np.full(2, 0.05))
        dT = BarrierForce(normals, d, np.zeros(2), np.zeros(2), np.ones(2), gain, PARAMS, room)
        np.testing.assert_allclose(gain * dT, [0.0, 0.05], atol=1e-9)

    def test_the_room_is_a_step_within_the_limits_and_holds_standing_still(self):
        lower, upper = np.array([0.0, 0.0, 0.0, 0.0]), np.array([1.0, 1.0, 1.0, 1.0])
        q = np.array([0.5, 0.98, 1.2, -0.01])  # free, near the upper limit, beyond each
        below, above = Room(q, lower, upper, 0.05)
        np.testing.assert_allclose(below, [-0.05, -0.05, -0.05, 0.0])
        np.testing.assert_allclose(above, [0.05, 0.02, 0.0, 0.05])
        n, d, gain = np.array([[1.0]]), np.array([0.003]), np.full(1, 1e-4)
        with self.assertRaisesRegex(ValueError, r"room must contain standing still"):
            BarrierForce(
                n,
                d,
                np.zeros(1),
                np.zeros(1),
                np.ones(1),
                gain,
                PARAMS,
                (np.array([0.01]), np.array([0.05])),
            )


class TestStepModels(unittest.TestCase):
    """The next period's displacement ``dq = offset + gain T`` of each robot, against the
    period simulated step by step."""

    mass, damping, h = np.array([1.0, 2.0]), np.array([50.0, 10.0]), 0.02
    q, v = np.array([0.3, -0.2]), np.array([0.5, -1.0])
    q_r, v_r = np.array([0.32, -0.25]), np.array([0.7, -1.4])
    total = np.array([-3.0, 8.0]) - damping * v  # MoBeE's total holds the damping -C v

    def _Predicted(self, model: StepModel) -> np.ndarray:
        d = model.Displacement(self.mass, self.damping)
        return d.Offset(self.q, self.v, self.q_r, self.v_r) + d.gain * self.total

    def test_the_kinematic_robot_moves_by_its_semi_implicit_step(self):
        M, C, h = self.mass, self.damping, self.h
        v_next = (self.v + h * (self.total + C * self.v) / M) / (1 + h * C / M)
        q_r, v_r = self.q, self.v  # the kinematic robot is its own reference
        d = StepModel(h).Displacement(M, C)
        np.testing.assert_allclose(
            d.Offset(self.q, self.v, q_r, v_r) + d.gain * self.total, h * v_next
        )

    def test_the_force_mode_holds_the_end_velocity(self):
        M, h = self.mass, self.h
        np.testing.assert_allclose(
            self._Predicted(StepModel(h, implicit_damping=False)),
            h * (self.v + h * self.total / M),
        )

    def test_the_tracking_plant_follows_the_virtual_trajectory_with_its_lag(self):
        """The virtual dynamics' step moves the reference; the plant's joints follow it with
        ``q'' = kp (q_r+ - q) + kd (v_r+ - v)`` for the period, integrated here with 20,000
        small steps (the prediction is the exact solution)."""
        M, C, h = self.mass, self.damping, self.h
        # VirtualDynamics with the measured damping: v_r+ = (v_r + h (T + C v) / M) / (1 + hC/M).
        v_r_next = (self.v_r + h * (self.total + C * self.v) / M) / (1 + h * C / M)
        q_r_next = self.q_r + h * v_r_next
        for kp, kd in ((400.0, 40.0), (0.0, 40.0)):
            with self.subTest(kp=kp):
                q, v, steps = self.q.copy(), self.v.copy(), 20000
                for _ in range(steps):
                    v = v + h / steps * (kp * (q_r_next - q) + kd * (v_r_next - v))
                    q = q + h / steps * v
                predicted = self._Predicted(StepModel(h, tracking=JointTracking(kp, kd)))
                np.testing.assert_allclose(predicted, q - self.q, rtol=1e-3)
                # Without the lag (the plant taken to be at the reference) it would be wrong.
                self.assertGreater(np.abs(q_r_next - self.q_r - (q - self.q)).max(), 1e-3)

    def test_the_dynamic_plant_moves_as_predicted(self):
        """The position and velocity modes' plant (contact-free, 1 ms steps) over one period,
        against the prediction from MoBeE's total and the virtual trajectory, while the hand
        accelerates away from home: within 1 % of the displacement, and 10 times closer than
        taking the plant to move on at its velocity."""
        for control, kp in (("position", POSITION_GAIN), ("velocity", 0.0)):
            with self.subTest(control):
                scenario = LoadScenario(
                    "reach_around_ball",
                    f"{{objects: [], mover: !Dynamic {{control: {control}}}, "
                    "data_log: {enabled: false}}",
                )
                station = BuildScenario(scenario)
                simulator = MakeSimulator(station, scenario.simulator_config)
                context = simulator.get_mutable_context()
                h = scenario.time_step
                model = StepModel(h, tracking=JointTracking(kp, VELOCITY_GAIN)).Displacement(
                    station.mobee.mass, station.mobee.damping
                )
                simulator.AdvanceTo(5 * h)  # (before the period's updates)
                x = station.robot_state.Eval(context).copy()
                x_r = station.mover.GetOutputPort("state").Eval(
                    station.mover.GetMyContextFromRoot(context)
                )
                total = station.mobee.GetOutputPort("total").Eval(
                    station.mobee.GetMyContextFromRoot(context)
                )
                n = len(total)
                predicted = model.Offset(x[:n], x[n:], x_r[:n], x_r[n:]) + model.gain * total
                simulator.AdvanceTo(6 * h)
                moved = station.robot_state.Eval(context)[:n] - x[:n]
                error = np.abs(predicted - moved).max()
                self.assertLess(error, 0.01 * np.abs(moved).max())
                self.assertLess(10 * error, np.abs(h * x[n:] - moved).max())


# The arm's period, and how a period moves it at rest (M = 1, C = 20: MobeeParams' defaults).
ARM_PERIOD = 0.01
_KEEP = 1.0 / (1.0 + ARM_PERIOD * 20.0)
_GAIN = ARM_PERIOD**2 * _KEEP


def _HeldAtTheRate(row, gap: float, v: np.ndarray) -> np.ndarray:
    """The least force dT (M = 1: along the row) with which the arm at velocity v closes the
    row's gap by exactly the allowed ``rate (gap - clearance)`` in the period:
    ``n . (h v / (1 + h C) + gain dT) = -rate (gap - clearance)``."""
    row = np.asarray(row)
    allowed = -PARAMS.rate * (gap - PARAMS.clearance)
    return row * (allowed - row @ (ARM_PERIOD * _KEEP * v)) / (_GAIN * row @ row)


class TestBarrierOnTheArm(unittest.TestCase):
    """MoBeE's barrier on the planar arm (tests/arm_diagram.py: links of 0.3 m along +x at zero,
    capsules of radius 0.03), the kinematic robot with a period of 0.01 s. At rest on its
    attractor with velocity v, the period moves the joints by ``h v / (1 + h C / M)`` plus
    ``gain dT`` for the barrier's force dT (M = 1, C = 20). The fields' own force is made
    negligible (a gain of 1e-6) and the flow is off, so where one row n (gap g) binds, dT is the
    closed form of :func:`_HeldAtTheRate`."""

    def _Arm(self, q, v, boxes=(), **params):
        params = MobeeParams(flow=FlowParams(enabled=False), collision_gain=1e-6, **params)
        arm = ArmDiagram(boxes=boxes, params=params, step=StepModel(ARM_PERIOD))
        arm.dut.GetInputPort("attractor").FixValue(arm.context, q)
        arm.Set(q, v)
        return arm

    def test_a_support_point_beyond_its_field_is_watched_as_far_as_the_period_moves_it(self):
        """link3 tilted up by asin(0.2), its tip 2 cm below a box's edge, turns about the tip
        (joint3 at -2.02 times joint2): the witness gap holds, the end cap at joint3 rises
        towards the box's plane. That cap, 8 cm from the plane (beyond the 5 cm field), is
        watched because the period's move (offset h v included) could bring it into the field;
        its row binds: dT along -(0.6, 0.3, 0) (its lever arms about the joints)."""
        phi = np.arcsin(0.2)
        tip = np.array([0.6 + 0.3 * np.cos(phi), 0.06])
        box = ((0.2, 0.1, 0.1), (tip[0] + 0.1, tip[1] + 0.03 + 0.02 + 0.05, 0.0))
        v2 = 9.6
        v = np.array([0.0, v2, -v2 * (tip[0] - 0.3) / (tip[0] - 0.6)])  # the tip moves along x
        arm = self._Arm([0.0, 0.0, phi], v, boxes=[box])
        (contact,) = arm.Out("field_contacts")
        np.testing.assert_allclose(contact.distance, 0.02, atol=1e-4)
        expected = _HeldAtTheRate([-0.6, -0.3, 0.0], 0.08, v)
        np.testing.assert_allclose(arm.Out("f_barrier"), expected, rtol=5e-3, atol=1e-6)

    def test_a_self_collision_holds_the_support_point_of_its_b_solid(self):
        """link3 folded back under link1 (2 cm below it at the tip's cap, the witness point;
        3 cm at joint3's), SceneGraph's B. Turning joint2 swings link3 about the elbow: its cap
        at joint3 rises towards link1 at (0.3 cos q2) per rad while the witness gap opens a
        little. The row of B's cap, against the plane through A's witness point, binds: dT on
        joint2 alone."""
        q2 = -np.arcsin(0.09 / 0.3)  # joint3 at (0.3 + 0.3 cos q2, -0.09)
        q3 = np.pi - np.arcsin(0.01 / 0.3) - q2 - 2 * np.pi  # link3 points back, 1/30 rad up
        v = np.array([0.0, 4.0, 0.0])
        arm = self._Arm([0.0, q2, q3], v, limit_delta=0.01)  # (q3 near its limit: f_lim off)
        (contact,) = arm.Out("field_contacts")
        self.assertEqual((contact.name_A, contact.name_B), ("link1", "link3"))
        np.testing.assert_allclose(contact.distance, 0.02, atol=1e-6)
        expected = _HeldAtTheRate([0.0, -0.3 * np.cos(q2), 0.0], 0.03, v)
        np.testing.assert_allclose(arm.Out("f_barrier"), expected, rtol=1e-4, atol=1e-6)

    def test_a_pair_beyond_its_field_that_the_period_could_close_is_held(self):
        """A box 5.5 cm above the straight arm's tip (beyond the 5 cm field, so no pair of
        ``field_pairs``), the arm turning up at 7.2 rad/s: joint1 moves by 0.06 rad in the
        period, which could bring link3 (0.93 m per rad at most) 5.6 cm closer, within the
        clearance. The wide query finds the pair; its witness row binds. Turning away, none."""
        box = ((0.2, 0.1, 0.1), (1.0, 0.03 + 0.055 + 0.05, 0.0))
        v = np.array([0.06 / (ARM_PERIOD * _KEEP), 0.0, 0.0])
        arm = self._Arm(np.zeros(3), v, boxes=[box])
        self.assertEqual(len(arm.Out("field_pairs")), 0)
        expected = _HeldAtTheRate([-0.9, -0.6, -0.3], 0.055, v)
        np.testing.assert_allclose(arm.Out("f_barrier"), expected, rtol=1e-3)
        arm.Set(np.zeros(3), -v)
        np.testing.assert_array_equal(arm.Out("f_barrier"), 0.0)


class TestLeverBounds(unittest.TestCase):
    def test_no_point_of_a_solid_outruns_its_bound_in_any_posture(self):
        """mobee/levers.py: the bound over every configuration of how fast each solid's points
        move per unit speed of each joint, against the iCub's Jacobians at 30 random postures
        (every box corner, capsule end and sphere centre, plus its radius turned)."""
        station = BuildScenario(LoadScenario("reach_around_ball", "{objects: []}"))
        mobee, plant, robot = station.mobee, station.plant, station.robot
        support = mobee._support  # (MoBeE's; its bounds are what this checks)
        n = len(mobee.joints)
        bounds = np.array([support.Lookahead(np.eye(n)[j]) for j in range(n)]).T  # (G, n)
        columns = [plant.GetJointByName(j).velocity_start() for j in mobee.joints]
        primitives = {p.name: p for p in robot.overlay.primitives}
        context = plant.CreateDefaultContext()
        lower, upper = mobee.position_limits
        rng = np.random.default_rng(0)
        closest = np.inf
        for _ in range(30):
            for joint, angle in zip(mobee.joints, rng.uniform(lower, upper)):
                plant.GetJointByName(joint).set_angle(context, angle)
            for g, geometry in enumerate(robot.field_margins):
                shape = primitives[robot.geometry_names[geometry]].shape
                points, radius = _SupportPointsOf(shape)
                frame = plant.get_frame(robot.geometry_frames[geometry])
                J = plant.CalcJacobianTranslationalVelocity(
                    context, JacobianWrtVariable.kV, frame, points.T, plant.world_frame(),
                    plant.world_frame(),
                )[:, columns].reshape(len(points), 3, n)  # fmt: skip
                speeds = np.linalg.norm(J, axis=1).max(axis=0)
                speeds += radius * (speeds > 0)  # (the joints that move the solid turn its ball)
                self.assertTrue(np.all(speeds <= bounds[g] + 1e-9), robot.geometry_names[geometry])
                closest = min(closest, np.min(bounds[g] - speeds))
        self.assertLess(closest, 0.05)  # (and not loose everywhere: some posture comes close)

    def test_the_arms_bounds_are_its_lined_up_reach_and_are_attained(self):
        """On the planar arm, the bound of a point per joint is its distance to the joint along
        the chain (to the joint's origin, then from joint to joint) plus its ball's radius: for
        the link capsules' end caps (radius 0.03), 0.33 m per rad of the link's own joint and
        0.3 m more per link further up; for a ball of 1 cm around a point 4 cm off link3's axis,
        |(0.3, 0.04)| + 0.01, plus 0.3 m per link further up.
        With that point lined up with the links (joint3 at -atan(0.04 / 0.3)), each ball's far
        point moves exactly that fast: no bound is loose."""
        plant = ArmDiagram().plant
        bodies = [int(plant.GetBodyByName(f"link{i}").index()) for i in (1, 2, 3)]
        velocities = np.array(
            [plant.GetJointByName(f"joint{i}").velocity_start() for i in (1, 2, 3)]
        )
        ends = np.array([[0.0, 0.0, 0.0], [0.3, 0.0, 0.0]])
        off_axis = np.array([[0.3, 0.04, 0.0]])
        radii = np.array([0.03, 0.03, 0.01])
        bounds = LeverBounds(plant, velocities, bodies, [ends, ends, off_axis], radii)
        far = np.hypot(0.3, 0.04) + 0.01
        expected = [[0.33, 0.0, 0.0], [0.63, 0.33, 0.0], [far + 0.6, far + 0.3, far]]
        np.testing.assert_allclose(bounds, expected, rtol=1e-12)
        context = plant.CreateDefaultContext()
        plant.SetPositions(context, [0.0, 0.0, -np.arctan2(0.04, 0.3)])
        world = plant.world_frame()
        for body, p_B, radius, bound in zip(bodies, [ends[1], ends[1], off_axis[0]], radii, bounds):
            frame = plant.get_body(BodyIndex(body)).body_frame()
            # The ball's point farthest from the base, on the +x axis of the lined-up arm.
            p_W = frame.CalcPoseInWorld(context) @ p_B + [radius, 0.0, 0.0]
            p_far = frame.CalcPoseInWorld(context).inverse() @ p_W
            J = plant.CalcJacobianTranslationalVelocity(
                context, JacobianWrtVariable.kV, frame, p_far, world, world
            )
            np.testing.assert_allclose(np.linalg.norm(J, axis=0), bound, rtol=1e-12, atol=1e-15)


def _SupportPointsOf(shape) -> tuple[np.ndarray, float]:
    """A primitive's corners or end caps (or centre) in its geometry frame, and its radius."""
    if hasattr(shape, "size"):
        half = np.asarray(shape.size) / 2
        return np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * half, 0
    if hasattr(shape, "start"):
        length = np.linalg.norm(np.subtract(shape.end, shape.start))
        return np.array([[0, 0, -length / 2], [0, 0, length / 2]]), shape.radius
    return np.zeros((1, 3)), shape.radius


class TestBarrierParameters(unittest.TestCase):
    def test_values_that_would_break_the_guarantee_are_refused(self):
        joints = ["a"]
        for params, words in (
            (MobeeParams(barrier=BarrierParams(rate=1.0)), "barrier rate must be in (0, 1)"),
            (MobeeParams(barrier=BarrierParams(rate=0.0)), "barrier rate must be in (0, 1)"),
            (MobeeParams(barrier=BarrierParams(clearance=0.0)), "barrier clearance"),
            (MobeeParams(barrier=BarrierParams(max_step=0.0)), "barrier max_step"),
            (MobeeParams(damping=0.0), "damping must be > 0 while the safety barrier is on"),
        ):
            with self.subTest(words), self.assertRaisesRegex(ValueError, re.escape(words)):
                params.Validate(joints)
        MobeeParams(damping=0.0, barrier=BarrierParams(enabled=False)).Validate(joints)


# Longer than the hand took to slide off its clearance on the table before the barrier held the
# clearance itself (issue 30: about 3 s under the dissertation's constants).
PUSH_SECONDS = 10.0


class TestSaturatedPushes(unittest.TestCase):
    """c = f = 1000 on the palm, with the attractor: into a table, a ball, the robot's body, for
    10 s, with both presets, on the kinematic robot and in the dynamic robot's three modes."""

    def _Runs(self, *, barrier: bool, scenes=SCENES, presets=tuple(PRESETS)):
        for preset in presets:
            for scene in scenes:
                for mover in MOVERS:
                    with self.subTest(f"{scene.name}, {preset}, {mover}"):
                        safety = SceneRun(
                            scene, mover, barrier=barrier, seconds=PUSH_SECONDS, preset=preset
                        ).safety
                        yield scene, safety

    def test_with_the_barrier_no_push_penetrates(self):
        for scene, safety in self._Runs(barrier=True):
            self.assertEqual(safety.penetrating_steps, 0)
            closest = safety.closest_approach[scene.obstacle]
            self.assertIsNotNone(closest)  # the push reached the obstacle's field
            self.assertGreater(closest, 0.0)

    def test_without_the_barrier_the_same_pushes_penetrate(self):
        """The check above, with the barrier off, fails: under the dissertation's constants the
        client's forces (60) beat the fields' (40) on every robot, by tens of millimetres on
        the kinematic one (the dynamic robot's own contact holds it up)."""
        for scene, safety in self._Runs(barrier=False, presets=("dissertation",)):
            self.assertGreater(safety.penetrating_steps, 0)
            if scene.name != "self":  # the pushes into the body: the dynamic robot's own contact
                self.assertGreater(safety.deepest_penetration, 0.0)

    def test_babbling_with_random_saturated_pushes(self):
        """The benchmark's second part for 4 simulated minutes (the old barrier first let the
        hand into the table between 2 and 4 minutes under the dissertation's constants):
        random attractors above a table, the push's direction redrawn every second."""
        for preset in PRESETS:
            with self.subTest(preset):
                summary = BabblingRun(preset=preset, seconds=240.0, push=True)
                self.assertEqual(summary.safety.penetrating_steps, 0)
                self.assertGreater(summary.safety.closest_approach["table"], 0.0)


class TestSolidsPlacedInPenetration(unittest.TestCase):
    """No motion can bring solids into penetration, but a scenario or a world event can place an
    object there: a run is refused if it starts so (tests/test_cli.py: in one line), and a world
    event that does it is named."""

    PALM_BALL = (
        "{objects: [{name: ball, shape: !Sphere {radius: 0.04}, position: [-0.31, 0.14, 0.0]}]"
    )

    def test_a_run_that_starts_in_penetration_is_refused(self):
        scenario = LoadScenario("reach_around_ball", self.PALM_BALL + ", duration: 0.1}")
        with self.assertRaisesRegex(
            StartsInPenetrationError,
            r"the robot starts in penetration: the robot: 'r_hand' .* mm inside 'ball'",
        ):
            RunScenario(scenario)

    def test_a_world_event_that_puts_an_object_inside_the_robot_is_named(self):
        scenario = LoadScenario(
            "reach_around_ball",
            "{duration: 0.2, data_log: {enabled: false}, world_events: "
            "[{time: 0.1, object: ball, position: [-0.31, 0.14, 0.0]}]}",
        )
        with self.assertLogs("mobee_drake.station.safety", "WARNING") as logs:
            RunScenario(scenario)
        self.assertRegex(
            logs.output[0], r"a world event put solids in penetration at t = 0.1.*'ball'"
        )


class TestTargetInsideTheArm(unittest.TestCase):
    """The Katana's reach target appearing 31 mm inside its forearm, where the adaptive-space
    battery's probe recorded it (docs/adaptive_space.md, "A run wedged inside itself"): the
    barrier opens the pair within each joint's step and limits (before the room, it turned
    joints by radians a period, out of their limits: docs/mobee.md)."""

    PROBE = DOC.parent / "results/adaptive_space_reaching_probe"

    def test_the_arm_leaves_the_target_within_its_steps_and_limits(self):
        probe = json.loads((self.PROBE / "reach_katana_random_maintained_seed1.json").read_text())
        problem = probe["problems"][44]
        self.assertIn("31.3 mm inside 'reach_target'", problem["at_start"]["pairs"][0])
        robot = ReachRobot(Lattice((0.25, 0.5, 0.75), 4), 0.05, robot="katana")
        station, context = robot.station, robot.context
        q = np.array(problem["at_start"]["q"])
        integrator = station.mover.GetSubsystemByName("integrator")
        integrator.GetMyMutableContextFromRoot(context).SetDiscreteState(
            np.concatenate([q, np.zeros_like(q)])
        )
        robot.SetProblem(np.array(problem["target"]))
        lower, upper = station.mobee.position_limits
        max_step = ReachScenario(robot="katana").mobee.barrier.max_step
        for period in range(75):  # 1.5 s, sampled between updates (one update per sample)
            robot.simulator.AdvanceTo((period + 0.5) * 0.02)
            q_next = station.robot_state.Eval(context)[: len(q)]
            self.assertLessEqual(np.abs(q_next - q).max(), max_step)
            self.assertTrue(np.all((lower <= q_next) & (q_next <= upper)), q_next)
            q = q_next
        self.assertEqual(Penetrations(station.diagram, context), [])


class TestSafetyTables(unittest.TestCase):
    """docs/mobee.md's safety tables are the benchmark's: regenerated here at smoke size (pushes
    of 0.05 and 0.1 s, 0.5 s of babbling) into a copy of the doc, they have its layout."""

    def test_the_benchmark_writes_the_docs_tables(self):
        with tempfile.TemporaryDirectory() as folder:
            doc = pathlib.Path(folder) / "mobee.md"
            shutil.copy(DOC, doc)
            output = io.StringIO()
            with contextlib.redirect_stdout(output):
                bench_safety.main(
                    ["--push-seconds", "0.05", "0.1", "--babbling-seconds", "0.5",
                     "--output", f"{folder}/results", "--doc", str(doc)]
                )  # fmt: skip
            for name in ("safety scenes", "safety babbling"):
                with self.subTest(name):
                    written = GeneratedTable(doc, name)
                    self.assertIn(written, output.getvalue())  # as printed
                    self.assertEqual(TableLayout(written), TableLayout(GeneratedTable(DOC, name)))
            results = bench_safety.SafetyResults.Load(
                pathlib.Path(folder, "results", "safety.json")
            )
            self.assertEqual(len(results.scenes), 2 * 2 * len(SCENES) * 2 * len(MOVERS))
            self.assertEqual(len(results.babbling), 2 * 2)
            self.assertEqual(results.platform, PlatformRecord())  # (what it ran on)
            self.assertEqual(results.platform["numpy"], np.__version__)
            # The doc's tables are the results' (--report-only rewrites them from the file).
            shutil.copy(DOC, doc)
            with contextlib.redirect_stdout(io.StringIO()):
                bench_safety.main(
                    ["--report-only", "--output", f"{folder}/results", "--doc", str(doc)]
                )
            self.assertEqual(
                GeneratedTable(doc, "safety scenes"), results.Tables()["safety scenes"]
            )


if __name__ == "__main__":
    unittest.main()
