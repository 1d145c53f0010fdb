"""MoBeE 1.0 (dissertation ch. 4.1): position moves guarded by a reflex that rewinds them.

The robot is position controlled: a *position move command* (the attractor input) drives every
joint toward it along a straight line in joint space at a fixed speed. A history buffer keeps the
poses the robot passed through; each new command marks a *waypoint* there (the pose where the
command was issued). When MoBeE's model reports trouble (a geometry pair inside its field: the
"generous bounding volumes" of ch. 4, or a constraint clause violated), the reflex takes over and
retraces the history, one pose per control period, back to the waypoint: the command failed and
the robot is where it was when the command arrived. A rewind that runs out of history before its
waypoint leaves the robot *stuck* (no safe pose left).

Where the source is silent we chose: the history logs a pose only when the robot moved (a robot at
rest does not fill the buffer); a command is *completed* when every joint is within
``tolerance`` of it; a failed or completed command leaves the robot holding still until the next
command; a command equal to the last one is not a new command.
"""

import dataclasses as dc
import enum
import math

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import BasicVector, LeafSystem

from mobee_drake.mobee.constraints import ClauseSet
from mobee_drake.mobee.fields import NO_FIELD_PAIRS


class Mode(enum.IntEnum):
    """What the controller is doing."""

    HOLDING = 0  # at rest, until a new command
    MOVING = 1  # toward the command
    REWINDING = 2  # the reflex: back along the history to the waypoint
    STUCK = 3  # the rewind ran out of history


class Status(enum.IntEnum):
    """The entries of the ``status`` output (counts since the start)."""

    MODE = 0
    COMMANDS = 1
    COMPLETED = 2
    REFLEXES = 3
    STUCK_COUNT = 4


@dc.dataclass
class ReflexParams:
    """MoBeE 1.0's position control and reflex."""

    # Joint-space speed of a position move (deg/s): the source babbled at 20 % of the maximum.
    speed_deg: float = 20.0
    # Poses the history buffer holds.
    history: int = 2000
    # A command is completed when every joint is this close to it (deg).
    tolerance_deg: float = 0.5


class ReflexController(LeafSystem):
    """The position-controlled robot of MoBeE 1.0 with its reflex.

    .. pydrake_system::

        name: ReflexController
        input_ports:
        - command
        - field_pairs
        output_ports:
        - state
        - status

    ``command`` is the position move command (n joint positions); ``field_pairs`` MoBeE's pairs
    inside their fields for the current pose. ``state`` is (q, v); ``status`` is (mode,
    commands received, commands completed, reflexes, times stuck).

    State: (q, v); the history ring buffer; and the bookkeeping vector (ring head, poses held,
    poses back to the waypoint, then the status, then the last command).
    """

    def __init__(
        self,
        *,
        initial_positions: np.ndarray,
        period: float,
        params: ReflexParams,
        clauses: ClauseSet,
    ):
        super().__init__()
        n = len(initial_positions)
        self._n, self._period, self._clauses = n, period, clauses
        self._step = math.radians(params.speed_deg) * period
        self._tolerance = math.radians(params.tolerance_deg)
        self._size = params.history
        q0 = np.asarray(initial_positions, dtype=float)
        self._command_port = self.DeclareVectorInputPort("command", n)
        self._pairs_port = self.DeclareAbstractInputPort(
            "field_pairs", AbstractValue.Make(NO_FIELD_PAIRS)
        )
        self._motion = self.DeclareDiscreteState(BasicVector(np.concatenate([q0, np.zeros(n)])))
        history = np.zeros(self._size * n)
        history[:n] = q0
        self._history = self.DeclareDiscreteState(BasicVector(history))
        # head = 0 holds q0; one pose held; waypoint 0 poses back; status: holding, counters 0.
        self._book = self.DeclareDiscreteState(
            BasicVector(np.concatenate([[0, 1, 0], [Mode.HOLDING, 0, 0, 0, 0], q0]))
        )
        self.DeclareStateOutputPort("state", self._motion)
        self.DeclareVectorOutputPort(
            "status",
            5,
            self._CalcStatus,
            prerequisites_of_calc={self.discrete_state_ticket(self._book)},
        )
        self.DeclarePeriodicDiscreteUpdateEvent(
            period_sec=period, offset_sec=0.0, update=self._Update
        )

    def _Trouble(self, context, q: np.ndarray) -> bool:
        return bool(
            len(self._pairs_port.Eval(context)) or self._clauses.ActiveClauses(q, 0.0).any()
        )

    def _Update(self, context, discrete_state) -> None:
        n = self._n
        q = context.get_discrete_state(self._motion).value()[:n].copy()
        history = context.get_discrete_state(self._history).value()
        book = context.get_discrete_state(self._book).value().copy()
        head, held, back = (int(v) for v in book[:3])
        status, last = book[3:8], book[8:]  # views: written back with the book
        mode = int(status[Status.MODE])
        command = self._command_port.Eval(context)
        # The planner's commands are suppressed while the reflex acts (then the latest one runs).
        if mode in (Mode.HOLDING, Mode.MOVING) and not np.array_equal(command, last):
            last[:] = command  # a new position move: the current pose is its waypoint
            status[Status.COMMANDS] += 1
            back, mode = 0, Mode.MOVING
        if mode == Mode.MOVING and self._Trouble(context, q):
            mode = Mode.REWINDING
            status[Status.REFLEXES] += 1
        q_next = q
        if mode == Mode.REWINDING:
            if back == 0:  # back at the waypoint: the command failed
                mode = Mode.HOLDING
            elif held <= 1:  # the history ran out before the waypoint
                mode = Mode.STUCK
                status[Status.STUCK_COUNT] += 1
            else:
                head, held, back = (head - 1) % self._size, held - 1, back - 1
                q_next = history[head * n : (head + 1) * n].copy()
        elif mode == Mode.MOVING:
            error = command - q
            largest = np.max(np.abs(error))
            if largest <= self._tolerance:
                mode = Mode.HOLDING
                status[Status.COMPLETED] += 1
            else:
                q_next = q + error * min(1.0, self._step / largest)
                head = (head + 1) % self._size
                # Drake hands the update the current state: only the new row is written.
                discrete_state.get_mutable_vector(self._history).get_mutable_value()[
                    head * n : (head + 1) * n
                ] = q_next
                held, back = min(held + 1, self._size), min(back + 1, self._size)
        book[:3] = head, held, back
        status[Status.MODE] = mode
        discrete_state.get_mutable_vector(self._motion).SetFromVector(
            np.concatenate([q_next, (q_next - q) / self._period])
        )
        discrete_state.get_mutable_vector(self._book).SetFromVector(book)

    def _CalcStatus(self, context, output) -> None:
        book = context.get_discrete_state(self._book).value()
        output.SetFromVector(book[3:8])
