"""Command-line values checked where they enter: argparse types that refuse, with a one-line
error naming the flag and the value, what no run could use."""

import argparse
import math
import re


def _Checked(text: str, convert, accept, what: str):
    try:
        value = convert(text)
    except ValueError:
        value = None
    if value is None or not accept(value):
        raise argparse.ArgumentTypeError(f"must be {what}, got '{text}'")
    return value


def PositiveInt(text: str) -> int:
    """A whole number >= 1 (a count)."""
    return _Checked(text, int, lambda v: v >= 1, "a whole number >= 1")


def NonNegativeInt(text: str) -> int:
    """A whole number >= 0 (a seed, a first seed)."""
    return _Checked(text, int, lambda v: v >= 0, "a whole number >= 0")


def PositiveFloat(text: str) -> float:
    """A finite number > 0 (a duration, a force)."""
    return _Checked(text, float, lambda v: math.isfinite(v) and v > 0, "a finite number > 0")


def InRange(low: float, high: float):
    """An argparse type: a number in [``low``, ``high``] (a physical value whose range outside
    which a run means nothing, e.g. a force that MoBeE's squashing saturates long before)."""

    def Checked(text: str) -> float:
        return _Checked(text, float, lambda v: low <= v <= high, f"a number in [{low:g}, {high:g}]")

    return Checked


def Fraction(text: str) -> float:
    """A number in (0, 1] (a share of a range)."""
    return _Checked(text, float, lambda v: 0 < v <= 1, "a number in (0, 1]")


def Discount(text: str) -> float:
    """A discount factor in [0, 1)."""
    return _Checked(text, float, lambda v: 0 <= v < 1, "a number in [0, 1)")


def NonEmpty(text: str) -> str:
    """A non-empty text (a path: an empty one would be silently ignored)."""
    return _Checked(text, str, bool, "a non-empty path")


def PlainHelp(text: str | None) -> str | None:
    """A docstring made user help: Sphinx roles and doubled backquotes read as plain code, and
    the developers' issue numbers left out."""
    if text is None:
        return None
    text = re.sub(r":(?:mod|class|func|meth|attr|data|obj):`~?([^`]+)`", r"`\1`", text)
    text = text.replace("``", "`")
    return re.sub(r" ?\(issues? \d+(?:, \d+)*\)", "", text)


class HelpFormatter(argparse.RawDescriptionHelpFormatter, argparse.ArgumentDefaultsHelpFormatter):
    """Every command's help: its description as written, each option with its default where it
    has one worth reading (not for a flag that is off, an option that is unset, or help that
    already says it)."""

    def _get_help_string(self, action) -> str:
        text = PlainHelp(action.help or "")
        unset = action.default is None or action.default is False or action.default in ([], "")
        if "default" in text or unset or action.default is argparse.SUPPRESS:
            return text
        return PlainHelp(super()._get_help_string(action))


class CommandParser(argparse.ArgumentParser):
    """A command's parser: help with defaults, a description in plain words, and a mistake in
    one line (no usage dump)."""

    def __init__(self, **kwargs):
        kwargs.setdefault("formatter_class", HelpFormatter)
        kwargs["description"] = PlainHelp(kwargs.get("description"))
        super().__init__(**kwargs)
        self._required_options = None

    def add_argument(self, *args, **kwargs):
        """As argparse's; a required option is listed under "required options", not among the
        optional ones."""
        if kwargs.get("required") and args and args[0].startswith("-"):
            if self._required_options is None:
                self._required_options = self.add_argument_group("required options")
            return self._required_options.add_argument(*args, **kwargs)
        return super().add_argument(*args, **kwargs)

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message}\n")
