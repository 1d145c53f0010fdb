"""A browser that looks at Meshcat as a person does: the system's Chromium driven by Playwright,
headless, WebGL in software (SwiftShader), and an instrumented Meshcat page (issue 35).

What it measures is measured in the page (``performance.now()``, ms since the page's time
origin) or on its websocket:

- :func:`OpenMeshcatPage` opens a live Meshcat server's URL or a saved recording (a file), with
  an init script that patches ``MeshCat.Viewer.prototype`` before the page's own script builds
  its viewer: ``handle_command`` counts the commands by type (the time of the last
  ``set_object`` received and of the ``set_animation``), ``set_object`` the time each path's
  object was put into the scene (a mesh is parsed asynchronously: this is when it is there),
  ``decode`` the websocket messages and their bytes as the page reads them;
- :func:`ViewerState` reads those counters (:class:`ViewerStats`);
- :func:`SceneCensus` lists every node of Meshcat's scene tree: its path, its object's type,
  world position and visibility (its own and its ancestors'), and a line's points in the world;
- :class:`WebsocketTraffic` records the frames received on the page's websockets (Playwright's
  ``framereceived``) with their wall times, for bytes/s and messages/s over a window;
- :func:`SliderLatency` drags a Meshcat slider with the mouse and measures in the page the time
  from the mouse press to the first change of a scene node's world matrix (polled every
  animation frame);
- :func:`SeekRecording` and :func:`ScreenshotAt` show a recording at a given time.

Meshcat's page (Drake's ``meshcat.html``, or ``Meshcat.StaticHtml()``) defines ``window.MeshCat``
by a UMD bundle and then ``var viewer = new MeshCat.Viewer(...)``; a recording's commands are
``fetch("data:...")`` calls handled by ``viewer.handle_command_bytearray``, its animation is
played by ``viewer.animator`` (``pause``, ``seek(t)``: sets every action's time and applies
it, ``duration``).

Playwright (``pip install playwright``) and Chromium (``apt-get install chromium``) are imported
and found only when a browser is opened; without them :class:`BrowserUnavailable` says what to
install.
"""

import dataclasses as dc
import pathlib
import re
import shutil
import tempfile
import time

# Chromium's flags: headless, no sandbox (containers), WebGL in software, nothing fetched.
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
]
VIEWPORT = {"width": 1280, "height": 720}

# Patches Meshcat's viewer class as the page's bundle defines it (before `new MeshCat.Viewer`).
INIT_SCRIPT = r"""
(() => {
  const probe = window.__probe = {
    counts: {}, by_kind: {}, last_set_object_ms: null, animation_ms: null, load_ms: null,
    pending: {}, objects_done: 0, first_object_ms: {}, last_new_object_ms: null,
    messages_at_last_new_object: 0, last_object_ms: null,
    messages: 0, bytes: 0, time_origin: performance.timeOrigin, errors: [], draw: true,
  };
  window.addEventListener('load', () => { probe.load_ms = performance.now(); });
  const Key = (parts) => parts.filter((s) => s.length > 0).join('/');
  function Patch(meshcat) {
    if (!meshcat || !meshcat.Viewer || meshcat.Viewer.prototype.__probed) return;
    const proto = meshcat.Viewer.prototype;
    proto.__probed = true;
    const handle = proto.handle_command;
    proto.handle_command = function (cmd) {
      const type = cmd && cmd.type;
      probe.counts[type] = (probe.counts[type] || 0) + 1;
      const parts = String(cmd.path || '').split('/').filter((s) => s.length > 0);
      const kind = type + ' /' + parts.slice(0, 3).join('/');
      probe.by_kind[kind] = (probe.by_kind[kind] || 0) + 1;
      if (type === 'set_object') {
        probe.last_set_object_ms = performance.now();
        const key = Key(String(cmd.path).split('/'));
        probe.pending[key] = (probe.pending[key] || 0) + 1;
      }
      const result = handle.call(this, cmd);
      if (type === 'set_animation') probe.animation_ms = performance.now();
      return result;
    };
    const setObject = proto.set_object;
    proto.set_object = function (path, object) {
      const result = setObject.call(this, path, object);
      const key = Key(path), now = performance.now();
      if (probe.pending[key] > 0) {  // An object a command asked for (not the viewer's own).
        probe.pending[key] -= 1;
        probe.objects_done += 1;
        probe.last_object_ms = now;
        if (!(key in probe.first_object_ms)) {
          probe.first_object_ms[key] = now;
          probe.last_new_object_ms = now;
          probe.messages_at_last_new_object = probe.messages;
        }
      }
      return result;
    };
    const render = proto.render;
    proto.render = function () {  // Drawing can be suspended (see OpenMeshcatPage).
      if (probe.draw) return render.call(this);
      this.needs_render = false;
    };
    const decode = proto.decode;
    proto.decode = function (message) {
      probe.messages += 1;
      probe.bytes += message.data.byteLength || message.data.length || 0;
      return decode.call(this, message);
    };
  }
  let value;
  Object.defineProperty(window, 'MeshCat', {
    configurable: true, enumerable: true, get() { return value; },
    set(v) { value = v; try { Patch(v); } catch (e) { probe.errors.push(String(e)); } },
  });
})();
"""

# The scene tree, walked without creating nodes (SceneNode.find creates missing ones).
_FIND_NODE = r"""
window.__probeFind = (path) => {
  let node = viewer.scene_tree;
  for (const part of path.split('/').filter((s) => s.length > 0)) {
    node = node.children[part];
    if (node === undefined) return null;
  }
  return node;
};
"""

_CENSUS = r"""
() => {
  const THREE = MeshCat.THREE, rows = [];
  viewer.scene.updateMatrixWorld(true);
  // Meshcat's world (Drake's, z up) is the scene's frame (three.js's world is y up).
  const toMeshcat = viewer.scene.matrixWorld.clone().invert();
  const Walk = (node, path, shown) => {
    const object = node.object, p = new THREE.Vector3();
    object.getWorldPosition(p).applyMatrix4(toMeshcat);
    const visible = shown && object.visible;
    let points = null;
    if ((object.isLine || object.isPoints) && object.geometry
        && object.geometry.attributes.position) {
      const a = object.geometry.attributes.position, v = new THREE.Vector3();
      const n = object.geometry.drawRange.count === Infinity ? a.count
        : Math.min(a.count, object.geometry.drawRange.count);
      points = [];
      for (let i = 0; i < n; ++i) {
        v.fromBufferAttribute(a, i).applyMatrix4(object.matrixWorld).applyMatrix4(toMeshcat);
        points.push([v.x, v.y, v.z]);
      }
    }
    rows.push({path: path || '/', type: object.type, position: [p.x, p.y, p.z],
               visible, points});
    for (const [name, child] of Object.entries(node.children)) {
      Walk(child, path + '/' + name, visible);
    }
  };
  Walk(viewer.scene_tree, '', true);
  return rows;
}
"""

_SEEK = r"""
(t) => {
  const a = viewer.animator;
  a.pause();
  for (const action of a.actions) {
    action.enabled = true;
    action.paused = false;
    if (!action.isScheduled()) action.play();
  }
  a.seek(t);
  a.display_progress(Math.min(t, a.duration));
  viewer.scene.updateMatrixWorld(true);
  viewer.render();
  return a.duration;
}
"""

# Arms a watch of a node's world matrix: re-baselined every frame until the mouse is pressed,
# then the first frame whose matrix differs is the move.
_ARM_MOVE_WATCH = r"""
([path, tolerance]) => {
  const node = window.__probeFind(path);
  if (node === null) return false;
  const watch = window.__probeWatch = {pressed_ms: null, moved_ms: null, done: false};
  const Matrix = () => { node.object.updateWorldMatrix(true, false);
                         return Array.from(node.object.matrixWorld.elements); };
  let base = Matrix();
  window.addEventListener('mousedown', () => { watch.pressed_ms = performance.now(); },
                          {capture: true, once: true});
  const Poll = () => {
    if (watch.done) return;
    const now = Matrix();
    if (watch.pressed_ms === null) base = now;
    else if (now.some((x, i) => Math.abs(x - base[i]) > tolerance)) {
      watch.moved_ms = performance.now();
      watch.done = true;
      return;
    }
    requestAnimationFrame(Poll);
  };
  requestAnimationFrame(Poll);
  return true;
}
"""


class BrowserUnavailable(RuntimeError):
    """No browser to look with: Playwright or Chromium is missing (the message says which)."""


@dc.dataclass
class SceneEntry:
    """One node of Meshcat's scene tree (see :func:`SceneCensus`)."""

    path: str
    type: str
    position: list[float]  # in Meshcat's world (Drake's world, z up; m)
    visible: bool  # its own visibility and all its ancestors'
    points: list[list[float]] | None  # a line's points in Meshcat's world (m), else None


@dc.dataclass
class ViewerStats:
    """The page's counters (see the module); times in ms since the page's time origin."""

    counts: dict[str, int]  # commands handled, by type
    by_kind: dict[str, int]  # commands handled, by type and the first 3 parts of their path
    last_set_object_ms: float | None  # the last set_object command received
    animation_ms: float | None  # the set_animation command handled
    load_ms: float | None  # the page's load event
    pending_objects: int  # set_object commands whose object is not yet in the scene
    objects_done: int  # set_object commands whose object is in the scene
    new_paths: int  # paths that received an object
    last_new_object_ms: float | None  # a path last received its first object
    last_object_ms: float | None  # an object was last put into the scene
    messages_at_last_new_object: int  # websocket messages decoded by then
    messages: int  # websocket messages decoded
    bytes: int  # their bytes
    time_origin: float  # the page's time origin (ms since the epoch)

    @property
    def set_objects(self) -> int:
        return self.counts.get("set_object", 0)

    @property
    def commands(self) -> int:
        return sum(self.counts.values())


@dc.dataclass
class WebsocketTraffic:
    """Frames received on a page's websockets: (wall time in s since the epoch, bytes) each,
    recorded as Playwright delivers them (during any call into the page)."""

    frames: list[tuple[float, int]] = dc.field(default_factory=list)

    def Attach(self, page) -> None:
        """Records the frames of every websocket ``page`` opens from now on."""
        page.on("websocket", lambda ws: ws.on("framereceived", self._Received))

    def _Received(self, payload) -> None:
        size = len(payload.encode() if isinstance(payload, str) else payload)
        self.frames.append((time.time(), size))

    def BytesOfFirst(self, count: int) -> int:
        """The bytes of the first ``count`` frames."""
        return sum(size for _, size in self.frames[:count])

    def Rates(self, start: float, end: float) -> tuple[float, float]:
        """Bytes/s and messages/s received in the wall-time window [start, end]."""
        window = [size for t, size in self.frames if start <= t <= end]
        span = max(end - start, 1e-9)
        return sum(window) / span, len(window) / span


@dc.dataclass
class MeshcatPage:
    """An instrumented Meshcat page and its websocket traffic."""

    page: object  # playwright.sync_api.Page
    traffic: WebsocketTraffic


def FindChromium() -> str:
    """The system's Chromium; BrowserUnavailable if there is none."""
    found = shutil.which("chromium") or shutil.which("chromium-browser")
    if found is None and pathlib.Path("/usr/bin/chromium").exists():
        found = "/usr/bin/chromium"
    if found is None:
        raise BrowserUnavailable("no Chromium found: install it (apt-get install chromium)")
    return found


class BrowserSession:
    """A headless Chromium driven by Playwright, with a fresh user-data folder; use as a context
    manager (closing it ends the browser and removes the folder)."""

    def __init__(self):
        try:
            from playwright.sync_api import sync_playwright
        except ImportError as e:
            raise BrowserUnavailable(
                f"Playwright for Python is missing ({e}): pip install playwright"
            ) from None
        executable = FindChromium()
        self._folder = tempfile.mkdtemp(prefix="mobee_browser_")
        self._playwright = sync_playwright().start()
        try:
            self.context = self._playwright.chromium.launch_persistent_context(
                self._folder,
                executable_path=executable,
                headless=True,
                args=CHROMIUM_ARGS,
                viewport=VIEWPORT,
            )
        except Exception as e:
            self.Close()
            raise BrowserUnavailable(
                f"{executable} did not start under Playwright: {str(e).splitlines()[0]}"
            ) from None

    def Close(self) -> None:
        """Ends the browser and Playwright's driver; removes the user-data folder."""
        context, self.context = getattr(self, "context", None), None
        try:
            if context is not None:
                context.close()
        finally:
            self._playwright.stop()
            shutil.rmtree(self._folder, ignore_errors=True)

    def __enter__(self) -> "BrowserSession":
        return self

    def __exit__(self, *exc) -> None:
        self.Close()


def OpenMeshcatPage(
    session: BrowserSession, url_or_file: str, *, draw: bool = True, timeout: float = 60.0
) -> MeshcatPage:
    """A new page of ``session`` at a Meshcat server's URL or a recording's HTML file (a path),
    instrumented (see the module) and loaded; its websocket traffic recorded from the start.

    With ``draw`` false the viewer draws nothing (its ``render`` returns at once) until
    :func:`SetDrawing` says otherwise: the page's data path (messages handled, the scene graph
    updated) is then timed without the cost of drawing in software, which a person's GPU does
    not pay (SwiftShader takes about a second a frame for the iCub's meshes on a busy 2-core
    machine, and the page handles no message meanwhile)."""
    page = session.context.new_page()
    page.set_default_timeout(1000 * timeout)
    page.add_init_script(INIT_SCRIPT)
    page.add_init_script(f"window.__probe.draw = {'true' if draw else 'false'};")
    page.add_init_script(_FIND_NODE)
    traffic = WebsocketTraffic()
    traffic.Attach(page)
    url = url_or_file
    if "://" not in url_or_file:
        url = pathlib.Path(url_or_file).resolve().as_uri()
    page.goto(url, wait_until="load", timeout=1000 * timeout)
    return MeshcatPage(page=page, traffic=traffic)


def SetDrawing(page, draw: bool) -> None:
    """Resumes (true) or suspends (false) the viewer's drawing (see :func:`OpenMeshcatPage`)."""
    page.evaluate("(draw) => { window.__probe.draw = draw; viewer.set_dirty(); }", draw)


def ViewerState(page) -> ViewerStats:
    """The page's counters (see :class:`ViewerStats`)."""
    p = page.evaluate("window.__probe")
    return ViewerStats(
        counts=dict(p["counts"]),
        by_kind=dict(p["by_kind"]),
        last_set_object_ms=p["last_set_object_ms"],
        animation_ms=p["animation_ms"],
        load_ms=p["load_ms"],
        pending_objects=sum(v for v in p["pending"].values() if v > 0),
        objects_done=p["objects_done"],
        new_paths=len(p["first_object_ms"]),
        last_new_object_ms=p["last_new_object_ms"],
        last_object_ms=p["last_object_ms"],
        messages_at_last_new_object=p["messages_at_last_new_object"],
        messages=p["messages"],
        bytes=p["bytes"],
        time_origin=p["time_origin"],
    )


def PageNow(page) -> float:
    """The page's clock (ms since its time origin)."""
    return page.evaluate("performance.now()")


def SceneCensus(page) -> list[SceneEntry]:
    """Every node of the page's scene tree (see :class:`SceneEntry`), parents first."""
    return [SceneEntry(**row) for row in page.evaluate(_CENSUS)]


def RecordingCommands(html: str | pathlib.Path) -> int:
    """How many commands a saved recording's page replays: its calls
    ``fetch("data:application/octet-binary;base64,...")``, one per command."""
    text = pathlib.Path(html).read_text(errors="replace")
    return text.count('fetch("data:application/octet-binary')


def WaitUntilPlayable(page, commands: int, timeout: float = 180.0) -> float:
    """Waits until a recording's page has handled all its ``commands``, every object is in the
    scene and its animation is loaded; the page's time then (s since its time origin: the
    latest of its load, its last object and its animation)."""
    deadline = time.monotonic() + timeout
    while True:
        stats = ViewerState(page)
        if (
            stats.load_ms is not None
            and stats.commands >= commands
            and stats.animation_ms is not None
            and stats.pending_objects == 0
        ):
            ends = [stats.load_ms, stats.animation_ms, stats.last_object_ms or 0.0]
            return max(ends) / 1000
        if time.monotonic() > deadline:
            raise TimeoutError(
                f"the recording was not playable within {timeout:g} s: {stats.commands} of "
                f"{commands} commands, {stats.pending_objects} objects pending"
            )
        page.wait_for_timeout(100)


def WaitForCompleteScene(page, quiet: float = 3.0, timeout: float = 180.0) -> ViewerStats:
    """Waits until no path has received its first object for ``quiet`` seconds (and none is
    pending) after a first object came; the counters then (the scene was complete at
    ``last_new_object_ms``). TimeoutError after ``timeout`` s."""
    deadline = time.monotonic() + timeout
    while True:
        stats, now = ViewerState(page), PageNow(page)
        last = stats.last_new_object_ms
        if last is not None and stats.pending_objects == 0 and now - last >= 1000 * quiet:
            return stats
        if time.monotonic() > deadline:
            raise TimeoutError(
                f"the scene was not complete within {timeout:g} s: {stats.new_paths} paths, "
                f"{stats.pending_objects} objects pending, {stats.bytes / 1e6:.1f} MB received"
            )
        page.wait_for_timeout(250)


def SeekRecording(page, seconds: float) -> float:
    """Shows the recording in ``page`` at ``seconds`` (paused there, rendered); its duration."""
    return page.evaluate(_SEEK, seconds)


def ScreenshotAt(page, seconds: float, png: str | pathlib.Path) -> None:
    """Writes a PNG of the 3D pane (without Meshcat's controls) at the recording's time
    ``seconds``."""
    SetDrawing(page, True)
    SeekRecording(page, seconds)
    page.add_style_tag(content=".dg.ac, .dg.main, #stats-plot { display: none !important; }")
    page.evaluate("() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)))")
    pathlib.Path(png).parent.mkdir(parents=True, exist_ok=True)
    page.locator("#meshcat-pane").screenshot(path=str(png))


def OpenControls(page) -> None:
    """Opens Meshcat's controls panel (dat.GUI's, closed in a small or headless window) as a
    person does: a click on its "Open Controls" button."""
    button = page.locator(".dg.main > .close-button")
    if button.count() and "Open" in button.first.inner_text():
        button.first.click()
        page.wait_for_timeout(300)  # (dat.GUI's opening transition.)


def SliderBox(page, name: str) -> dict:
    """The bounding box of the track of Meshcat's slider ``name`` (a dat.GUI number controller
    whose property name is ``name``), scrolled into view."""
    label = page.locator(".property-name", has_text=re.compile(rf"^\s*{re.escape(name)}\s*$"))
    item = page.locator("li.cr.number").filter(has=label)
    if item.count() == 0:
        raise ValueError(f"no Meshcat slider '{name}' in the page")
    OpenControls(page)
    slider = item.first.locator(".slider")
    slider.evaluate("(e) => e.scrollIntoView({block: 'center'})")
    box = slider.bounding_box()
    if box is None:
        raise ValueError(f"Meshcat's slider '{name}' is not shown")
    return box


def DragSlider(page, name: str, start: float, end: float, steps: int = 8) -> None:
    """Drags the slider ``name`` with the mouse from ``start`` to ``end`` (fractions of its
    track: 0 its minimum, 1 its maximum)."""
    box = SliderBox(page, name)
    y = box["y"] + box["height"] / 2
    page.mouse.move(box["x"] + start * box["width"], y)
    page.mouse.down()
    page.mouse.move(box["x"] + end * box["width"], y, steps=steps)
    page.mouse.up()


def NodeWorldPosition(page, path: str) -> list[float] | None:
    """The position of the scene node at ``path`` in Meshcat's world (Drake's, z up), or None
    if there is none."""
    return page.evaluate(
        """(path) => { const node = window.__probeFind(path); if (node === null) return null;
        const p = new MeshCat.THREE.Vector3(); viewer.scene.updateMatrixWorld(true);
        node.object.getWorldPosition(p).applyMatrix4(viewer.scene.matrixWorld.clone().invert());
        return [p.x, p.y, p.z]; }""",
        path,
    )


def WaitUntilStill(page, path: str, still: float = 1.0, timeout: float = 30.0) -> bool:
    """Waits until the node at ``path`` has not moved (1e-5 m) for ``still`` s; whether it
    did within ``timeout`` s."""
    deadline = time.monotonic() + timeout
    last, since = NodeWorldPosition(page, path), time.monotonic()
    while time.monotonic() < deadline:
        page.wait_for_timeout(100)
        now = NodeWorldPosition(page, path)
        if now is None or last is None or max(abs(a - b) for a, b in zip(now, last)) > 1e-5:
            last, since = now, time.monotonic()
        elif time.monotonic() - since >= still:
            return True
    return False


def SliderLatency(
    page, slider: str, start: float, end: float, node: str, timeout: float = 10.0
) -> float | None:
    """Drags ``slider`` from ``start`` to ``end`` (fractions of its track) and returns the time
    (s) from the mouse press to the first change of the world matrix of the scene node at
    ``node`` (both in the page), or None if it did not change within ``timeout`` s."""
    SliderBox(page, slider)  # (Opens the controls first: that click is no drag.)
    if not page.evaluate(_ARM_MOVE_WATCH, [node, 1e-6]):
        raise ValueError(f"no scene node '{node}' in the page")
    DragSlider(page, slider, start, end)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        watch = page.evaluate("window.__probeWatch")
        if watch is None:
            raise RuntimeError("the Meshcat page reloaded during the drag (its server restarted?)")
        if watch["moved_ms"] is not None:
            return (watch["moved_ms"] - watch["pressed_ms"]) / 1000
        page.wait_for_timeout(20)
    page.evaluate("window.__probeWatch.done = true")
    return None
