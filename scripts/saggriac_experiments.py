"""Runs the SAGG-RIAC experiments of Baranes & Oudeyer (IROS 2010), Sec. IV; see --help."""

from mobee_drake.goal_babbling.experiments import main

main()
