"""The shipped robot models: MoBeE's overlays, MoBeE XML robots and the reach targets.

Resolved as ``package://mobee_drake/<file>`` through ``package.xml`` (see
:mod:`mobee_drake.resources`).
"""
