"""mobee-drake: MoBeE 2.0, the curious MDP roadmap planner, the learner of dynamic reaches and
SAGG-RIAC goal babbling for the iCub, on Drake.

The package is layered; each layer imports only the layers below it (``.importlinter`` states
the contract, ``docs/architecture.md`` the map):

- :mod:`mobee_drake.experiments` and :mod:`mobee_drake.cli`: experiments, reports, plots,
  benchmarks and the command line, on top of everything;
- :mod:`mobee_drake.scenario`: the composition root that reads a scenario and builds the station
  with its client;
- the clients, each a package of its own: :mod:`~mobee_drake.planning` (the curious agent),
  :mod:`~mobee_drake.reaching` (learning to reach), :mod:`~mobee_drake.roadmaps` (adaptive
  roadmaps on MoBeE 1.0), :mod:`~mobee_drake.trm` (task-relevant roadmaps),
  :mod:`~mobee_drake.ngik` (natural gradient IK), :mod:`~mobee_drake.goal_babbling` (SAGG-RIAC);
- :mod:`mobee_drake.station`: robot, world, MoBeE, the mover and the viewer, knowing no client;
- :mod:`~mobee_drake.mobee` (MoBeE 2.0 and 1.0's reflex), :mod:`~mobee_drake.world` and
  :mod:`~mobee_drake.robots`: the controllers, the robot's surroundings and its models;
- :mod:`~mobee_drake.yaml_io`, :mod:`~mobee_drake.atomic_files` (and checkpoint generations),
  :mod:`~mobee_drake.owned_folders` (folders claimed and locked before a run writes),
  :mod:`~mobee_drake.progress` (bars on a terminal, plain lines in a log),
  :mod:`~mobee_drake.resources`.
"""

import importlib.metadata

__version__ = importlib.metadata.version("mobee-drake")
