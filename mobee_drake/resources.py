"""Where the shipped models and scenarios are, in a source checkout and in an installed wheel.

The repository keeps ``models/`` and ``diagrams/`` at its top level; the wheel ships them inside
the package as ``mobee_drake.models`` and ``mobee_drake.diagrams`` (``pyproject.toml`` maps the
folders), so both are found through :mod:`importlib.resources` wherever the package is installed.
``models/package.xml`` names the models folder ``mobee_drake`` for Drake's
:class:`~pydrake.multibody.parsing.PackageMap`: a model file is written
``package://mobee_drake/katana.xml``; a plain relative name (``katana.xml``) means the same file.
A scenario is a file path or the name of a shipped one (``reach_around_ball``).
"""

import difflib
import functools
import importlib.resources
import pathlib

from pydrake.multibody.parsing import PackageMap


def ModelsDirectory() -> pathlib.Path:
    """The folder of the shipped models (``models/`` in the repository)."""
    return pathlib.Path(str(importlib.resources.files("mobee_drake.models")))


def ScenariosDirectory() -> pathlib.Path:
    """The folder of the shipped scenarios (``diagrams/`` in the repository)."""
    return pathlib.Path(str(importlib.resources.files("mobee_drake.diagrams")))


@functools.cache
def MobeePackageMap() -> PackageMap:
    """A package map that resolves ``package://mobee_drake/...`` and the packages on
    ``ROS_PACKAGE_PATH`` (a user's own models)."""
    package_map = PackageMap.MakeEmpty()
    package_map.AddPackageXml(str(ModelsDirectory() / "package.xml"))
    package_map.PopulateFromRosPackagePath()
    return package_map


def _PackageFile(url: str) -> pathlib.Path:
    """The file a ``package://`` URI names (ValueError naming an unknown package)."""
    package = url[len("package://") :].split("/", 1)[0]
    if not MobeePackageMap().Contains(package):
        raise ValueError(
            f"{url}: unknown package '{package}' (known: "
            + ", ".join(sorted(MobeePackageMap().GetPackageNames()))
            + "; add yours to ROS_PACKAGE_PATH)"
        )
    return pathlib.Path(MobeePackageMap().ResolveUrl(url))


def ResolveModelFile(name: str | pathlib.Path) -> pathlib.Path:
    """The file of a model: a ``package://`` URI (``package://mobee_drake/...``), an absolute
    path, or a path relative to the shipped models folder."""
    text = str(name)
    if text.startswith("package://"):
        return _PackageFile(text)
    path = pathlib.Path(text)
    return path if path.is_absolute() else ModelsDirectory() / path


def ResolveModelPath(name: str) -> pathlib.Path:
    """The existing file a ``package://`` URI or a path (relative to the current folder) names.

    Raises:
        ValueError: naming the URI's unknown package, or the missing file.
    """
    path = _PackageFile(name) if name.startswith("package://") else pathlib.Path(name)
    if not path.is_file():
        raise ValueError(f"{name}: no such file")
    return path


def ScenarioNames() -> list[str]:
    """The names of the shipped scenarios."""
    return sorted(p.stem for p in ScenariosDirectory().glob("*.yaml"))


def ResolveScenarioFile(name: str | pathlib.Path) -> pathlib.Path:
    """A scenario file: ``name`` if it is an existing file, else the shipped scenario of that name
    (with or without ``.yaml``); an unknown name is returned as given, for the loader to report
    (see :func:`UnknownScenario`)."""
    path = pathlib.Path(name)
    if path.is_file():
        return path
    shipped = ScenariosDirectory() / (path.stem + ".yaml")
    if path.parent == pathlib.Path(".") and shipped.is_file():
        return shipped
    return path


def UnknownScenario(name: str | pathlib.Path) -> str:
    """What to say of a scenario ``name`` that is neither a file nor a shipped scenario: the
    shipped ones, and the closest."""
    close = difflib.get_close_matches(pathlib.Path(name).stem, ScenarioNames(), n=1)
    return (
        f"{name}: no such file, nor a shipped scenario (shipped: {', '.join(ScenarioNames())})"
        + (f"; did you mean '{close[0]}'?" if close else "")
    )
