"""Loads YAML files into typed dataclasses with Drake's loader; errors name the file and line.

Drake's ``yaml_load_typed`` reports *what* is wrong ("The fields ['shap'] were unknown to the
schema", "could not convert string to float: 'x'") but not *where*. Every file this package reads
goes through :func:`LoadYamlFile`, which re-raises such errors as :class:`YamlFileError`
carrying the file name and, when the offending key or value can be found in the text, its
line number.

Before Drake reads a file, :func:`CheckYamlStructure` walks its events (no recursion, no alias
expanded) and refuses nesting deeper than :data:`MAX_YAML_DEPTH` (PyYAML's composer and Drake's
reader recurse, so a deeper file would end in a ``RecursionError``) and aliases that repeat more
than :data:`MAX_ALIAS_NODES` nodes in all (a "billion laughs" file: a few lines whose nested
aliases expand to billions of nodes, which Drake's reader would walk for hours).
"""

import dataclasses as dc
import difflib
import pathlib
import re
import typing

from pydrake.common.yaml import yaml_load_typed
import yaml

# libyaml's parser where PyYAML was built with it (its wheels are), for speed; the same events.
_SafeLoader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


class YamlFileError(ValueError):
    """A YAML file that does not match its schema; the message names the file and line."""


# Nesting deeper than this is refused (our schemas nest a few levels).
MAX_YAML_DEPTH = 100
# Aliases (``*name``) may repeat at most this many nodes in all.
MAX_ALIAS_NODES = 10_000


def CheckYamlStructure(text: str, source: str) -> None:
    """Refuses nesting deeper than :data:`MAX_YAML_DEPTH`, aliases that repeat more than
    :data:`MAX_ALIAS_NODES` nodes and a key given twice in one mapping (YAML keeps the last,
    silently), reading the parser's events one at a time (linear time).

    Raises:
        YamlFileError: naming ``source`` and the line; yaml.MarkedYAMLError for invalid YAML.
    """
    sizes: dict[str, int] = {}  # an anchor's node count, its aliases expanded
    open_nodes: list[list] = []  # [anchor, node count so far] of each open collection
    repeated = 0
    mappings: list = []  # per open collection: [next is a key, keys seen], None for a sequence
    for event in _Events(text, source):
        line = event.start_mark.line + 1
        if isinstance(event, yaml.NodeEvent) and mappings and mappings[-1] is not None:
            _CheckKey(mappings[-1], event, f"{source}:{line}")
        if isinstance(event, yaml.CollectionStartEvent):
            mappings.append([True, set()] if isinstance(event, yaml.MappingStartEvent) else None)
            if len(open_nodes) >= MAX_YAML_DEPTH:
                raise YamlFileError(f"{source}:{line}: nested deeper than {MAX_YAML_DEPTH} levels")
            open_nodes.append([event.anchor, 1])
            continue
        if isinstance(event, yaml.ScalarEvent):
            anchor, size = event.anchor, 1
        elif isinstance(event, yaml.AliasEvent):
            anchor, size = None, sizes.get(event.anchor, 1)
            repeated += size
            if repeated > MAX_ALIAS_NODES:
                raise YamlFileError(
                    f"{source}:{line}: aliases repeat more than {MAX_ALIAS_NODES} nodes (here "
                    f"*{event.anchor}); write the data out instead"
                )
        elif isinstance(event, yaml.CollectionEndEvent):
            mappings.pop()
            anchor, size = open_nodes.pop()
        else:
            continue
        if anchor is not None:
            sizes[anchor] = size
        if open_nodes:
            open_nodes[-1][1] += size


def InvalidYaml(source: str, error: yaml.YAMLError) -> str:
    """The one-line message of a YAML text that PyYAML could not read: where (the line, when
    PyYAML knows it) and why (a syntax error, or a character YAML does not allow)."""
    mark = getattr(error, "problem_mark", None)
    where = f"{source}:{mark.line + 1}" if mark is not None else source
    if isinstance(error, yaml.reader.ReaderError):
        character = error.character
        character = chr(character) if isinstance(character, int) else character
        problem = f"character {character!r} is not allowed in YAML ({error.reason})"
    else:
        problem = getattr(error, "problem", None) or str(error).splitlines()[0]
    return f"{where}: invalid YAML: {problem}"


def _Events(text: str, source: str):
    """The parser's events of ``text``; libyaml's own depth limit (deeper than ours) reported
    as ours."""
    try:
        yield from yaml.parse(text, Loader=_SafeLoader)
    except yaml.MarkedYAMLError as error:
        if "nesting depth" not in str(error.problem):
            raise
        raise YamlFileError(
            f"{source}:{error.problem_mark.line + 1}: nested deeper than {MAX_YAML_DEPTH} levels"
        ) from None


def _CheckKey(mapping: list, event: yaml.NodeEvent, where: str) -> None:
    """``mapping``'s next node ``event``: a key (refused if it was given before) or a value."""
    if mapping[0] and isinstance(event, yaml.ScalarEvent):
        if event.value in mapping[1]:
            raise YamlFileError(f"{where}: key '{event.value}' given twice (YAML keeps the last)")
        mapping[1].add(event.value)
    mapping[0] = not mapping[0]


def LineOf(text: str, names: list[str]) -> int | None:
    """The 1-based line of the first mapping key or scalar of ``text`` that is in ``names``."""
    quoted = set(names)
    if not quoted:
        return None
    try:
        root = yaml.compose(text, Loader=_SafeLoader)
    except yaml.YAMLError:
        return None
    stack = [root] if root is not None else []
    while stack:
        node = stack.pop(0)
        if isinstance(node, yaml.MappingNode):
            for key, value in node.value:
                if key.value in quoted:
                    return key.start_mark.line + 1
                stack.append(value)
        elif isinstance(node, yaml.SequenceNode):
            stack.extend(node.value)
        elif isinstance(node, yaml.ScalarNode) and node.value in quoted:
            return node.start_mark.line + 1
    return None


def _FieldNames(schema) -> set[str]:
    """Every field name of ``schema`` and of the dataclasses its fields may hold (unions, lists
    and dicts looked into)."""
    names, seen, stack = set(), set(), [schema]
    while stack:
        kind = stack.pop()
        if dc.is_dataclass(kind) and kind not in seen:
            seen.add(kind)
            names.update(f.name for f in dc.fields(kind))
            stack.extend(typing.get_type_hints(kind).values())
        else:
            stack.extend(typing.get_args(kind))
    return names


def DidYouMean(schema, message: str) -> str:
    """Drake's message of fields unknown to ``schema`` with, for each, the closest known field
    name, if one is close (a typo), or a word that the field belongs to another type (a union
    read without its tag)."""
    unknown = re.search(r"The fields \[(.*?)\] were unknown", message)
    if unknown is None:
        return message
    known = _FieldNames(schema)
    hints = []
    for name in re.findall(r"'([^']+)'", unknown.group(1)):
        if name in known:  # a field of another type than the one read here
            hints.append(f"; '{name}' belongs to another type: is its !Tag missing?")
        elif match := difflib.get_close_matches(name, known, n=1, cutoff=0.75):
            hints.append(f"; '{name}': did you mean '{match[0]}'?")
    return message + "".join(hints)


def LoadYamlFile(*, schema, filename, child_name: str | None = None, defaults=None):
    """Loads ``filename`` (optionally its top-level ``child_name``) into an instance of ``schema``.

    Raises:
        YamlFileError: naming the file, the line where it can be located, and Drake's reason, when
            the file is missing, is not valid YAML, or does not match the schema.
    """
    path = pathlib.Path(filename)
    if not path.is_file():
        what = "no such file"
        if path.exists():
            what = (
                "a folder, not a file" if path.is_dir() else "not a regular file (a pipe or device)"
            )
        raise YamlFileError(f"{path}: {what}")
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise YamlFileError(f"{path}: not a text file (not UTF-8)") from None
    except OSError as e:
        raise YamlFileError(f"{path}: cannot be read: {e.strerror}") from None
    if "\0" in text:
        raise YamlFileError(f"{path}: not a text file")
    if not text.strip() or all(
        not line.strip() or line.lstrip().startswith("#") for line in text.splitlines()
    ):
        raise YamlFileError(f"{path}: empty (write {{}} for all the defaults)")
    try:
        CheckYamlStructure(text, str(path))
        kwargs = dict(schema=schema, data=text, child_name=child_name)
        if defaults is not None:
            kwargs["defaults"] = defaults
        return yaml_load_typed(**kwargs)
    except YamlFileError:
        raise
    except yaml.YAMLError as e:
        raise YamlFileError(InvalidYaml(str(path), e)) from e
    except (RuntimeError, ValueError, TypeError, KeyError) as e:
        # Drake's messages quote the offending names: ['shap'], 'x'.
        line = LineOf(text, re.findall(r"'([^']+)'", str(e)))
        where = f"{path}:{line}" if line else f"{path}"
        raise YamlFileError(f"{where}: {DidYouMean(schema, str(e))}") from e


class _TaggedLoader(_SafeLoader):
    """Reads YAML that Drake's ``yaml_dump_typed`` wrote, a tagged value as ``{"!Tag": value}``."""


def _Tagged(loader: _SafeLoader, suffix: str, node: yaml.Node):
    if isinstance(node, yaml.MappingNode):
        return {"!" + suffix: loader.construct_mapping(node, deep=True)}
    if isinstance(node, yaml.SequenceNode):
        return {"!" + suffix: loader.construct_sequence(node, deep=True)}
    return {"!" + suffix: loader.construct_scalar(node)}


_TaggedLoader.add_multi_constructor("!", _Tagged)


def _Flatten(data, prefix: str = "") -> dict[str, object]:
    if isinstance(data, dict) and data:
        flat = {}
        for key, value in data.items():
            flat.update(_Flatten(value, f"{prefix}.{key}" if prefix else str(key)))
        return flat
    if isinstance(data, list) and data:
        flat = {}
        for i, value in enumerate(data):
            flat.update(_Flatten(value, f"{prefix}[{i}]"))
        return flat
    return {prefix: data}


def TaggedData(text: str):
    """The plain data of YAML that Drake's ``yaml_dump_typed`` wrote, a tagged value (a union's
    member) as ``{"!Tag": value}``: comparable by value, unlike Drake's config structs."""
    return yaml.load(text, Loader=_TaggedLoader)


def YamlDifferences(before: str, after: str) -> list[str]:
    """What differs between two YAML texts of the same schema: ``key: old -> new`` for every
    leaf (a missing one shown as ``-``), in key order."""
    old, new = _Flatten(TaggedData(before)), _Flatten(TaggedData(after))
    return [
        f"{key}: {old.get(key, '-')} -> {new.get(key, '-')}"
        for key in sorted(old.keys() | new.keys())
        if old.get(key, "-") != new.get(key, "-")
    ]


def LoadYamlOverride(*, schema, text: str, defaults):
    """``defaults`` with the YAML ``text`` merged in, as Drake's ``yaml_load_typed``, except
    that a top-level field whose tag names another class than its value's is made anew: Drake
    keeps a default that is an instance of the tagged class, so ``{mobee: !MobeeParams {}}``
    over a ``Dissertation`` (its subclass) would silently stay a ``Dissertation``."""
    data = TaggedData(text)
    if isinstance(data, dict):
        hints = typing.get_type_hints(schema)
        fresh = {}
        for key, value in data.items():
            if not (isinstance(value, dict) and len(value) == 1 and key in hints):
                continue
            tag = next(iter(value))
            if not str(tag).startswith("!") or type(getattr(defaults, key)).__name__ == tag[1:]:
                continue
            for member in typing.get_args(hints[key]):
                if getattr(member, "__name__", None) == tag[1:]:
                    fresh[key] = member()
        defaults = dc.replace(defaults, **fresh)
    return yaml_load_typed(schema=schema, data=text, defaults=defaults)
