"""The station: the robot, its world, MoBeE, what moves the robot and the viewer in one Diagram
that knows no client (``builder``, ``config``). Clients join through one seam (``parts``); the
station's own building blocks for them are the attractor programs (``attractors``), the settling
test (``settling``) and the state-action executor (``executor``). Around it: world events
(``world_events``), checkpoints (``checkpoint``) and the runner (``runner``)."""
