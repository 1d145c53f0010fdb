"""The robot's surroundings: objects with shapes, poses and roles (``objects``) and the live
world that adds, moves and switches them in a running diagram's Context (``live_world``)."""
