"""Learning to reach (dissertation ch. 8): reward predictors (eq. 8.1-8.7), goals, the learner of
problem-tries with its exploration strategies, the reach targets, and the simulated robot that
runs state-actions through the station's executor."""
