"""Behaviours that run beside the reach planner on joints of their own (dissertation ch. 9.4.2):
pointing a marker at a target (gaze, palm normal) and placing the torso so that the target lies
where the learned reaches succeed. Composed on one robot by ``station/composition.py``."""
