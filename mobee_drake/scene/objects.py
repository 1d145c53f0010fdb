"""Objects in the robot's world: fixed primitives that MoBeE treats as obstacles."""

import numpy as np
from pydrake.geometry import Box, Shape
from pydrake.math import RigidTransform
from pydrake.multibody.plant import CoulombFriction, MultibodyPlant

OBSTACLE_COLOR = np.array([0.55, 0.4, 0.25, 1.0])


def AddFixedObject(plant: MultibodyPlant, name: str, shape: Shape, X_WO: RigidTransform,
                   color: np.ndarray = OBSTACLE_COLOR) -> None:
    """Adds ``shape`` fixed in the world at ``X_WO``, for collision and illustration."""
    world = plant.world_body()
    plant.RegisterCollisionGeometry(world, X_WO, shape, name, CoulombFriction(0.5, 0.5))
    plant.RegisterVisualGeometry(world, X_WO, shape, name, color)


def AddBox(plant: MultibodyPlant, name: str, size, X_WO: RigidTransform) -> None:
    """Adds a fixed box obstacle of edge lengths ``size`` (m)."""
    AddFixedObject(plant, name, Box(*size), X_WO)
