"""The reference of a scenario file's keys, generated from the config dataclasses themselves.

Every key of a scenario is a field of :class:`~mobee_drake.scenario.Scenario` or of a dataclass
it holds; the comment above a field in the source is its documentation (Drake's style for config
structs). :func:`ScenarioReference` walks them: one section per dataclass, one row per key with
its type, its default and its comment; a field that takes one of several tagged classes (``!Tag
{...}`` in YAML) lists the tags, each with its own section. ``mobee-drake scenarios
--reference`` prints it; docs/scenario_reference.md is its output (tested).
"""

import dataclasses as dc
import inspect
import re
import types
import typing

from mobee_drake.scenario import Scenario


def _Comments(cls: type) -> dict[str, str]:
    """Each field's comment: the ``#`` lines right above it in ``cls``'s own source."""
    comments, pending = {}, []
    for line in inspect.getsource(cls).splitlines():
        text = line.strip()
        if text.startswith("#"):
            pending.append(text.lstrip("# "))
            continue
        field = re.match(r"(\w+)\s*:", text)
        if field and pending:
            comments[field.group(1)] = " ".join(pending)
        pending = []
    return comments


def _AllComments(cls: type) -> dict[str, str]:
    """The comments of ``cls``'s fields, its base classes' included."""
    comments = {}
    for base in reversed(cls.__mro__):
        if dc.is_dataclass(base):
            comments.update(_Comments(base))
    return comments


def _Classes(annotation) -> list[type]:
    """The dataclasses a field's type may hold (the tags of a union, a list's items)."""
    if dc.is_dataclass(annotation):
        return [annotation]
    return [c for arg in typing.get_args(annotation) for c in _Classes(arg)]


def _TypeName(annotation) -> str:
    if isinstance(annotation, types.UnionType) or typing.get_origin(annotation) is typing.Union:
        classes = _Classes(annotation)
        if len(classes) > 1:
            return "one of " + ", ".join(f"`!{c.__name__}`" for c in classes)
        if classes and type(None) in typing.get_args(annotation):
            return f"`{classes[0].__name__}` or none"
    if typing.get_origin(annotation) is list and _Classes(annotation):
        return "list of " + " or ".join(f"`{c.__name__}`" for c in _Classes(annotation))
    if typing.get_origin(annotation) in (list, dict):
        return str(annotation).replace("typing.", "")
    if not dc.is_dataclass(annotation) and hasattr(annotation, "__module__"):
        if annotation.__module__.startswith("pydrake"):
            return f"Drake's `{annotation.__name__}`"
    return getattr(annotation, "__name__", str(annotation))


def _Default(field: dc.Field, tagged: bool) -> str:
    if field.default is not dc.MISSING:
        value = field.default
    elif field.default_factory is not dc.MISSING:
        value = field.default_factory()
    else:
        return "(required)"
    if dc.is_dataclass(value):
        return f"`!{type(value).__name__}`" if tagged else "(its section)"
    return f"`{value!r}`"


def _Section(cls: type) -> list[str]:
    hints, comments = typing.get_type_hints(cls), _AllComments(cls)
    doc = " ".join((inspect.getdoc(cls) or "").split())
    lines = [
        f"### `{cls.__name__}`",
        "",
        doc,
        "",
        "| key | type | default | what |",
        "|---|---|---|---|",
    ]
    for field in dc.fields(cls):
        what = comments.get(field.name, "").replace("|", "\\|")
        hint = hints[field.name]
        default = _Default(field, len(_Classes(hint)) > 1)
        lines.append(f"| `{field.name}` | {_TypeName(hint)} | {default} | {what} |")
    return lines + [""]


HEADER = """# Scenario files: every key

Written by `mobee-drake scenarios --reference > docs/scenario_reference.md` from the config
dataclasses and the comments above their fields (a test checks it is up to date). A scenario is
a YAML file of the `Scenario` keys below; a key left out keeps its default; `!Tag {...}` picks
one of several classes (e.g. `mover: !Dynamic {control: force}`). `mobee-drake scenarios NAME`
prints a shipped scenario to start from.

"""


def ScenarioReference() -> str:
    """The reference of every key of a scenario file (markdown, with its header)."""
    seen, order, queue = set(), [], [Scenario]
    while queue:
        cls = queue.pop(0)
        if cls in seen:
            continue
        seen.add(cls)
        order.append(cls)
        hints = typing.get_type_hints(cls)
        queue += [c for f in dc.fields(cls) for c in _Classes(hints[f.name])]
    return HEADER + "\n".join(line for cls in order for line in _Section(cls)).rstrip() + "\n"
