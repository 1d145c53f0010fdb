"""Inverse kinematics by natural evolution strategies (dissertation ch. 3.1): a kinematic model
of the robot and its world without a simulator (``kinematic_model``), Table 3.1's costs
(``costs``), xNES and SNES (``nes``) and the solver (``solver``)."""
