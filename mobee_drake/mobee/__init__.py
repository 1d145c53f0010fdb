"""The controllers: MoBeE 2.0 as a LeafSystem with one output port per force term of eq. 5.7
(``system``), its math (``fields``, ``constraints``, ``joint_limits``, ``squash``,
``projection``, ``params``), and MoBeE 1.0's position moves with the rewinding reflex
(``reflex``)."""
