"""MoBeE 1.0: the reflex controller with fixed input ports, and on the iCub."""

import math
import unittest

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.analysis import Simulator

from mobee_drake.mobee.constraints import ClauseSet
from mobee_drake.mobee.fields import NO_FIELD_PAIRS, FieldPairs
from mobee_drake.mobee.reflex import Mode, ReflexController, ReflexParams, Status
from mobee_drake.robots.overlay import Clause, Literal

H = 0.02
# One pair inside its field (the controller only asks whether there is any).
ONE_PAIR = FieldPairs(
    [None],
    [None],
    distance=np.zeros(1),
    margin=np.full(1, 0.05),
    p_WCa=np.zeros((1, 3)),
    nhat_BA_W=np.zeros((1, 3)),
    row_A=np.zeros(1, dtype=int),
    row_B=np.ones(1, dtype=int),
    X_WA=np.zeros((1, 3, 4)),
    X_WB=np.zeros((1, 3, 4)),
)


class ReflexControllerTest(unittest.TestCase):
    def Make(self, *, history=100, clauses=()):
        controller = ReflexController(
            initial_positions=np.zeros(2),
            period=H,
            params=ReflexParams(speed_deg=10.0, history=history, tolerance_deg=0.01),
            clauses=ClauseSet(list(clauses), ["a", "b"]),
        )
        simulator = Simulator(controller)
        context = simulator.get_mutable_context()
        controller.GetInputPort("field_pairs").FixValue(context, AbstractValue.Make(NO_FIELD_PAIRS))
        return controller, simulator, context

    def Q(self, controller, context):
        return controller.GetOutputPort("state").Eval(context)[:2].copy()

    def Status(self, controller, context):
        return controller.GetOutputPort("status").Eval(context)

    def test_a_free_move_goes_straight_at_its_speed(self):
        controller, simulator, context = self.Make()
        command = np.radians([3.0, -1.5])
        controller.GetInputPort("command").FixValue(context, command)
        step = math.radians(10.0) * H  # the largest joint moves 0.2 deg per period
        steps = math.ceil(math.radians(3.0) / step)  # 15
        simulator.AdvanceTo(5 * H + 1e-9)
        q = self.Q(controller, context)
        # Five periods along the straight line (the first update is at t = 0).
        np.testing.assert_allclose(q, command * 6 * step / math.radians(3.0), atol=1e-12)
        simulator.AdvanceTo((steps + 2) * H)
        np.testing.assert_allclose(self.Q(controller, context), command, atol=1e-12)
        status = self.Status(controller, context)
        self.assertEqual(
            (
                status[Status.MODE],
                status[Status.COMMANDS],
                status[Status.COMPLETED],
                status[Status.REFLEXES],
            ),
            (Mode.HOLDING, 1, 1, 0),
        )

    def test_the_reflex_retraces_the_move_back_to_its_waypoint(self):
        controller, simulator, context = self.Make()
        first = np.radians([2.0, 0.0])
        controller.GetInputPort("command").FixValue(context, first)
        simulator.AdvanceTo(1.0)
        np.testing.assert_allclose(self.Q(controller, context), first)
        # The second move runs for a while, then MoBeE reports trouble.
        controller.GetInputPort("command").FixValue(context, np.radians([2.0, 5.0]))
        path = []
        for k in range(1, 8):
            simulator.AdvanceTo(1.0 + k * H)
            path.append(self.Q(controller, context))
        controller.GetInputPort("field_pairs").FixValue(context, AbstractValue.Make(ONE_PAIR))
        back = []
        for k in range(8, 16):
            simulator.AdvanceTo(1.0 + k * H)
            back.append(self.Q(controller, context))
            # A new command during the rewind is suppressed.
            controller.GetInputPort("command").FixValue(context, np.radians([0.0, 0.0]))
        # The poses of the way out, in reverse order, ending at the waypoint.
        expected = path[-2::-1] + [first]
        np.testing.assert_allclose(np.array(back[: len(expected)]), np.array(expected), atol=1e-12)
        status = self.Status(controller, context)
        self.assertEqual(
            (status[Status.COMMANDS], status[Status.COMPLETED], status[Status.REFLEXES]), (2, 1, 1)
        )
        # Trouble gone: the suppressed command now runs.
        controller.GetInputPort("field_pairs").FixValue(context, AbstractValue.Make(NO_FIELD_PAIRS))
        simulator.AdvanceTo(3.0)
        np.testing.assert_allclose(self.Q(controller, context), np.zeros(2), atol=1e-12)
        self.assertEqual(self.Status(controller, context)[Status.COMMANDS], 3)

    def test_a_short_history_gets_stuck(self):
        controller, simulator, context = self.Make(history=3)
        controller.GetInputPort("command").FixValue(context, np.radians([5.0, 0.0]))
        simulator.AdvanceTo(10 * H)
        controller.GetInputPort("field_pairs").FixValue(context, AbstractValue.Make(ONE_PAIR))
        simulator.AdvanceTo(20 * H)
        status = self.Status(controller, context)
        self.assertEqual((status[Status.MODE], status[Status.STUCK_COUNT]), (Mode.STUCK, 1))
        # Ten moves of 0.2 deg (the updates at 0 ... 9 H), then back as far as the history
        # allowed (two poses before the current one), and it stays there.
        np.testing.assert_allclose(
            self.Q(controller, context), np.radians([10 * 0.2 - 2 * 0.2, 0.0]), atol=1e-12
        )

    def test_a_violated_clause_triggers_the_reflex(self):
        # b <= 1 deg.
        clause = Clause(name="b_low", literals=[Literal(coefficients={"b": -1.0}, offset=1.0)])
        controller, simulator, context = self.Make(clauses=[clause])
        controller.GetInputPort("command").FixValue(context, np.radians([0.0, 3.0]))
        simulator.AdvanceTo(1.0)
        status = self.Status(controller, context)
        self.assertEqual(
            (status[Status.MODE], status[Status.REFLEXES], status[Status.COMPLETED]),
            (Mode.HOLDING, 1, 0),
        )
        np.testing.assert_allclose(self.Q(controller, context), np.zeros(2), atol=1e-12)

    def test_the_velocity_is_the_periods_step_out_and_back(self):
        """The state's velocity is the pose's change over the period: 10 and -5 deg/s along the
        move to (3, -1.5) deg, the same reversed while the reflex retraces it, then zero."""
        controller, simulator, context = self.Make()
        controller.GetInputPort("command").FixValue(context, np.radians([3.0, -1.5]))
        speed = np.radians([10.0, -5.0])

        def V():
            return controller.GetOutputPort("state").Eval(context)[2:]

        simulator.AdvanceTo(5 * H + 1e-9)  # six steps out
        np.testing.assert_allclose(V(), speed, atol=1e-12)
        controller.GetInputPort("field_pairs").FixValue(context, AbstractValue.Make(ONE_PAIR))
        for k in range(6, 12):  # six steps back
            simulator.AdvanceTo(k * H + 1e-9)
            np.testing.assert_allclose(V(), -speed, atol=1e-12)
        np.testing.assert_allclose(self.Q(controller, context), 0.0, atol=1e-12)
        simulator.AdvanceTo(12 * H + 1e-9)  # at the waypoint: the command failed
        self.assertEqual(self.Status(controller, context)[Status.MODE], Mode.HOLDING)
        np.testing.assert_array_equal(V(), 0.0)

    def test_the_counters_count_every_command_completion_and_reflex(self):
        """Two moves of 1 deg completed, then two that meet trouble three periods out and are
        rewound: 4 commands, 2 completed, 2 reflexes, holding at the last waypoint."""
        controller, simulator, context = self.Make()
        command, pairs = controller.GetInputPort("command"), controller.GetInputPort("field_pairs")
        t = 0.0
        for target in ([1.0, 0.0], [1.0, 1.0]):
            command.FixValue(context, np.radians(target))
            t += 10 * H
            simulator.AdvanceTo(t)
        for target in ([0.0, 1.0], [1.0, 2.0]):
            command.FixValue(context, np.radians(target))
            t += 3 * H
            simulator.AdvanceTo(t)
            pairs.FixValue(context, AbstractValue.Make(ONE_PAIR))
            t += 10 * H
            simulator.AdvanceTo(t)
            pairs.FixValue(context, AbstractValue.Make(NO_FIELD_PAIRS))
        status = self.Status(controller, context)
        np.testing.assert_array_equal(status, [Mode.HOLDING, 4, 2, 2, 0])
        np.testing.assert_allclose(self.Q(controller, context), np.radians([1.0, 1.0]), atol=1e-12)


if __name__ == "__main__":
    unittest.main()
