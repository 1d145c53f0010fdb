import os

# Plots in tests never open windows.
os.environ.setdefault("MPLBACKEND", "Agg")


def pytest_addoption(parser):
    parser.addoption(
        "--zero-mobee",
        action="store_true",
        help="break MoBeE on purpose: every force it outputs is zero (the robot never moves); "
        "the tests of what MoBeE does must then fail (see docs/testing.md)",
    )


def pytest_configure(config):
    """With --zero-mobee, MoBeE's forces (every term and the total) are zero in this process,
    before any test class builds a station."""
    if config.getoption("--zero-mobee"):
        from mobee_drake.mobee.system import Mobee

        calc = Mobee._CalcForces

        def Zero(self, context, output):
            calc(self, context, output)
            output.get_mutable_value()[:] = 0.0

        Mobee._CalcForces = Zero
