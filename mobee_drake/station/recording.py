"""A Meshcat recording made smaller without changing what it plays.

Drake's recording keeps a keyframe of every moving path at every recorded frame, also while the
path stands still: in the main job the robot settles after 3 s of 15, and three quarters of the
recording's animation repeats itself. :func:`CompactRecording` drops the keyframes inside runs
of values within half the ``tolerance`` of the run's first one; the animation interpolates
linearly between the keyframes kept, so every frame plays within ``tolerance`` of the original.

The recording is the HTML of ``Meshcat.StaticHtml()``: Drake embeds each command as msgpack in a
base64 data URI; the animation is the one ``set_animation`` command.
"""

import base64
import html
import re

import msgpack
import numpy as np

# A tenth of a millimetre, or 1e-4 of a unit quaternion's component (about 0.01 degrees): far
# below what a person sees (`mobee-drake bench viewer` prints the recording's size).
KEYFRAME_TOLERANCE = 1e-4
_COMMAND = re.compile(r'fetch\("data:application/octet-binary;base64,([A-Za-z0-9+/=]*)"\)')


def ThinKeyframes(keys: list[dict], tolerance: float = KEYFRAME_TOLERANCE) -> list[dict]:
    """The keyframes of one track (``{"time": frame, "value": v}``, in time order) without those
    inside a run of values within ``tolerance / 2`` of the run's first; both ends of a run stay,
    so linear interpolation between the kept keyframes is within ``tolerance`` of every
    original."""
    if len(keys) < 3:
        return keys
    values = [np.atleast_1d(np.asarray(k["value"], dtype=float)) for k in keys]
    kept, anchor, half = [keys[0]], values[0], tolerance / 2
    for i in range(1, len(keys) - 1):
        still = np.abs(values[i] - anchor).max() <= half
        if still and np.abs(values[i + 1] - anchor).max() <= half:
            continue
        kept.append(keys[i])
        anchor = values[i]
    kept.append(keys[-1])
    return kept


def _Compact(match: re.Match, tolerance: float) -> str:
    command = msgpack.unpackb(base64.b64decode(match.group(1)), strict_map_key=False)
    if command.get("type") != "set_animation":
        return match.group(0)
    for animation in command["animations"]:
        for track in animation["clip"]["tracks"]:
            track["keys"] = ThinKeyframes(track["keys"], tolerance)
    encoded = base64.b64encode(msgpack.packb(command)).decode("ascii")
    return match.group(0).replace(match.group(1), encoded)


def CompactRecording(html: str, tolerance: float = KEYFRAME_TOLERANCE) -> str:
    """``html`` (a Meshcat recording) with its animation's still keyframes dropped."""
    return _COMMAND.sub(lambda m: _Compact(m, tolerance), html)


def NotebookFrame(recording: str, width: int = 800, height: int = 450) -> str:
    """An ``<iframe>`` that holds ``recording`` (a Meshcat recording's HTML) itself, for a
    notebook's output: it replays once the notebook is saved and its Meshcat server is gone."""
    return (
        f'<iframe srcdoc="{html.escape(recording)}" width="{width}" height="{height}" '
        'style="border: none"></iframe>'
    )
