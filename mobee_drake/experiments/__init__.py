"""The top layer: experiments, reports, plots, benchmarks and the battery runner; nothing in the
library imports it."""
