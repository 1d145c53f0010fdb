"""Roadmaps as graphs: shortest paths over joint-space edges (``graph_paths``, shared with the
task-relevant roadmaps) and adaptive roadmap planning on MoBeE 1.0 (dissertation ch. 4.2-4.3,
``adaptive_roadmap``)."""
