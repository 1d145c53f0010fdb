"""Learning to reach (dissertation ch. 8): reward predictors, reach actions and problem-tries."""
