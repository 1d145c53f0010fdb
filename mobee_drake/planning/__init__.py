"""The curious MDP roadmap planner (dissertation ch. 6-7): state-action spaces over joint
configurations, the compressed ("Kail") KL-divergence curiosity, value iteration, and exploring
agents."""
