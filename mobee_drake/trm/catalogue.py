"""Every roadmap of ch. 3.4 that this package builds, by name (``mobee-drake experiment trm
--examples``), and the source's tasks it does not build, with the reason."""

from mobee_drake.trm.bimanual import (
    BimanualInspect,
    BimanualRotate,
    BimanualTwist,
    Carry,
    PushForward,
    PushOver,
    TorsoOverHeldHands,
    Unscrew,
)
from mobee_drake.trm.examples import (
    ElbowDown,
    Inspect,
    PalmDown,
    PalmToTheSide,
    RaiseAGlass,
    ReachInto,
)

EXAMPLES = {
    "reach_into": ReachInto,  # Fig. 3.8
    "raise_a_glass": RaiseAGlass,  # Fig. 3.3
    "elbow_down": ElbowDown,  # Fig. 3.1, right
    "palm_to_the_side": PalmToTheSide,  # Fig. 3.2, left
    "palm_down": PalmDown,  # Fig. 3.2, right
    "inspect": Inspect,  # Fig. 3.5
    "carry": Carry,  # Fig. 3.1, left
    "torso_over_held_hands": TorsoOverHeldHands,  # Fig. 3.1, centre
    "bimanual_inspect": BimanualInspect,  # Fig. 3.4
    "push_forward": PushForward,  # Fig. 3.6
    "push_over": PushOver,  # Fig. 3.7
    "bimanual_rotate": BimanualRotate,  # Fig. 3.9
    "bimanual_twist": BimanualTwist,  # Fig. 3.10
    "unscrew": Unscrew,  # Fig. 3.11
}
