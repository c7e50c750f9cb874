"""The schedule study's decision rule (benchmarks/lr_schedule_summary.py), fixed before its data were seen."""

import importlib.util
from pathlib import Path

spec = importlib.util.spec_from_file_location(
    "lr_schedule_summary", Path(__file__).parents[1] / "benchmarks" / "lr_schedule_summary.py"
)
summary = importlib.util.module_from_spec(spec)
spec.loader.exec_module(summary)


def row(seed: int, test: float, optimism: float, last_swing: float) -> dict:
    return {"seed": seed, "test": test, "optimism": optimism, "last_swing": last_swing}


def test_cosine_needs_all_three_conditions():
    constant = [row(s, 0.2, 0.10, 0.20) for s in (1000, 1001, 1002)]
    better = [row(s, 0.3, 0.02, 0.05) for s in (1000, 1001, 1002)]
    assert summary.decide(constant, better)[0] == "cosine"
    # as good on test and steadier, but validation overstates more: constant stays
    overstating = [row(s, 0.3, 0.12, 0.05) for s in (1000, 1001, 1002)]
    assert summary.decide(constant, overstating)[0] == "constant"
    # steadier, but a lower test rate: constant stays
    worse = [row(s, 0.1, 0.0, 0.0) for s in (1000, 1001, 1002)]
    choice, why = summary.decide(constant, worse)
    assert choice == "constant" and "mean test not below: no" in why


def test_rule_waits_for_three_shared_seeds():
    constant = [row(s, 0.2, 0.1, 0.2) for s in (1000, 1001, 1002)]
    cosine = [row(s, 0.9, 0.0, 0.0) for s in (1000, 1001)]
    choice, why = summary.decide(constant, cosine)
    assert choice == "undecided" and "2 training seeds" in why


def test_rule_compares_only_seeds_both_ran():
    # a fourth constant seed with a high rate must not tip the comparison
    constant = [row(s, 0.2, 0.1, 0.2) for s in (1000, 1001, 1002)] + [row(1003, 1.0, 0.0, 0.0)]
    cosine = [row(s, 0.25, 0.05, 0.1) for s in (1000, 1001, 1002)]
    assert summary.decide(constant, cosine)[0] == "cosine"
