"""Makes one run of the adaptive-space reaching battery again, in this process, and records for
every problem that began with solids penetrating (which the battery's watch, before adf6900,
counted as one whose target appeared inside the robot) its target, its penetrating control
periods, and, when its target appeared and when it was closed, the pairs of solids penetrating
(``safety.Penetrations``), MoBeE's joints and its joint-limit and barrier forces (the run's
joint limits with them).

The battery's report splits the penetrating periods by whether a problem's target appeared
inside the robot; this shows what the periods it sets aside were.

Run from the project's root: ``python scripts/probe_penetrations.py
reach_katana_random_maintained_seed1 --battery docs/results/adaptive_space_reaching_303aba8 --output
probe.json`` (its roadmaps and MDPs are copied from the battery's folder into a scratch one; the
run is made with the code this imports, and its result is written beside the records, to be
compared with the battery's).
"""

import argparse
import json
import pathlib
import subprocess
import tempfile

from mobee_drake.experiments import adaptive_space_command as command
from mobee_drake.experiments import adaptive_space_reaching as reaching
from mobee_drake.experiments import ch8_reaching
from mobee_drake.experiments.battery import CopySharedRuns, RunFolder
from mobee_drake.reaching import appearance
from mobee_drake.station.safety import Penetrations


class _Probe(appearance.AppearanceWatch):
    """An appearance watch (counting as the code it runs with does) that keeps a record of each
    problem that began with solids penetrating."""

    records: list = []
    limits: tuple = ()

    def SetProblem(self, target) -> None:
        super().SetProblem(target)
        _Probe.limits = self.robot.station.mobee.position_limits
        object.__setattr__(self, "_target", [float(v) for v in target])
        object.__setattr__(self, "_at_start", self._Moment())
        object.__setattr__(self, "_start", self._Penetrating())
        object.__setattr__(self, "_recording", bool(self._at_start["pairs"]))

    def Close(self) -> None:
        if getattr(self, "_recording", False):
            object.__setattr__(self, "_recording", False)
            _Probe.records.append(
                dict(
                    target=self._target,
                    periods=self._Penetrating() - self._start,
                    at_start=self._at_start,
                    at_end=self._Moment(),
                )
            )
        super().Close()

    def _Moment(self) -> dict:
        """The penetrating pairs, MoBeE's joints (rad) and its f_lim and f_barrier now."""
        station, context = self.robot.station, self.robot.context
        mobee = station.mobee
        mobee_context = mobee.GetMyContextFromRoot(context)
        n = len(mobee.position_limits[0])
        return dict(
            pairs=Penetrations(station.diagram, context),
            q=station.robot_state.Eval(context)[:n].tolist(),
            **{
                term: mobee.GetOutputPort(term).Eval(mobee_context).tolist()
                for term in ("f_lim", "f_barrier")
            },
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("run", help="the run's name in the battery, e.g. reach_katana_..._seed1")
    parser.add_argument("--battery", type=pathlib.Path, required=True, help="its folder")
    parser.add_argument("--output", type=pathlib.Path, required=True, help="a JSON file")
    args = parser.parse_args()
    jobs = _Jobs()
    runs = [job for job in jobs if job.name == args.run]
    if not runs:
        parser.error(f"{args.run}: not a run of the reaching battery")
    (run,) = runs
    commit = subprocess.run(  # (the code imported now: "-dirty" if it was not committed)
        ["git", "describe", "--always", "--dirty", "--abbrev=40"], capture_output=True, text=True
    )
    ch8_reaching.AppearanceWatch = _Probe  # (the run's robot is watched by the probe)
    support = [job for job in jobs if not job.name.startswith("reach_")]
    with tempfile.TemporaryDirectory() as scratch:
        CopySharedRuns(support, args.battery, pathlib.Path(scratch))  # (roadmaps and MDPs)
        folder = pathlib.Path(scratch) / "runs" / run.name
        folder.mkdir()
        result = run.function(RunFolder(folder), **run.kwargs)
    lower, upper = _Probe.limits
    probe = dict(run=run.name, commit=commit.stdout.strip(), result=result)
    probe["limits"] = dict(lower=lower.tolist(), upper=upper.tolist())
    probe["problems"] = _Probe.records
    args.output.write_text(json.dumps(probe, indent=1) + "\n")


def _Jobs():
    """The jobs of the reaching battery of docs/adaptive_space.md's command."""
    parser = command._Parser()
    args = parser.parse_args("--part reaching --robots icub katana --seeds 10".split())
    maintenance = command._Maintenance(parser, args)
    return [job for _, jobs in reaching.Stages(args, maintenance) for job in jobs]


if __name__ == "__main__":
    main()
