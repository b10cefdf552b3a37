"""Experiment 2's outputs from its rows: ``trials.csv``, the summary (both waits, the
paper's ratios on shared trials, the translation's record with an LLM), the box plot
and the Markdown table."""

from __future__ import annotations

import csv
import statistics
from dataclasses import asdict
from pathlib import Path

from ara.coordination.exp2_config import METHODS, WAITS, Exp2Config
from ara.stats import describe

COLUMNS = ("trial", "seed", "method", "delta", "delta_arrival", "helper", "solve_s",
           "feasible", "before", "tau_help", "tau_new", "wait", "stl", "reason", "wording",
           "template_equivalent", "declined", "delta_template")
#: Mean Delta in the paper (Fig. 4) and in a replay of the authors' code (a range over
#: its reruns), both with the wait counted until the helper arrives.
PAPER = {"oracle_ils": 4.49, "ours": 5.47}
REPLAY = {"oracle_ils": 4.51, "ours": (5.26, 5.61), "b2": 7.98, "b3": (7.78, 8.63)}
#: How often the paper's method beat each baseline, in percent of trials.
PAPER_BETTER = {"b2": 46, "b3": 53}


def write_csv(rows: list[dict], path: Path) -> None:
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, COLUMNS, extrasaction="ignore")
        w.writeheader()
        for r in sorted(rows, key=lambda r: (r["trial"], METHODS.index(r["method"]))):
            w.writerow(r)


def _delta_key(wait: str) -> str:
    return "delta_arrival" if wait == "arrival" else "delta"


def _method_stats(rows: list[dict], wait: str) -> dict:
    key, methods = _delta_key(wait), {}
    for m in METHODS:
        mine = [r for r in rows if r["method"] == m]
        deltas = [r[key] for r in mine if r[key] is not None]
        times = [r["solve_s"] for r in mine]
        methods[m] = {**describe(deltas), "infeasible": len(mine) - len(deltas),
                      "solve_s": {"mean": round(statistics.fmean(times), 6) if times else None,
                                  "median": statistics.median(times) if times else None,
                                  "max": max(times, default=None)}}
    return methods


def _paired_means(rows: list[dict], wait: str, a: str, b: str) -> tuple[float, float, int]:
    """Mean Delta of methods ``a`` and ``b`` over the trials where both are feasible."""
    key = _delta_key(wait)
    by = {(r["trial"], r["method"]): r[key] for r in rows}
    trials = sorted({r["trial"] for r in rows})
    pairs = [(by.get((t, a)), by.get((t, b))) for t in trials]
    pairs = [(x, y) for x, y in pairs if x is not None and y is not None]
    if not pairs:
        return float("nan"), float("nan"), 0
    return (statistics.fmean(x for x, _ in pairs), statistics.fmean(y for _, y in pairs),
            len(pairs))


def _comparisons(rows: list[dict], wait: str) -> dict:
    """The paper's ratios, each over the trials where both methods are feasible."""
    out = {}
    for m, better in (("oracle_ils", False), ("oracle_exact", False), ("b2", True),
                      ("b3", True)):
        ours, ref, n = _paired_means(rows, wait, "ours", m)
        if better:
            name, value = f"ours_better_than_{m}", (ref - ours) / ref if n and ref else None
            formula = f"({m} - ours) / {m}"
        else:
            name, value = f"ours_vs_{m}", (ours - ref) / ours if n and ours else None
            formula = f"(ours - {m}) / ours, as the paper's 'within 18%'"
        out[name] = {"value_pct": None if value is None else round(100 * value, 2),
                     "trials": n, "formula": formula + ", on the trials where both are feasible"}
    return out


def translation_summary(rows: list[dict]) -> dict:
    """With an LLM: how often the helpers' formula was the template's, and what the
    wrong ones did to the auction (its Delta against the template's, drop wait)."""
    ours = [r for r in rows if r["method"] == "ours"]
    wrong = [r for r in ours if r.get("template_equivalent") is not True]
    changed = [r for r in wrong if r["delta"] != r.get("delta_template")]
    by_wording: dict[int, list[int]] = {}
    for r in ours:
        tally = by_wording.setdefault(r.get("wording", 0), [0, 0])
        tally[0] += r.get("template_equivalent") is True
        tally[1] += 1
    return {"trials": len(ours), "equivalent_to_template": len(ours) - len(wrong),
            "helpers_declined": sum(r.get("declined", 0) for r in ours),
            "wrong_formula_trials": len(wrong),
            "wrong_formula_changed_delta": len(changed),
            # None where either auction found no helper
            "delta_change_when_changed": [
                None if None in (r["delta"], r.get("delta_template"))
                else r["delta"] - r["delta_template"] for r in changed],
            "by_wording": {str(w): {"equivalent": k, "trials": n}
                           for w, (k, n) in sorted(by_wording.items())}}


def summarize(rows: list[dict], config: Exp2Config) -> dict:
    """Per-method statistics of Delta over feasible trials, with the requester's wait
    counted both ways (``config.wait`` first), and the paper's ratios."""
    by_wait = {w: {"methods": _method_stats(rows, w), "comparisons": _comparisons(rows, w)}
               for w in WAITS}
    chosen = by_wait[config.wait]
    extra = {"translation": translation_summary(rows)} if config.llm != "none" else {}
    return {"config": asdict(config), "trials": len({r["trial"] for r in rows}),
            "wait": config.wait, "methods": chosen["methods"],
            "comparisons": chosen["comparisons"], "by_wait": by_wait, **extra,
            "paper": {"wait": "arrival", "oracle": PAPER["oracle_ils"], "ours": PAPER["ours"],
                      **{f"ours_better_than_{m}_pct": pct for m, pct in PAPER_BETTER.items()}},
            "replay_of_authors_code": {"wait": "arrival", "oracle": REPLAY["oracle_ils"],
                                       **{m: list(v) if isinstance(v, tuple) else v
                                          for m, v in REPLAY.items() if m != "oracle_ils"}}}


def plot(rows: list[dict], path: Path, wait: str = "arrival") -> None:
    """Box plot of Delta per method, like the paper's Fig. 4."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = {"ours": "Ours", "oracle_ils": "Oracle (ILS)", "oracle_exact": "Oracle (exact)",
              "b2": "B2 (nearest adds)", "b3": "B3 (nearest + re-opt.)"}
    key = _delta_key(wait)
    data = [[r[key] for r in rows if r["method"] == m and r[key] is not None]
            for m in METHODS]
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.boxplot(data, showmeans=True)
    ax.set_xticks(range(1, len(METHODS) + 1), [labels[m] for m in METHODS], rotation=15)
    ax.set_ylabel(f"time-steps added to the system (Delta, wait until {wait})")
    n = len({r["trial"] for r in rows})
    ax.set_title(f"Experiment 2: {n} trials (mean as triangle)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def table(summary: dict) -> str:
    """A Markdown table of the summary beside the paper's and the replay's numbers
    (both count the wait until the helper arrives)."""
    def shown(v) -> str:
        return "" if v is None else f"{v[0]}-{v[1]}" if isinstance(v, tuple) else f"{v}"

    wait = summary.get("wait", "drop")
    note = "" if wait == "arrival" else " (+1 to set beside ours: wait until drop)"
    lines = [f"Delta with the requester's wait counted until {wait}; paper and authors' "
             f"code count until arrival{note}.", "",
             "| method | mean Delta | std | median | n | infeasible | paper | authors' code |",
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for m in METHODS:
        s = summary["methods"][m]
        mean = "-" if s["mean"] is None else f"{s['mean']:.2f}"
        std = "-" if s["std"] is None else f"{s['std']:.2f}"
        med = "-" if s["median"] is None else f"{s['median']:g}"
        lines.append(f"| {m} | {mean} | {std} | {med} | {s['n']} | {s['infeasible']} | "
                     f"{shown(PAPER.get(m))} | {shown(REPLAY.get(m))} |")
    return "\n".join(lines)
