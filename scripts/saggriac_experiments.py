"""Runs the SAGG-RIAC experiments of Baranes & Oudeyer (IROS 2010), Sec. IV; see --help."""

from mobee_drake.experiments.saggriac_command import main

main()
