"""Simulating the iCub under MoBeE: scenarios, robots, world, viewer and runner."""
