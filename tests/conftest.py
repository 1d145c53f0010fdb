import os

# Plots in tests never open windows.
os.environ.setdefault("MPLBACKEND", "Agg")
