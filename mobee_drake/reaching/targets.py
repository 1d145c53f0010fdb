"""The reach targets (RL problems) of dissertation ch. 8.3, Fig. 8.1: a grid of spheres."""

import dataclasses as dc
import itertools

import numpy as np

from mobee_drake.resources import ResolveModelFile
from mobee_drake.world.objects import SceneObject, Sphere
from mobee_drake.yaml_io import LoadYamlFile, YamlFileError

DEFAULT_TARGETS = "package://mobee_drake/reach_targets.yaml"
# The name of the target object while it is in the world.
TARGET_NAME = "reach_target"


@dc.dataclass
class TargetGrid:
    """Sphere centres on a grid: every combination of the levels of x, y and z (m)."""

    radius: float = 0.05
    x: list[float] = dc.field(default_factory=list)
    y: list[float] = dc.field(default_factory=list)
    z: list[float] = dc.field(default_factory=list)

    def Centres(self) -> np.ndarray:
        """(k, 3) the targets, x varying slowest: problem i is row i."""
        return np.array(list(itertools.product(self.x, self.y, self.z)), dtype=float)


def LoadTargetGrid(filename=DEFAULT_TARGETS) -> TargetGrid:
    """Loads a target grid; errors name the file and the key."""
    grid = LoadYamlFile(schema=TargetGrid, filename=ResolveModelFile(filename))
    for axis in "xyz":
        if not getattr(grid, axis):
            raise YamlFileError(f"{filename}: '{axis}' needs at least one level")
    if not grid.radius > 0:
        raise YamlFileError(f"{filename}: radius must be > 0, got {grid.radius}")
    return grid


def TargetObject(centre, radius: float) -> SceneObject:
    """The target as an object of the robot's world: an obstacle (see docs/reaching.md)."""
    return SceneObject(
        name=TARGET_NAME,
        shape=Sphere(radius=radius),
        position=[float(c) for c in centre],
        role="obstacle",
    )
