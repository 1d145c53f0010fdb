"""The data log of a run: what the robot, MoBeE, the world and the client did, period by period.

One Drake :class:`VectorLogSink` samples every signal at once (a :class:`Multiplexer` gathers
them) every ``DataLog.period`` (0: every control period) into its Context;
:meth:`DataLogger.Table` turns the samples into a table and :meth:`DataLogger.Write` writes it as
Parquet, a columnar file pandas reads (``pandas.read_parquet``). The columns, in order (each
field's unit is in the file's schema metadata, key ``unit``):

========================  ===========  ==================================================
column                    unit         what
========================  ===========  ==================================================
``time``                  s            the sample's time
``q.<joint>``             rad          MoBeE's joint positions (the robot's state)
``v.<joint>``             rad/s        their velocities
``q_star.<joint>``        rad          the attractor q*
``force.<term>``          M rad/s^2    the norm of each force of eq. 5.7 (``spring``,
                                       ``damping``, ``f_lim``, ``f_cst``, ``f_coll``,
                                       ``f_config``, ``f_work``), of the safety barrier
                                       (``f_barrier``) and of their ``total``;
                                       with ``full_forces``, ``force.<term>.<joint>``
``marker.<name>.<x|y|z>`` m            each marker's position in world
``field_pairs``           count        pairs of geometry inside their fields
``closest_distance``      m            the smallest signed distance among them (NaN: none)
``world_events``          text         the world events applied since the previous row
``<client's columns>``    (its own)    what the client reports (agents' states and actions)
========================  ===========  ==================================================

A world event applied at time t (see :mod:`mobee_drake.station.world_events`) first shows in the
row after t's. A client joins the log by declaring a ``data_log`` system (see
:mod:`mobee_drake.station.parts`).
"""

import dataclasses as dc
import pathlib

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import DiagramBuilder, LeafSystem, OutputPort
from pydrake.systems.primitives import Multiplexer, VectorLogSink

from mobee_drake import __version__
from mobee_drake.atomic_files import WriteFileAtomically
from mobee_drake.mobee.fields import NO_FIELD_PAIRS
from mobee_drake.mobee.system import FORCE_TERMS, Mobee
from mobee_drake.station.config import DataLog
from mobee_drake.station.parts import DATA_LOG_PORT, LogsData
from mobee_drake.world.objects import WorldEvent

FORCE_UNIT = "M rad/s^2"  # MoBeE's forces: virtual mass times joint acceleration (eq. 5.7)


class FieldPairsSummary(LeafSystem):
    """How many pairs of geometry are inside their fields, and the smallest signed distance among
    them (NaN when there is none).

    .. pydrake_system::

        name: FieldPairsSummary
        input_ports:
        - field_pairs
        output_ports:
        - summary
    """

    def __init__(self):
        super().__init__()
        self._pairs_port = self.DeclareAbstractInputPort(
            "field_pairs", AbstractValue.Make(NO_FIELD_PAIRS)
        )
        self.DeclareVectorOutputPort("summary", 2, self._Calc)

    def _Calc(self, context, output) -> None:
        pairs = self._pairs_port.Eval(context)
        closest = pairs.distance.min() if len(pairs) else np.nan
        output.SetFromVector([len(pairs), closest])


def DescribeWorldEvent(event: WorldEvent) -> str:
    """One line for ``event``: its object and what changed."""
    changes = [f"role {event.role}"] if event.role else []
    if event.position:
        changes.append("moved to ({:.3f}, {:.3f}, {:.3f})".format(*event.position))
    return f"{event.object}: {', '.join(changes) or 'unchanged'}"


@dc.dataclass
class DataLogger:
    """The log's sink and how its rows map to the table's columns."""

    config: DataLog
    sink: VectorLogSink
    period: float  # s between rows
    joints: list[str]
    markers: list[str]
    client_columns: list[tuple[str, str]]
    # The world events: the scripted ones by time, and the ports of the clients' requests.
    scripted_events: list[WorldEvent]
    request_ports: list[OutputPort]

    def Table(self, root_context, *, first_row_events: bool = True) -> pa.Table:
        """The samples in ``root_context`` as a table (see the module for its columns); with
        ``first_row_events`` false (a resumed run), the first row lists no world events (those
        applied before it belong to the log of the run resumed)."""
        log = self.sink.FindLog(root_context)
        data = log.data()
        n, m = len(self.joints), len(self.markers)
        columns: list[tuple[str, str, np.ndarray]] = [("time", "s", log.sample_times())]
        row = 0

        def Take(size: int) -> np.ndarray:
            nonlocal row
            block = data[row : row + size]
            row += size
            return block

        for prefix, unit in (("q", "rad"), ("v", "rad/s"), ("q_star", "rad")):
            columns += [(f"{prefix}.{j}", unit, x) for j, x in zip(self.joints, Take(n))]
        for term in (*FORCE_TERMS, "total"):
            force = Take(n)
            if self.config.full_forces:
                columns += [
                    (f"force.{term}.{j}", FORCE_UNIT, x) for j, x in zip(self.joints, force)
                ]
            else:
                columns.append((f"force.{term}", FORCE_UNIT, np.linalg.norm(force, axis=0)))
        positions = Take(3 * m)
        for i, name in enumerate(self.markers):
            columns += [
                (f"marker.{name}.{a}", "m", positions[3 * i + k]) for k, a in enumerate("xyz")
            ]
        pairs, closest = Take(2)
        columns += [
            ("field_pairs", "count", pairs.astype(np.int64)),
            ("closest_distance", "m", closest),
        ]
        counts = Take(1 + len(self.request_ports)).astype(int)
        columns.append(
            ("world_events", "text", self._EventTexts(root_context, counts, first_row_events))
        )
        client = Take(len(self.client_columns))
        columns += [(name, unit, x) for (name, unit), x in zip(self.client_columns, client)]
        arrays = [pa.array(x) for _, _, x in columns]
        schema = pa.schema(
            [
                pa.field(name, a.type, metadata={"unit": unit})
                for (name, unit, _), a in zip(columns, arrays)
            ],
            metadata={
                "mobee_drake_version": __version__,
                "period": str(self.period),
            },
        )
        return pa.Table.from_arrays(arrays, schema=schema)

    def _EventTexts(self, root_context, counts: np.ndarray, first_row_events: bool) -> list[str]:
        """Per row, the world events applied since the previous row."""
        issued = [self.scripted_events] + [
            port.Eval(port.get_system().GetMyContextFromRoot(root_context))
            for port in self.request_ports
        ]
        texts = []
        for k in range(counts.shape[1]):
            if k > 0:
                before = counts[:, k - 1]
            else:
                before = np.zeros_like(counts[:, 0]) if first_row_events else counts[:, 0]
            new = [
                DescribeWorldEvent(event)
                for source, start, end in zip(issued, before, counts[:, k])
                for event in source[start:end]
            ]
            texts.append("; ".join(new))
        return texts

    def Write(self, path: str | pathlib.Path, root_context) -> None:
        """Writes the log of ``root_context`` as Parquet, atomically (a run with checkpoints:
        :class:`CheckpointedLog`)."""
        WriteTable(path, self.Table(root_context))


def WriteTable(path: str | pathlib.Path, table: pa.Table) -> None:
    """Writes ``table`` as Parquet, atomically."""
    WriteFileAtomically(path, lambda staging: pq.write_table(table, staging))


class CheckpointedLog:
    """The data log of a run with checkpoints, saved with them: every checkpoint adds the rows
    since the one before as a segment, ``log/<k>.parquet`` in the checkpoint's folder, and its
    generation records how many segments it covers (:meth:`Save`'s count). A resumed run reads
    exactly the segments of the checkpoint it resumes (:meth:`Resume`; those a killed run wrote
    after it are removed), so its log is the uninterrupted run's, never a file of another run.
    """

    def __init__(self, logger: DataLogger, folder: str | pathlib.Path):
        self._logger, self._folder = logger, pathlib.Path(folder) / "log"
        self._earlier: pa.Table | None = None  # the rows before this process's
        self._resumed_at: float | None = None
        self._count = 0  # segments on disk that count
        self._saved_until = -np.inf  # the last time this process saved

    def _Segment(self, k: int) -> pathlib.Path:
        return self._folder / f"{k:06d}.parquet"

    def Resume(self, count: int, resumed_at: float) -> None:
        """Reads the first ``count`` segments (a checkpoint's) for a run resumed at ``resumed_at``
        and removes the rest."""
        segments = [pq.read_table(self._Segment(k)) for k in range(count)]
        for stale in self._folder.glob("*.parquet"):
            if int(stale.stem) >= count:
                stale.unlink()
        self._earlier = pa.concat_tables(segments) if segments else None
        self._resumed_at, self._count, self._saved_until = resumed_at, count, resumed_at

    def _Current(self, root_context) -> pa.Table:
        """This process's rows after what the segments hold."""
        table = self._logger.Table(root_context, first_row_events=self._resumed_at is None)
        if self._resumed_at is None:
            return table
        return table.filter(pc.greater(table["time"], self._resumed_at))

    def Save(self, root_context) -> int:
        """Writes the rows since the last save as a new segment; returns the segments' count."""
        current = self._Current(root_context)
        new = current.filter(pc.greater(current["time"], self._saved_until))
        if len(new):
            WriteTable(self._Segment(self._count), new)
            self._count += 1
            self._saved_until = float(new["time"][-1].as_py())
        return self._count

    def Table(self, root_context) -> pa.Table:
        """The whole log: the segments of the run resumed, then this process's rows."""
        current = self._Current(root_context)
        if self._earlier is None:
            return current
        return pa.concat_tables([self._earlier.cast(current.schema), current])


def AddDataLog(
    builder: DiagramBuilder,
    *,
    config: DataLog,
    time_step: float,
    mobee: Mobee,
    robot_state: OutputPort,
    attractor: OutputPort,
    event_counts: OutputPort,
    scripted_events: list[WorldEvent],
    request_ports: list[OutputPort],
    clients: list[LogsData],
) -> DataLogger:
    """Adds the log's sink and what it reads to ``builder`` (see the module); the ``clients``
    systems' columns come last, in order."""
    summary = builder.AddNamedSystem("field_pairs_summary", FieldPairsSummary())
    builder.Connect(mobee.GetOutputPort("field_pairs"), summary.get_input_port())
    client_columns = []
    signals = [robot_state, attractor]
    signals.append(mobee.GetOutputPort("forces"))
    signals += [mobee.GetOutputPort("marker_positions"), summary.get_output_port(), event_counts]
    for client in clients:
        client_columns += list(client.DataLogColumns())
        signals.append(client.GetOutputPort(DATA_LOG_PORT))
    mux = builder.AddNamedSystem("data_log_signals", Multiplexer([p.size() for p in signals]))
    for i, port in enumerate(signals):
        builder.Connect(port, mux.get_input_port(i))
    period = config.period or time_step
    sink = builder.AddNamedSystem("data_log", VectorLogSink(mux.get_output_port().size(), period))
    builder.Connect(mux.get_output_port(), sink.get_input_port())
    return DataLogger(
        config=config,
        sink=sink,
        period=period,
        joints=list(mobee.joints),
        markers=list(mobee.marker_names),
        client_columns=client_columns,
        scripted_events=scripted_events,
        request_ports=request_ports,
    )
