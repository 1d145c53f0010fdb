"""The curious MDP roadmap planner (dissertation ch. 6-7): state-action spaces over joint
configurations, the compressed ("Kail") KL-divergence curiosity, value iteration, exploring agents
and their strategies (a registry), planning with the learned model, and the exploration supervisor
that runs agents on the station (its client config: ``ExploreAttractor``)."""
