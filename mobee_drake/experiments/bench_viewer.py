"""Benchmark: Meshcat as a person gets it. A headless Chromium (Playwright driving the system's
chromium, WebGL in software; see mobee_drake/experiments/browser_probe.py) looks at the main
job's recording and at a live interactive run as a person would.

It measures, in the page:

- the main job's recording (``mobee-drake run reach_around_ball --record FILE``, its data log
  left out): the HTML's size (MB), and the time from opening the file until it is playable
  (the page loaded, every command of the file handled, every object in the scene and the
  animation loaded: the page's clock, from its navigation);
- the live view (``mobee-drake run interactive --meshcat --duration 300``, its recording and
  log in a temporary folder; the URL is the one Drake prints): the time from opening the URL
  until the scene is complete and the bytes received until then (complete: no path received
  its first object for 3 s; the time is that of the last path's first object, the bytes those
  of the websocket frames received until that message). The page measured is the second one
  opened: a first one waits for the scene to be complete, so that the server is running and
  the station's build is not counted;
- the live stream: bytes/s and messages/s received over 10 s while the bench drags a slider
  (``r_shoulder_pitch``) back and forth (1 s between drags), so that the robot moves;
- the slider latency: 5 drags of that slider, the robot still before each; per drag the time
  from the mouse press on the slider to the first change of the world matrix of the robot's
  right hand (``.../r_hand`` under ``/drake/illustration``, found in the scene's census),
  polled every animation frame in the page; the median and the largest.

The page does not draw while it is timed (``--draw`` to draw): drawing the iCub's meshes in
software takes about a second a frame on this 2-core machine, during which the page handles no
message; a person's GPU draws them in milliseconds, so the figures without drawing are the
viewer's own (and with drawing the page reads the stream only as fast as it draws, which hides
what the server sends).

The figures are written to ``RESULTS/bench_viewer_LABEL.json`` and printed beside the issue's
targets; ``--doc FILE`` rewrites the generated block ``viewer`` there with one column per
stored label (``before``, ``after``, then any other); ``--screenshots DIR`` writes PNGs of the
recording at 0, 2 and 15 s (``main_job_0s.png``, ...).

Run: ``mobee-drake bench viewer --label before [--doc docs/benchmarks.md] [--screenshots DIR]``.
"""

import dataclasses as dc
import datetime
import json
import os
import pathlib
import re
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time

from mobee_drake.atomic_files import StrictJson, WriteTextAtomically
from mobee_drake.experiments import browser_probe
from mobee_drake.experiments.arguments import CommandParser, NonEmpty, PositiveFloat, PositiveInt
from mobee_drake.experiments.browser_probe import BrowserSession, BrowserUnavailable
from mobee_drake.experiments.doc_tables import CheckDocBlocks, WriteGeneratedTable

MAIN_JOB = "reach_around_ball"
LIVE_SCENARIO = "interactive"
SLIDER = "r_shoulder_pitch"
# The robot's link watched for the slider's effect: the right hand, downstream of the shoulder.
HAND_LINK = "r_hand"
# Where a drag starts and ends, as fractions of the slider's track (alternating directions).
DRAG = (0.3, 0.7)
STREAM_SECONDS = 10.0
QUIET_SECONDS = 3.0
SCREENSHOT_TIMES = (0.0, 2.0, 15.0)
DOC_BLOCK = "viewer"
# The targets: (the result's field, what it is, the largest acceptable value).
TARGETS = [
    ("recording_mb", "main job's recording (MB)", 5.0),
    ("recording_playable_s", "main job's recording playable after (s)", 3.0),
    ("live_complete_s", "live scene complete after (s)", 5.0),
    ("live_complete_mb", "live scene's bytes until complete (MB)", 3.0),
    ("stream_kb_per_s", "live stream while a slider moves (kB/s)", 100.0),
    ("stream_messages_per_s", "live stream while a slider moves (messages/s)", 300.0),
    ("slider_latency_median_s", "slider to the robot's hand, median (s)", 0.5),
    ("slider_latency_max_s", "slider to the robot's hand, largest (s)", 0.5),
]


@dc.dataclass
class ViewerResult:
    """One run of the benchmark (see the module for what each figure is)."""

    label: str
    date: str
    draw: bool  # whether the page drew while timed
    recording_mb: float
    recording_playable_s: float
    # The live view's figures: None where it could not be measured (``live_failure`` says why).
    live_complete_s: float | None
    live_complete_mb: float | None
    stream_kb_per_s: float | None
    stream_messages_per_s: float | None
    slider_latency_median_s: float | None  # None: the hand never moved
    slider_latency_max_s: float | None
    slider_latencies_s: list[float | None]
    live_paths: int | None  # paths that received an object by the scene's completion
    slider: str
    hand_node: str
    # The stream's commands/s by type and path (its first 3 parts), largest first.
    stream_by_kind_per_s: dict[str, float] = dc.field(default_factory=dict)
    live_failure: str = ""

    def Save(self, path: pathlib.Path) -> None:
        path.parent.mkdir(parents=True, exist_ok=True)
        WriteTextAtomically(path, StrictJson(dc.asdict(self), indent=1) + "\n")

    @staticmethod
    def Load(path: pathlib.Path) -> "ViewerResult":
        return ViewerResult(**json.loads(pathlib.Path(path).read_text()))


@dc.dataclass
class LiveFigures:
    """What :func:`MeasureLive` measures."""

    complete_s: float
    complete_mb: float
    paths: int
    stream_kb_per_s: float
    stream_messages_per_s: float
    latencies_s: list[float | None]
    hand_node: str
    by_kind_per_s: dict[str, float]
    failure: str = ""  # why the figures are missing, if they are

    @staticmethod
    def Failed(why: str) -> "LiveFigures":
        return LiveFigures(None, None, None, None, None, [], "", {}, why)


# The folder this package was imported from: the runs it starts import the same package (``python
# -m`` would put the working directory first on their path, before PYTHONPATH).
PACKAGE_ROOT = str(pathlib.Path(__file__).resolve().parents[2])


def PackageCommand(*args: str) -> list[str]:
    """``mobee-drake ARGS`` run by this Python, on this very package."""
    start = f"import sys; sys.path.insert(0, {PACKAGE_ROOT!r}); from mobee_drake.cli import main"
    return [sys.executable, "-c", f"{start}; main(sys.argv[1:])", *args]


def Shown(command: list[str]) -> str:
    """A :func:`PackageCommand` as a person would type it."""
    return " ".join(["mobee-drake", *command[3:]])


def RecordMainJob(folder: pathlib.Path, *, log: bool = False, timeout: float = 600.0):
    """Runs the main job (``mobee-drake run reach_around_ball``) with its recording written to
    ``folder/main_job.html`` (and its data log beside it if ``log``); the recording's path.
    RuntimeError with the end of its output if the run fails."""
    html = pathlib.Path(folder) / "main_job.html"
    command = PackageCommand("run", MAIN_JOB, "--record", str(html))
    if not log:
        command.append("--no-log")
    done = subprocess.run(command, capture_output=True, text=True, timeout=timeout)
    if done.returncode != 0 or not html.is_file():
        tail = (done.stdout + done.stderr).strip().splitlines()[-5:]
        raise RuntimeError(f"{Shown(command)} failed: " + " | ".join(tail))
    return html


class LiveServer:
    """``mobee-drake run SCENARIO --meshcat`` in a process group of its own, its output drained
    by a thread; a context manager that ends the group (SIGTERM, then SIGKILL) on exit."""

    URL = re.compile(r"Meshcat listening for connections at (\S+)")

    def __init__(self, folder: pathlib.Path, *, scenario: str = LIVE_SCENARIO, seconds=300.0):
        folder = pathlib.Path(folder)
        self.command = PackageCommand(
            *("run", scenario, "--meshcat", "--duration", f"{seconds:g}"),
            *("--record", str(folder / f"{scenario}.html")),
            *("--log", str(folder / f"{scenario}.log.parquet")),
        )
        self.output: list[str] = []
        self.process = subprocess.Popen(
            self.command,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            start_new_session=True,
        )
        self._reader = threading.Thread(target=self._Drain, daemon=True)
        self._reader.start()

    def _Drain(self) -> None:
        for line in self.process.stdout:
            self.output.append(line)

    def WaitForUrl(self, timeout: float = 180.0) -> str:
        """The URL the server printed; RuntimeError if it ended or printed none in time."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            for line in list(self.output):
                match = self.URL.search(line)
                if match:
                    return match[1]
            if self.process.poll() is not None:
                break
            time.sleep(0.2)
        tail = " | ".join(line.strip() for line in self.output[-5:])
        raise RuntimeError(f"{Shown(self.command)} printed no Meshcat URL: {tail}")

    def Stop(self) -> None:
        """Ends the server's process group (and waits for it)."""
        if self.process.poll() is None:
            for sig, wait in ((signal.SIGTERM, 10.0), (signal.SIGKILL, 10.0)):
                try:
                    os.killpg(self.process.pid, sig)
                    self.process.wait(timeout=wait)
                    break
                except ProcessLookupError:
                    break
                except subprocess.TimeoutExpired:
                    continue
        self._reader.join(timeout=5.0)

    def __enter__(self) -> "LiveServer":
        return self

    def __exit__(self, *exc) -> None:
        self.Stop()


def HandNode(census: list[browser_probe.SceneEntry], link: str = HAND_LINK) -> str:
    """The path of the robot's (not the attractor's) ``link`` under ``/drake/illustration``;
    ValueError if the scene has none."""
    paths = [
        e.path
        for e in census
        if e.path.startswith("/drake/illustration/")
        and e.path.endswith("/" + link)
        and "/attractor" not in e.path
    ]
    if not paths:
        raise ValueError(f"no robot link '{link}' under /drake/illustration in the scene")
    return min(paths, key=len)


def MeasureRecording(session: BrowserSession, html, *, draw: bool, timeout: float, shots=None):
    """The recording's size (MB) and the time (s) until the browser can play it; with
    ``shots`` (a folder) PNGs of it at :data:`SCREENSHOT_TIMES`."""
    html = pathlib.Path(html)
    opened = browser_probe.OpenMeshcatPage(session, str(html), draw=draw, timeout=timeout)
    try:
        commands = browser_probe.RecordingCommands(html)
        playable = browser_probe.WaitUntilPlayable(opened.page, commands, timeout)
        for seconds in SCREENSHOT_TIMES if shots else ():
            png = pathlib.Path(shots) / f"main_job_{seconds:g}s.png"
            browser_probe.ScreenshotAt(opened.page, seconds, png)
            print(f"screenshot: {png}", flush=True)
    finally:
        opened.page.close()
    return html.stat().st_size / 1e6, playable


def DragBackAndForth(page, slider: str, seconds: float) -> tuple[float, float]:
    """Drags ``slider`` back and forth (1 s apart) for ``seconds``; the wall-time window."""
    start = time.time()
    forth = True
    while time.time() - start < seconds:
        begin, end = DRAG if forth else DRAG[::-1]
        browser_probe.DragSlider(page, slider, begin, end)
        page.wait_for_timeout(1000)
        forth = not forth
    return start, time.time()


def SliderLatencies(page, slider: str, node: str, drags: int) -> list[float | None]:
    """The latency of ``drags`` drags of ``slider`` (alternating directions), the node at
    ``node`` still before each (see :func:`browser_probe.SliderLatency`)."""
    latencies = []
    for k in range(drags):
        if not browser_probe.WaitUntilStill(page, node, still=1.0, timeout=30.0):
            raise RuntimeError(f"the robot's {node} did not come to rest within 30 s")
        begin, end = DRAG if k % 2 == 0 else DRAG[::-1]
        latencies.append(browser_probe.SliderLatency(page, slider, begin, end, node))
    return latencies


def WaitForRunningServer(session: BrowserSession, url: str, timeout: float) -> None:
    """Waits until the server at ``url`` serves a complete scene (a first page sees it; then
    the station is built and the run under way: what a second page measures is the viewer's
    alone, not the station's build)."""
    opened = browser_probe.OpenMeshcatPage(session, url, draw=False, timeout=timeout)
    try:
        browser_probe.WaitForCompleteScene(opened.page, QUIET_SECONDS, timeout)
    finally:
        opened.page.close()


def _RatesByKind(first: dict, last: dict, seconds: float) -> dict[str, float]:
    rates = {k: (n - first.get(k, 0)) / seconds for k, n in last.items()}
    return dict(sorted(((k, r) for k, r in rates.items() if r > 0), key=lambda kr: -kr[1]))


def MeasureLive(session: BrowserSession, url: str, *, draw: bool, timeout: float, drags: int):
    """The live view's figures (see the module) at a Meshcat server's ``url``."""
    WaitForRunningServer(session, url, timeout)
    opened = browser_probe.OpenMeshcatPage(session, url, draw=draw, timeout=timeout)
    page, traffic = opened.page, opened.traffic
    try:
        stats = browser_probe.WaitForCompleteScene(page, QUIET_SECONDS, timeout)
        node = HandNode(browser_probe.SceneCensus(page))
        first = browser_probe.ViewerState(page).by_kind
        start, end = DragBackAndForth(page, SLIDER, STREAM_SECONDS)
        bytes_per_s, messages_per_s = traffic.Rates(start, end)
        by_kind = _RatesByKind(first, browser_probe.ViewerState(page).by_kind, end - start)
        latencies = SliderLatencies(page, SLIDER, node, drags)
    finally:
        page.close()
    return LiveFigures(
        complete_s=stats.last_new_object_ms / 1000,
        complete_mb=traffic.BytesOfFirst(stats.messages_at_last_new_object) / 1e6,
        paths=stats.new_paths,
        stream_kb_per_s=bytes_per_s / 1e3,
        stream_messages_per_s=messages_per_s,
        latencies_s=latencies,
        hand_node=node,
        by_kind_per_s=by_kind,
    )


def RunBenchmark(args) -> ViewerResult:
    """Runs the main job and the live view and measures both (see the module)."""
    with tempfile.TemporaryDirectory(prefix="bench_viewer_") as folder:
        print(f"main job: mobee-drake run {MAIN_JOB} --record ...", flush=True)
        html = RecordMainJob(pathlib.Path(folder))
        with BrowserSession() as session:
            size, playable = MeasureRecording(
                session, html, draw=args.draw, timeout=args.timeout, shots=args.screenshots
            )
            print(f"recording: {size:.1f} MB, playable after {playable:.2f} s", flush=True)
            with LiveServer(pathlib.Path(folder), seconds=args.live_seconds) as server:
                url = server.WaitForUrl(args.timeout)
                print(f"live view: {Shown(server.command)} at {url}", flush=True)
                try:
                    live = MeasureLive(
                        session, url, draw=args.draw, timeout=args.timeout, drags=args.drags
                    )
                except (RuntimeError, TimeoutError, ValueError) as error:  # Kept, with why.
                    print(f"the live view could not be measured: {error}", flush=True)
                    live = LiveFigures.Failed(str(error))
    moved = [s for s in live.latencies_s if s is not None]
    return ViewerResult(
        label=args.label,
        date=datetime.datetime.now().isoformat(timespec="seconds"),
        draw=args.draw,
        recording_mb=size,
        recording_playable_s=playable,
        live_complete_s=live.complete_s,
        live_complete_mb=live.complete_mb,
        stream_kb_per_s=live.stream_kb_per_s,
        stream_messages_per_s=live.stream_messages_per_s,
        slider_latency_median_s=statistics.median(moved) if moved else None,
        slider_latency_max_s=max(moved) if moved and len(moved) == len(live.latencies_s) else None,
        slider_latencies_s=live.latencies_s,
        live_paths=live.paths,
        stream_by_kind_per_s=live.by_kind_per_s,
        slider=SLIDER,
        hand_node=live.hand_node,
        live_failure=live.failure,
    )


_RECORDING_FIELDS = ("recording_mb", "recording_playable_s")


def _Figure(value: float | None) -> str:
    if value is None:
        return "never"
    return f"{value:.0f}" if value >= 100 else f"{value:.3g}"


def Table(results: list[ViewerResult]) -> str:
    """A markdown table: one row per figure, its target, and one column per result (a live
    figure that could not be measured reads "failed", and a note below says why)."""
    header = "| | target | " + " | ".join(r.label for r in results) + " |"
    lines = [header, "|---|---:|" + "---:|" * len(results)]
    for field, what, target in TARGETS:
        cells = " | ".join(
            "failed" if r.live_failure and field not in _RECORDING_FIELDS
            else _Figure(getattr(r, field))
            for r in results
        )  # fmt: skip
        lines.append(f"| {what} | <= {target:g} | {cells} |")
    notes = [
        f"- {r.label}: the live view failed: {r.live_failure}" for r in results if r.live_failure
    ]
    return "\n".join(lines + ([""] + notes if notes else []))


def StoredResults(folder: pathlib.Path) -> list[ViewerResult]:
    """The results stored in ``folder``: ``before``, ``after``, ``before-drawn``,
    ``after-drawn``, then the other labels."""
    results = [ViewerResult.Load(p) for p in sorted(folder.glob("bench_viewer_*.json"))]
    order = {"before": 0, "after": 1, "before-drawn": 2, "after-drawn": 3}
    return sorted(results, key=lambda r: (order.get(r.label, 2), r.label))


def _Parser() -> CommandParser:
    parser = CommandParser(prog="mobee-drake bench viewer", description=__doc__)
    parser.add_argument(
        "--label", default="current", help="names the result (e.g. before, after) and its file"
    )
    parser.add_argument(
        "--results", type=NonEmpty, default="results", help="the folder of the result files"
    )
    parser.add_argument("--doc", help="rewrite the generated block 'viewer' of this file")
    parser.add_argument(
        "--report-only", action="store_true", help="run nothing: --doc from the stored results"
    )
    parser.add_argument("--screenshots", help="write PNGs of the main job's recording here")
    parser.add_argument("--drags", type=PositiveInt, default=5, help="drags timed for latency")
    parser.add_argument(
        "--draw", action="store_true", help="let the page draw while timed (see above)"
    )
    parser.add_argument(
        "--timeout",
        type=PositiveFloat,
        default=180.0,
        help="seconds to wait for a page to be playable or complete, or the server's URL",
    )
    parser.add_argument(
        "--live-seconds", type=PositiveFloat, default=300.0, help="the live run's duration"
    )
    return parser


def _Terminate(signum, frame) -> None:
    raise SystemExit(128 + signum)  # (So that the live server and the browser are ended.)


def main(argv=None) -> None:
    parser = _Parser()
    args = parser.parse_args(argv)
    if not re.fullmatch(r"[A-Za-z0-9_.-]+", args.label):
        parser.error(f"--label: letters, digits, '_', '.' or '-' only, got '{args.label}'")
    if args.report_only and not args.doc:
        parser.error("--report-only needs --doc")
    CheckDocBlocks(parser, args.doc, DOC_BLOCK)  # Checked before anything runs.
    folder = pathlib.Path(args.results)
    if not args.report_only:
        signal.signal(signal.SIGTERM, _Terminate)
        try:
            result = RunBenchmark(args)
        except (BrowserUnavailable, RuntimeError, TimeoutError, ValueError) as error:
            sys.exit(f"mobee-drake bench viewer: {error}")
        path = folder / f"bench_viewer_{args.label}.json"
        result.Save(path)
        print("\n" + Table([result]))
        print(f"\nlatencies (s): {result.slider_latencies_s}; drawing: {result.draw}")
        kinds = list(result.stream_by_kind_per_s.items())[:6]
        print("the stream's commands/s: " + ", ".join(f"{k} {r:.0f}" for k, r in kinds))
        print(f"result: {path}")
    if args.doc:
        stored = StoredResults(folder)
        command = f"mobee-drake bench viewer --report-only --doc {args.doc}"
        if args.results != _Parser().get_default("results"):
            command += f" --results {args.results}"
        WriteGeneratedTable(args.doc, DOC_BLOCK, command, Table(stored))
        print(f"{args.doc}: block '{DOC_BLOCK}' rewritten ({len(stored)} results)")


if __name__ == "__main__":
    main()
