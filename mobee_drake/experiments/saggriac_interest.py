"""What SAGG-RIAC's interest measures, and the marks that follow (issue 34): the leaves' interests
against their permutation nulls, the variance-only control, and Fig. 3's goals in reach.

Runs of different methods share no randomness but the test set, so groups are compared unpaired
(:func:`~mobee_drake.experiments.statistics.CompareRuns`, one value per run), with Holm's
correction over each mark's comparisons.
"""

import math

import numpy as np
from scipy import stats

from mobee_drake.experiments.saggriac import BabblingRun
from mobee_drake.experiments.statistics import CompareRuns, Holm

ALPHA = 0.05
# A leaf whose mean competence is at most this is treated as unreachable (min_C is -1).
UNREACHABLE_COMPETENCE = -0.95
REFERENCE, RANDOM, VARIANCE = "SAGG-RIAC", "SAGG-Random", "SAGG-RIAC [variance-only]"
BOOTSTRAP_RESAMPLES, BOOTSTRAP_SEED = 10_000, 0


def _MeanInterval(values) -> str:
    """'mean [95 % t-interval]' of one value per run."""
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    if values.size < 2:
        return "-"
    half = stats.t.ppf(0.975, values.size - 1) * values.std(ddof=1) / math.sqrt(values.size)
    return f"{values.mean():.2f} [{values.mean() - half:.2f}, {values.mean() + half:.2f}]"


def _Spearman(leaves: list[dict]) -> float:
    """Spearman's rho of the leaves' interests and competence spreads (NaN if undefined)."""
    interests = [leaf["interest"] for leaf in leaves]
    spreads = [leaf["spread"] for leaf in leaves]
    if len(leaves) < 3 or np.ptp(interests) == 0 or np.ptp(spreads) == 0:
        return math.nan
    return float(stats.spearmanr(interests, spreads).statistic)


def InterestTable(runs: list[BabblingRun], groups: list[str]) -> list[str]:
    """Markdown rows: per group with leaf diagnostics, the leaves per run, how many beat their
    permutation null at 95 %, the unreachable leaves' interest, and how closely the interest
    follows the competences' spread (Spearman's rho per run)."""
    lines = [
        "| group | runs | leaves per run | leaves beating the 95 % null | unreachable leaves "
        "(mean competence <= -0.95): per run, mean interest | rho(interest, competence "
        "spread), mean over runs [95 % CI] |",
        "|---|---:|---:|---|---|---|",
    ]
    for group in groups:
        with_leaves = [r for r in runs if r.label == group and r.leaf_interests]
        if not with_leaves:
            continue
        leaves = [leaf for r in with_leaves for leaf in r.leaf_interests]
        beating = sum(leaf["null_p"] < ALPHA for leaf in leaves)
        unreachable = [leaf for leaf in leaves if leaf["mean_competence"] <= UNREACHABLE_COMPETENCE]
        unreachable_interest = (
            f"{np.mean([leaf['interest'] for leaf in unreachable]):.4f}" if unreachable else "-"
        )
        lines.append(
            f"| {group} | {len(with_leaves)} | {len(leaves) / len(with_leaves):.1f} | "
            f"{beating} of {len(leaves)} ({100 * beating / len(leaves):.1f} %) | "
            f"{len(unreachable) / len(with_leaves):.1f}, {unreachable_interest} | "
            f"{_MeanInterval([_Spearman(r.leaf_interests) for r in with_leaves])} |"
        )
    return lines


def _Errors(runs: list[BabblingRun], group: str) -> np.ndarray:
    return np.array([r.curve[-1]["reaching_error"] for r in runs if r.label == group])


def _GainShare(reference, random, variance) -> tuple[float, float, float]:
    """(mean(random) - mean(variance)) / (mean(random) - mean(reference)): the share of
    SAGG-RIAC's gain over SAGG-Random that the variance-only selector keeps, with a 95 %
    percentile bootstrap interval (runs resampled within each group)."""
    rng = np.random.default_rng(BOOTSTRAP_SEED)

    def Means(values: np.ndarray) -> np.ndarray:
        picks = rng.integers(values.size, size=(BOOTSTRAP_RESAMPLES, values.size))
        return values[picks].mean(axis=1)

    a, r, v = Means(reference), Means(random), Means(variance)
    low, high = np.percentile((r - v) / (r - a), [2.5, 97.5])
    share = (random.mean() - variance.mean()) / (random.mean() - reference.mean())
    return float(share), float(low), float(high)


def MechanismMark(runs: list[BabblingRun]) -> tuple[str, str]:
    """Is SAGG-RIAC's gain over SAGG-Random (final reaching error) learning progress or
    competence variance? ``competence variance``: the variance-only selector also beats
    SAGG-Random and is not worse than SAGG-RIAC; ``learning progress``: it is worse than
    SAGG-RIAC and not better than SAGG-Random; ``undecided`` otherwise; ``no gain to explain``
    when SAGG-RIAC does not beat SAGG-Random (Holm over the three comparisons)."""
    reference, random, variance = (_Errors(runs, g) for g in (REFERENCE, RANDOM, VARIANCE))
    if min(reference.size, random.size, variance.size) < 2:
        return "not testable", "needs 2 runs each of SAGG-RIAC, SAGG-Random and variance-only"
    gain, variance_random, variance_reference = (
        CompareRuns(reference, random),
        CompareRuns(variance, random),
        CompareRuns(variance, reference),
    )
    p_gain, p_vr, p_va = Holm([c.welch_p for c in (gain, variance_random, variance_reference)])
    evidence = (
        f"reaching error SAGG-RIAC minus SAGG-Random {gain.Text()} (Holm p = {p_gain:.2g}); "
        f"variance-only minus SAGG-Random {variance_random.Text()} (Holm p = {p_vr:.2g}); "
        f"variance-only minus SAGG-RIAC {variance_reference.Text()} (Holm p = {p_va:.2g})"
    )
    if not (gain.difference < 0 and p_gain < ALPHA):
        return "no gain to explain", evidence
    share, low, high = _GainShare(reference, random, variance)
    evidence += f"; share of the gain kept by variance-only {share:.2f} [{low:.2f}, {high:.2f}]"
    beats_random = variance_random.difference < 0 and p_vr < ALPHA
    worse = variance_reference.difference > 0 and p_va < ALPHA
    if beats_random and not worse:
        return "competence variance", evidence
    if worse and not beats_random:
        return "learning progress", evidence
    return "undecided", evidence


def _InReach(run: BabblingRun) -> float:
    goals = run.Goals()
    length = run.config["arm"]["total_length"]
    return float(np.mean(np.hypot(goals[:, 1], goals[:, 2]) <= length)) if len(goals) else 0.0


def UniformInReach(run: BabblingRun) -> float:
    """The share of S' inside the reachable half-disc (x >= 0): what uniform goals give."""
    low, high = run.config["goal_space_low"], run.config["goal_space_high"]
    length = run.config["arm"]["total_length"]
    box = (high[0] - low[0]) * (high[1] - low[1])
    inside = low[0] == 0 and high[0] >= length and low[1] <= -length and high[1] >= length
    return math.pi * length**2 / 2 / box if inside else math.nan


def GoalsFocusMark(runs: list[BabblingRun]) -> tuple[str, str]:
    """Fig. 3, "goals focus on the reachable area", from the share of SAGG-RIAC's goals in
    reach: ``reproduced`` when it exceeds SAGG-Random's (Welch p < 0.05) and the majority of
    its goals are in reach (the 95 % t-interval of the runs' shares above 0.5); ``more than
    uniform, not a focus`` when only the first holds; ``not reproduced`` otherwise."""
    reference = [r for r in runs if r.label == REFERENCE and r.goal_log]
    random = [r for r in runs if r.label == RANDOM and r.goal_log]
    if len(reference) < 2 or len(random) < 2:
        return "not testable", "needs 2 runs each of SAGG-RIAC and SAGG-Random"
    shares = np.array([_InReach(r) for r in reference])
    compared = CompareRuns(shares, [_InReach(r) for r in random])
    unreachable = [r.diagnostics["unreachable_share"] for r in reference]
    half = stats.t.ppf(0.975, shares.size - 1) * shares.std(ddof=1) / math.sqrt(shares.size)
    evidence = (
        f"goals in reach: SAGG-RIAC {_MeanInterval(shares)}, SAGG-Random minus it "
        f"{-compared.difference:+.3f} (Welch p = {compared.welch_p:.2g}), uniform "
        f"{UniformInReach(reference[0]):.3f}; SAGG-RIAC's micro-actions on unreachable "
        f"(sub)goals {_MeanInterval(unreachable)}"
    )
    more = compared.difference > 0 and compared.welch_p < ALPHA
    if more and shares.mean() - half > 0.5:
        return "reproduced", evidence
    return ("more than uniform, not a focus" if more else "not reproduced"), evidence


def Issue34Lines(all_runs: dict[int, list[BabblingRun]], groups: list[str]) -> list[str]:
    """Markdown: per experiment, the interest table and the two marks."""
    lines = []
    for experiment, runs in all_runs.items():
        if not runs:
            continue
        mechanism, mechanism_evidence = MechanismMark(runs)
        focus, focus_evidence = GoalsFocusMark(runs)
        lines += [
            f"Experiment {experiment}:",
            "",
            *InterestTable(runs, groups),
            "",
            f"- The paper's gain (SAGG-RIAC over SAGG-Random): **{mechanism}**; "
            f"{mechanism_evidence}.",
            f"- Fig. 3, goals focus on the reachable area: **{focus}**; {focus_evidence}.",
            "",
        ]
    return lines
