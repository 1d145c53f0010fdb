"""The ``mobee-drake`` command: one subcommand per job a user runs."""

import argparse
import sys


def _Bench(args: list[str]) -> None:
    parser = argparse.ArgumentParser(prog="mobee-drake bench")
    parser.add_argument("what", choices=["forces"], help="which benchmark to run")
    known, rest = parser.parse_known_args(args)
    if known.what == "forces":
        from mobee_drake.bench.forces import main

        main(rest)


def _Info(args: list[str]) -> None:
    """Prints the iCub model, its controlled joints, overlay geometry, markers and clauses."""
    parser = argparse.ArgumentParser(prog="mobee-drake info")
    parser.add_argument("--model", default=None, help="an icub-models robot name")
    known = parser.parse_args(args)

    from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
    from pydrake.systems.framework import DiagramBuilder

    from mobee_drake.mobee.system import Mobee
    from mobee_drake.robots.icub import AddIcub, IcubConfig
    from mobee_drake.robots.model_cache import IcubModelNames

    config = IcubConfig() if known.model is None else IcubConfig(model=known.model)
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
    robot = AddIcub(plant, scene_graph, config)
    plant.Finalize()
    mobee = Mobee(plant, robot, joints=config.controlled_joints)
    print(f"model: {config.model} (available: {', '.join(IcubModelNames())})")
    print(f"bodies: {plant.num_bodies()}, controlled joints: {len(mobee.joints)}")
    lower, upper = mobee.position_limits
    import numpy as np

    for name, lo, hi, home in zip(mobee.joints, np.degrees(lower), np.degrees(upper),
                                  np.degrees(mobee.home)):
        print(f"  {name:18s} [{lo:7.1f}, {hi:7.1f}] deg, home {home:6.1f}")
    print("overlay primitives (field margin, m): " + ", ".join(
        f"{robot.geometry_names[g]} ({m:.3f})" for g, m in robot.field_margins.items()))
    print("markers: " + ", ".join(mobee.marker_names))
    print("constraint clauses: " + ", ".join(mobee.clauses.names))


COMMANDS = {"bench": _Bench, "info": _Info}


def main(argv: list[str] | None = None) -> None:
    argv = sys.argv[1:] if argv is None else argv
    parser = argparse.ArgumentParser(
        prog="mobee-drake", description="MoBeE 2.0 on Drake for the iCub.")
    parser.add_argument("command", choices=sorted(COMMANDS))
    parser.add_argument("args", nargs=argparse.REMAINDER)
    known = parser.parse_args(argv[:1])
    COMMANDS[known.command](argv[1:])


if __name__ == "__main__":
    main()
