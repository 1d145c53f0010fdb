"""Task-relevant roadmaps (dissertation ch. 3.2-3.4, Alg. 2-4): task spaces, the advancing front
with the covered region (``roadmap``), the "Reach Into" and "Raise a glass" examples and their
display in Meshcat."""
