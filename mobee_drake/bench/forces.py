"""Benchmark: MoBeE total-force evaluations per second for the iCub upper body among boxes.

Like the scalability experiment of dissertation Fig. 2.4: every controlled joint is driven through
its range by its own oscillator, and for each new pose the whole MoBeE evaluation runs (forward
kinematics, SceneGraph's signed-distance query, every force term and their total), against 0 to
several hundred fixed boxes in front of the robot. One process, one core.

Run: ``mobee-drake bench forces`` (or ``python -m mobee_drake.bench.forces``).
"""

import argparse
import dataclasses as dc
import time

import numpy as np
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder

from mobee_drake.mobee.system import Mobee
from mobee_drake.robots.icub import AddIcub, IcubConfig
from mobee_drake.simulation.scenario import Box, SceneObject
from mobee_drake.simulation.world import LiveWorld

# The region in front of the iCub (root frame: x backwards, y right, z up) where boxes are placed.
# It spans 60 cm in front of the chest, 1.2 m across and 1 m high; the arms reach about half of it.
BOX_REGION_LOW = np.array([-0.80, -0.60, -0.40])
BOX_REGION_HIGH = np.array([-0.20, 0.60, 0.60])


@dc.dataclass
class ForceBenchmarkResult:
    num_obstacles: int
    # The best and the median rate over the repeats (this machine's speed varies between runs).
    best_per_second: float
    median_per_second: float
    mean_pairs_in_fields: float


def _BuildIcubAmongBoxes(num_boxes: int, rng: np.random.Generator):
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
    config = IcubConfig()
    robot = AddIcub(plant, scene_graph, config)
    world = LiveWorld(plant, scene_graph)
    for i in range(num_boxes):
        world.Register(SceneObject(
            name=f"box{i}", shape=Box(size=rng.uniform(0.02, 0.05, size=3).tolist()),
            position=rng.uniform(BOX_REGION_LOW, BOX_REGION_HIGH).tolist()))
    plant.Finalize()
    mobee = Mobee.AddToBuilder(builder, plant=plant, scene_graph=scene_graph, robot=robot,
                               joints=config.controlled_joints)
    diagram = builder.Build()
    return diagram, plant, mobee


def _OscillatorPoses(mobee: Mobee, num_poses: int, rng: np.random.Generator,
                     amplitude: float = 1.0) -> np.ndarray:
    """Poses 10 ms apart, each joint on its own sinusoid.

    With ``amplitude`` 1 every joint sweeps its whole range (Fig. 2.4); with a smaller amplitude it
    sweeps that fraction of its range around the home posture (clipped to the limits).
    """
    q_min, q_max = mobee.position_limits
    period = rng.uniform(4.0, 12.0, size=q_min.size)  # seconds per sweep
    phase = rng.uniform(0, 2 * np.pi, size=q_min.size)
    t = 0.01 * np.arange(num_poses)[:, None]
    center = (q_min + q_max) / 2 if amplitude >= 1 else mobee.home
    q = center + amplitude * (q_max - q_min) / 2 * np.sin(2 * np.pi * t / period + phase)
    return np.clip(q, q_min, q_max)


def MeasureForceEvaluations(num_obstacles: int, *, num_poses: int = 2000, repeats: int = 5,
                            amplitude: float = 1.0, seed: int = 0) -> ForceBenchmarkResult:
    """Times ``repeats`` sweeps of ``num_poses`` total-force evaluations among boxes."""
    rng = np.random.default_rng(seed)
    diagram, plant, mobee = _BuildIcubAmongBoxes(num_obstacles, rng)
    context = diagram.CreateDefaultContext()
    plant_context = plant.GetMyMutableContextFromRoot(context)
    mobee_context = mobee.GetMyContextFromRoot(context)
    total, contacts = mobee.GetOutputPort("total"), mobee.GetOutputPort("field_contacts")
    # The plant's positions are the controlled joints, possibly in another order.
    order = [plant.GetJointByName(j).position_start() for j in mobee.joints]
    poses = _OscillatorPoses(mobee, num_poses, rng, amplitude)
    x = plant.GetPositions(plant_context)
    rates = []
    for _ in range(repeats):
        start = time.perf_counter()
        for q in poses:
            x[order] = q
            plant.SetPositions(plant_context, x)
            total.Eval(mobee_context)
        rates.append(num_poses / (time.perf_counter() - start))
    pairs = 0
    for q in poses[::10]:  # Untimed: how busy the field term was.
        x[order] = q
        plant.SetPositions(plant_context, x)
        pairs += len(contacts.Eval(mobee_context))
    return ForceBenchmarkResult(num_obstacles, max(rates), float(np.median(rates)),
                                pairs / len(poses[::10]))


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--obstacles", type=int, nargs="+", default=[0, 10, 30, 100, 300])
    parser.add_argument("--poses", type=int, default=2000, help="evaluations per sweep")
    parser.add_argument("--repeats", type=int, default=5, help="sweeps per row")
    parser.add_argument("--amplitude", type=float, default=1.0,
                        help="fraction of each joint's range swept (1: the whole range, Fig. 2.4)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    print("| boxes | evaluations/s (best) | evaluations/s (median) | us/evaluation (best) "
          "| pairs inside fields (mean) |")
    print("|---:|---:|---:|---:|---:|")
    for n in args.obstacles:
        r = MeasureForceEvaluations(n, num_poses=args.poses, repeats=args.repeats,
                                    amplitude=args.amplitude, seed=args.seed)
        print(f"| {n} | {r.best_per_second:,.0f} | {r.median_per_second:,.0f} | "
              f"{1e6 / r.best_per_second:.0f} | {r.mean_pairs_in_fields:.2f} |", flush=True)


if __name__ == "__main__":
    main()
