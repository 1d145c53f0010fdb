"""The source's claims of ch. 8.4-8.5 marked from a battery's result files (issue 33).

Each claim is a comparison of strategies on one value per run. Runs are paired by seed: runs of
one seed share their MDP (:func:`mobee_drake.experiments.ch8_reaching.RunReachBattery`: seed k
uses MDP k mod ``--mdps``) and their evaluation seeds, so strategies are compared on paired
differences (:func:`~mobee_drake.experiments.statistics.ComparePaired`, the MDP a block), and a
claim's comparisons (two other strategies, several stages) are one family under Holm's
correction. Every setting of the battery (a reading of the source's ambiguities, a distance
unit, a reach force) is marked on its own; a claim then *holds under* the settings where it is
reproduced.

Marks: ``reproduced`` (every comparison of the claim in the claimed direction, Holm-adjusted
p < 0.05), ``not reproduced`` (otherwise; the evidence says whether the difference is reversed
or not found), ``not testable`` (the runs lack what the claim needs, e.g. the stage or the
strategy).
"""

from collections.abc import Callable
import dataclasses as dc

import numpy as np
from scipy import stats

from mobee_drake.experiments.ch8_figures import RunLog
from mobee_drake.experiments.ch8_measures import (
    Fingerprints,
    RunSums,
    RunTrends,
    TimedOutTries,
)
from mobee_drake.experiments.ch8_reaching import ReachRun, SettingLabel
from mobee_drake.experiments.statistics import (
    ComparePaired,
    Holm,
    PairedComparison,
    RatioOfMeans,
)

REPRODUCED, NOT_REPRODUCED, NOT_TESTABLE = "reproduced", "not reproduced", "not testable"
ALPHA = 0.05
# The source's robot hours of random exploration over the other two strategies' (207 h against
# 109 and 113 h, ch. 8.4.4).
SOURCE_TIME_RATIO = 207 / np.mean([109, 113])
# "From about 800 on" (ch. 8.4.1).
BEST_FROM = 800


@dc.dataclass
class Verdict:
    """One claim marked on one setting's runs."""

    claim: str
    setting: str
    mark: str
    evidence: str


# A setting's runs: per strategy, per seed, the run's result.
Runs = dict[str, dict[int, ReachRun]]


def _Pairs(runs: Runs, a: str, b: str, value: Callable[[ReachRun], float]):
    """The values of the runs of ``a`` and ``b`` of every seed both have, and the seeds'
    MDPs."""
    seeds = sorted(set(runs.get(a, {})) & set(runs.get(b, {})))
    values_a = [value(runs[a][s]) for s in seeds]
    values_b = [value(runs[b][s]) for s in seeds]
    blocks = [runs[a][s].settings.mdp_seed for s in seeds]
    return values_a, values_b, blocks


def _Family(runs: Runs, comparisons, larger: bool) -> tuple[str, str]:
    """Marks a claim made of paired comparisons ``(label, a, b, value)``, each claiming that a's
    value is ``larger`` (or smaller) than b's; Holm over the family."""
    if not comparisons:
        return NOT_TESTABLE, "needs the runs of both other strategies"
    done: list[tuple[str, PairedComparison]] = []
    for label, a, b, value in comparisons:
        values_a, values_b, blocks = _Pairs(runs, a, b, value)
        if len(values_a) < 2:
            return NOT_TESTABLE, f"{label}: fewer than 2 paired runs"
        done.append(_Compared(label, values_a, values_b, blocks))
    adjusted = Holm([c.t_p for _, c in done])
    held = [
        (c.difference > 0) == larger and p < ALPHA for (_, c), p in zip(done, adjusted, strict=True)
    ]
    reversed_ = [
        (c.difference > 0) != larger and p < ALPHA for (_, c), p in zip(done, adjusted, strict=True)
    ]
    evidence = "; ".join(
        f"{label} {c.Text(p)}" for (label, c), p in zip(done, adjusted, strict=True)
    )
    if all(held):
        return REPRODUCED, evidence
    found = f"{sum(held)} of {len(held)} comparisons as claimed, {sum(reversed_)} reversed"
    return NOT_REPRODUCED, f"{found}: {evidence}"


def _Compared(label: str, a, b, blocks) -> tuple[str, PairedComparison]:
    """(the label, :func:`ComparePaired` of ``a`` and ``b`` in the MDPs ``blocks``); with one
    pair per MDP there is no error within the MDPs, so they are not separated (the label says
    so)."""
    if len(a) <= len(set(blocks)):
        blocks, label = [0] * len(blocks), f"{label} (one pair per MDP, MDPs not separated)"
    return label, ComparePaired(a, b, blocks)


def _StageMean(stage: int, penalties: bool) -> Callable[[ReachRun], float]:
    return lambda run: float(RunSums([run], stage, penalties)[0])


def _Trend(penalties: bool, stages: list[int]) -> Callable[[ReachRun], float]:
    """A run's change per doubling over ``stages`` (the setting's common ones, so that paired
    runs are compared over the same stages)."""
    return lambda run: RunTrends([run], stages, penalties)[0]


def _Stages(runs: Runs) -> list[int]:
    """The stages every run of the setting was evaluated at."""
    every = [set(r.evaluations) for seeds in runs.values() for r in seeds.values()]
    return sorted(set.intersection(*every)) if every else []


def _Trended(runs: Runs) -> list[int]:
    """The stages a trend is taken over: those after 0."""
    return [s for s in _Stages(runs) if s > 0]


def _OthersThan(runs: Runs, strategy: str) -> list[str]:
    """The two other strategies, when the setting has runs of both, else none: a claim against
    "the others" (least competent, the best, many more) is not the claim against one of them
    (e.g. a distance unit swept with greedy and intrinsic alone)."""
    others = [s for s in ("random", "greedy", "intrinsic") if s != strategy]
    return others if all(s in runs for s in others) else []


def LeastCompetentFirst(runs: Runs, penalties: bool) -> tuple[str, str]:
    """Ch. 8.4.1: intrinsic motivation is the least competent after 100 problem-tries."""
    if 100 not in _Stages(runs) or "intrinsic" not in runs:
        return NOT_TESTABLE, "no evaluations at 100 problem-tries"
    value = _StageMean(100, penalties)
    comparisons = [(f"minus {o}", "intrinsic", o, value) for o in _OthersThan(runs, "intrinsic")]
    return _Family(runs, comparisons, larger=False)


def ImprovesSteadily(runs: Runs, penalties: bool) -> tuple[str, str]:
    """Ch. 8.4.1: intrinsic motivation improves steadily (its trend per doubling > 0)."""
    if len(runs.get("intrinsic", {})) < 2 or len(_Trended(runs)) < 2:
        return NOT_TESTABLE, "fewer than 2 intrinsic runs or 2 stages after 0"
    intrinsic = list(runs["intrinsic"].values())
    trends = [_Trend(penalties, _Trended(runs))(r) for r in intrinsic]
    blocks = [r.settings.mdp_seed for r in intrinsic]  # (as the other claims: within the MDPs)
    label, test = _Compared("per doubling, minus 0", trends, np.zeros(len(trends)), blocks)
    mark = REPRODUCED if test.difference > 0 and test.t_p < ALPHA else NOT_REPRODUCED
    return mark, f"{label} {test.Text()}"


def ImprovesMoreThanOthers(runs: Runs, penalties: bool) -> tuple[str, str]:
    """Ch. 8.4.1 read with Fig. 8.2: it improves more than the other strategies."""
    if len(_Trended(runs)) < 2:
        return NOT_TESTABLE, "fewer than 2 stages after 0"
    comparisons = [
        (f"minus {o}", "intrinsic", o, _Trend(penalties, _Trended(runs)))
        for o in _OthersThan(runs, "intrinsic")
    ]
    return _Family(runs, comparisons, larger=True)


def BestFrom800(runs: Runs, penalties: bool) -> tuple[str, str]:
    """Ch. 8.4.1: intrinsic motivation is clearly the best from about 800 on (every stage from
    800, against both others: one family)."""
    stages = [s for s in _Stages(runs) if s >= BEST_FROM]
    if not stages or "intrinsic" not in runs:
        return NOT_TESTABLE, f"no evaluations at {BEST_FROM} or later"
    comparisons = [
        (f"at {stage} minus {o}", "intrinsic", o, _StageMean(stage, penalties))
        for stage in stages
        for o in _OthersThan(runs, "intrinsic")
    ]
    return _Family(runs, comparisons, larger=True)


def _Hours(run: ReachRun, exploration_only: bool) -> float:
    seconds = run.simulated_seconds
    if exploration_only:
        seconds -= run.evaluation_seconds
    return seconds / 3600


def RandomTakesLonger(runs: Runs, exploration_only: bool = False) -> tuple[str, str]:
    """Ch. 8.4.4: random exploration takes about 1.86 times the robot time of the others. The
    source's experiments "ran for" their hours, which the evaluations are part of; its reason
    (random's trips across the state space) is the exploration's: ``exploration_only`` leaves
    the evaluations' robot time out, over the seeds whose three runs timed their evaluations."""
    strategies = ("random", "greedy", "intrinsic")
    if not set(strategies) <= set(runs):
        return NOT_TESTABLE, "needs random, greedy and intrinsic runs"
    seeds = sorted(set(runs["random"]) & set(runs["greedy"]) & set(runs["intrinsic"]))
    every = len(seeds)
    if exploration_only:
        seeds = [
            s for s in seeds if all(runs[o][s].evaluation_seconds is not None for o in strategies)
        ]
    if len(seeds) < 2:
        return NOT_TESTABLE, "fewer than 2 seeds with all three strategies" + (
            " timing their evaluations" if exploration_only else ""
        )
    random = [_Hours(runs["random"][s], exploration_only) for s in seeds]
    others = [
        np.mean([_Hours(runs[o][s], exploration_only) for o in ("greedy", "intrinsic")])
        for s in seeds
    ]
    blocks = [runs["random"][s].settings.mdp_seed for s in seeds]
    ratio, low, high = RatioOfMeans(random, others, blocks)
    # Where random's extra time goes: tries that ran out of actions (ch. 8.1's cycles) or trips.
    timed_out = {
        o: np.mean([TimedOutTries(runs[o][s]) / runs[o][s].settings.problem_tries for s in seeds])
        for o in strategies
    }
    evidence = (
        f"{ratio:.2f} times [{low:.2f}, {high:.2f}] (95 % bootstrap over {len(seeds)} seeds in "
        f"{len(set(blocks))} MDPs"
        + (f", leaving out {every - len(seeds)} with untimed runs" if len(seeds) < every else "")
        + f"; the source: {SOURCE_TIME_RATIO:.2f}); problem-tries that ran out of actions "
        f"without a reach: random {timed_out['random']:.1%}, greedy {timed_out['greedy']:.1%}, "
        f"intrinsic {timed_out['intrinsic']:.1%}"
    )
    # More time than the others, and as much as the source's within the interval.
    held = 1.0 < low <= SOURCE_TIME_RATIO <= high
    return (REPRODUCED if held else NOT_REPRODUCED), evidence


def _FailedPerTry(run: ReachRun) -> float:
    log = RunLog(run)
    return float(np.sum(log[:, 6] < 0) / run.settings.problem_tries)


def RandomFailsMore(runs: Runs) -> tuple[str, str]:
    """Fig. 8.8: the random explorer accumulates many more failed transitions."""
    comparisons = [(f"minus {o}", "random", o, _FailedPerTry) for o in _OthersThan(runs, "random")]
    if "random" not in runs or not comparisons:
        return NOT_TESTABLE, "needs random, greedy and intrinsic runs"
    return _Family(runs, comparisons, larger=True)


def _LastLineShare(run: ReachRun) -> float:
    shares = Fingerprints(run)["line_share"]
    return shares[max(shares)]


def GreedysLines(runs: Runs) -> tuple[str, str]:
    """Fig. 8.7: after about 800, greedy tries a few reaches on every problem (vertical lines),
    more than the intrinsic agent (the last window's top-2 share of its reaches)."""
    if not {"greedy", "intrinsic"} <= set(runs) or max(_Stages(runs), default=0) <= BEST_FROM:
        return NOT_TESTABLE, f"needs greedy and intrinsic runs past {BEST_FROM}"
    mark, evidence = _Family(
        runs, [("greedy minus intrinsic", "greedy", "intrinsic", _LastLineShare)], larger=True
    )
    level = np.mean([_LastLineShare(r) for r in runs["greedy"].values()])
    return mark, f"greedy's last-window share {level:.2f}; {evidence}"


# (claim as the source makes it, the value compared, the test).
CLAIMS: tuple[tuple[str, str, Callable[[Runs], tuple[str, str]]], ...] = (
    (
        "intrinsic motivation is the least competent after 100 problem-tries (8.4.1)",
        "the source's sum",
        lambda runs: LeastCompetentFirst(runs, penalties=True),
    ),
    (
        "the same",
        "reaches only",
        lambda runs: LeastCompetentFirst(runs, penalties=False),
    ),
    (
        "it improves steadily (8.4.1)",
        "the source's sum, change per doubling",
        lambda runs: ImprovesSteadily(runs, penalties=True),
    ),
    (
        "it improves more than the others (8.4.1, Fig. 8.2)",
        "the source's sum, change per doubling",
        lambda runs: ImprovesMoreThanOthers(runs, penalties=True),
    ),
    (
        "it is clearly the best from about 800 on (8.4.1)",
        "the source's sum",
        lambda runs: BestFrom800(runs, penalties=True),
    ),
    ("the same", "reaches only", lambda runs: BestFrom800(runs, penalties=False)),
    (
        "random exploration needs about 1.86 times the robot time (8.4.4)",
        "robot hours",
        RandomTakesLonger,
    ),
    (
        "the same",
        "robot hours of the exploration alone",
        lambda runs: RandomTakesLonger(runs, exploration_only=True),
    ),
    (
        "random accumulates many more failed transitions (8.4.4, Fig. 8.8)",
        "failed transitions per problem-try",
        RandomFailsMore,
    ),
    (
        "greedy tries a few reaches on every problem after about 800 (Fig. 8.7)",
        "top-2 share of the last window's reaches",
        GreedysLines,
    ),
)


def _EtaSquared(groups: list[np.ndarray]) -> float:
    """The share of the values' variance between the groups."""
    values = np.concatenate(groups)
    total = np.sum((values - values.mean()) ** 2)
    between = sum(len(g) * (g.mean() - values.mean()) ** 2 for g in groups)
    return float(between / total) if total else 0.0


def _UnitSpread(groups: list[np.ndarray]) -> float:
    """How far apart the units' mean sums lie (the largest minus the smallest), in reward: how
    much choosing the unit matters, whatever the runs' spread within a unit."""
    means = [g.mean() for g in groups]
    return float(max(means) - min(means))


def _UnitGroups(runs: list[ReachRun]) -> dict[float, np.ndarray] | None:
    """Per distance unit (m, in order), the runs' sums at their last common stage (the source's
    sum); None with fewer than 2 units of 2 runs."""
    stage = (
        max(set.intersection(*(set(r.evaluations) for r in runs)), default=None) if runs else None
    )
    if stage is None:
        return None
    units = sorted({r.settings.distance_unit for r in runs})
    groups = {
        u: RunSums([r for r in runs if r.settings.distance_unit == u], stage, True) for u in units
    }
    return groups if len(groups) > 1 and min(len(g) for g in groups.values()) > 1 else None


def _LessTuningIn(runs: list[ReachRun]) -> tuple[str, str]:
    by_unit = {
        s: _UnitGroups([r for r in runs if r.strategy == s]) for s in ("greedy", "intrinsic")
    }
    if None in by_unit.values():
        return NOT_TESTABLE, "needs greedy and intrinsic runs over at least 2 distance units"
    groups = {s: list(g.values()) for s, g in by_unit.items()}
    eta = {s: _EtaSquared(g) for s, g in groups.items()}
    spread = {s: _UnitSpread(g) for s, g in groups.items()}
    greedy_p = float(stats.f_oneway(*groups["greedy"]).pvalue)
    # Greedy minus intrinsic, of the eta squareds and of the spreads, with bootstrap intervals:
    # runs resampled within units.
    rng = np.random.default_rng(0)
    differences = []
    for _ in range(2000):
        drawn = {s: [rng.choice(g, g.size) for g in groups[s]] for s in groups}
        differences.append(
            [
                _EtaSquared(drawn["greedy"]) - _EtaSquared(drawn["intrinsic"]),
                _UnitSpread(drawn["greedy"]) - _UnitSpread(drawn["intrinsic"]),
            ]
        )
    (low, spread_low), (high, spread_high) = np.percentile(differences, [2.5, 97.5], axis=0)
    held = greedy_p < ALPHA and low > 0
    evidence = (
        f"the unit's share of the variance of the last stage's sums: greedy {eta['greedy']:.2f} "
        f"(ANOVA p = {greedy_p:.2g}), intrinsic {eta['intrinsic']:.2f}; greedy minus intrinsic "
        f"{eta['greedy'] - eta['intrinsic']:+.2f} [{low:+.2f}, {high:+.2f}]; the range of the "
        f"units' mean sums (not marked): greedy {spread['greedy']:.2f}, intrinsic "
        f"{spread['intrinsic']:.2f}, greedy minus intrinsic "
        f"{spread['greedy'] - spread['intrinsic']:+.2f} [{spread_low:+.2f}, {spread_high:+.2f}]"
        "; the units' mean sums, greedy / intrinsic: "
        + ", ".join(
            f"{unit:g} m {g.mean():+.2f} / {by_unit['intrinsic'][unit].mean():+.2f}"
            for unit, g in by_unit["greedy"].items()
            if unit in by_unit["intrinsic"]
        )
    )
    return (REPRODUCED if held else NOT_REPRODUCED), evidence


def LessTuning(results: list[ReachRun]) -> list[tuple[str, str, str]]:
    """Ch. 8.5: intrinsic motivation alleviates parameter tuning. Within each group of runs that
    differ only in the distance unit (the same force and readings): the unit changes greedy's
    competence (ANOVA p < 0.05) and explains less of the intrinsic agent's (the difference of
    the units' eta squared, greedy minus intrinsic, has a bootstrap interval above 0). Returns
    (group, mark, evidence) per group."""
    groups: dict[str, list[ReachRun]] = {}
    for r in results:
        key = SettingLabel(dc.replace(r.settings, distance_unit=1.0)).removeprefix("unit1_")
        groups.setdefault(key, []).append(r)
    return [(key, *_LessTuningIn(runs)) for key, runs in groups.items()]


def _BySetting(results: list[ReachRun]) -> dict[str, Runs]:
    """The runs per setting, the reference readings' settings first."""
    settings: dict[str, Runs] = {}
    for r in sorted(results, key=lambda r: (len(r.settings.Readings()), SettingLabel(r.settings))):
        by_strategy = settings.setdefault(SettingLabel(r.settings), {})
        by_strategy.setdefault(r.strategy, {})[r.settings.seed] = r
    return settings


def Verdicts(results: list[ReachRun]) -> list[Verdict]:
    """Every claim of :data:`CLAIMS` marked on every setting's runs."""
    return [
        Verdict(claim, label, *Test(runs))
        for label, runs in _BySetting(results).items()
        for claim, _, Test in CLAIMS
    ]


def ClaimsTables(results: list[ReachRun]) -> list[str]:
    """Markdown: per claim its mark under every setting and the settings it holds under, then
    the evidence per claim and setting."""
    verdicts = Verdicts(results)
    settings = list(dict.fromkeys(v.setting for v in verdicts))
    lines = [
        "| the source's claim | value compared | " + " | ".join(settings) + " | holds under |",
        "|---|---|" + "---|" * (len(settings) + 1),
    ]
    for i, (claim, value, _) in enumerate(CLAIMS):
        marks = verdicts[i :: len(CLAIMS)]  # (setting-major: claim i of every setting)
        holds = [v.setting for v in marks if v.mark == REPRODUCED]
        lines.append(
            f"| {claim} | {value} | "
            + " | ".join(v.mark for v in marks)
            + f" | {', '.join(holds) or 'none'} |"
        )
    tuning = LessTuning(results)
    held = [group for group, mark, _ in tuning if mark == REPRODUCED]
    lines.append(
        "| intrinsic motivation alleviates parameter tuning (8.5) | the source's sum at the last "
        f"stage, across the distance units | {' | '.join(['-'] * len(settings))} | "
        f"{', '.join(held) or 'none'} ({'; '.join(f'{g}: {m}' for g, m, _ in tuning)}) |"
    )
    lines += ["", "Evidence (paired by seed; Holm-adjusted p over each claim's comparisons):", ""]
    for i, (claim, value, _) in enumerate(CLAIMS):
        for v in verdicts[i :: len(CLAIMS)]:
            lines.append(f"- {claim} ({value}), {v.setting}: {v.mark}; {v.evidence}")
    for group, mark, evidence in tuning:
        lines.append(
            f"- intrinsic motivation alleviates parameter tuning (8.5), {group}: {mark}; {evidence}"
        )
    return lines
