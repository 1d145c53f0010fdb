"""SAGG-RIAC goal babbling on a planar arm (Baranes & Oudeyer, IROS 2010) and its baselines.

Modules: config (typed parameters), planar_arm, competence (eq. 1, 2, 7), regions (interest, splits,
modes), low_level (memory-based local models and the SSA-like low level), sagg_riac, baselines,
evaluation. The Sec. IV experiments are in :mod:`mobee_drake.experiments.saggriac`.
"""
