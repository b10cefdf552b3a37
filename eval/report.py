"""Turn a run's samples into ``results.json``, ``tables.md`` and ``plot.png``."""

from __future__ import annotations

import json
import math
from collections import Counter
from pathlib import Path
from typing import TypedDict

from ara.eval.metrics import VariantResult, overhead, score
from ara.run_store import RUN, read_samples


class Results(TypedDict):
    """Schema of ``results.json``.

    Attributes:
        meta: ``run.json``: config, model id and hash, data version, grammar version,
            seed, git commit, machine.
        results: One entry per (variant, shots); percentages, latency in ms.
        overhead: Latency ratio of each constrained variant to its unconstrained twin.
        counts: Samples on disk, and how their Spot checks ended.
    """

    meta: dict
    results: list[VariantResult]
    overhead: dict[str, float]
    counts: dict[str, int]


def build_results(folder: Path) -> Results:
    samples = read_samples(folder)
    meta = json.loads((folder / RUN).read_text())
    results = score(samples)
    spot = Counter(s.get("spot", "ok") for s in samples)
    return Results(meta=meta, results=results, overhead=overhead(results),
                   counts={"samples": len(samples), **{f"spot_{k}": v for k, v in spot.items()}})


def write_report(folder: Path, plot: bool = True) -> Results:
    """Score the samples in ``folder`` and write the three report files."""
    results = build_results(folder)
    (folder / "results.json").write_text(json.dumps(results, indent=2, sort_keys=True) + "\n")
    (folder / "tables.md").write_text(tables_markdown(results))
    if plot and results["results"]:
        plot_results(results, folder / "plot.png")
    return results


def _cell(stat: dict) -> str:
    if not stat["n"] or math.isnan(stat["mean"]):
        return "-"
    return f"{stat['mean']:.2f} ± {stat['std']:.2f}"


def data_name(meta: dict) -> str:
    """The split's name, or for a run on a user's file that file's name."""
    # data_files also holds the worked examples' file, and may list it first
    file = meta["config"].get("data")
    return Path(file).name if file else meta["data"]["split"]


def tables_markdown(results: Results) -> str:
    """Tables shaped like the paper's Tables I (validity) and II (accuracy, containment)."""
    rows = results["results"]
    shots = sorted({r["shots"] for r in rows})
    variants = sorted({r["variant"] for r in rows}, key=lambda v: (len(v), v))
    cell = {(r["variant"], r["shots"]): r for r in rows}
    meta = results["meta"]
    lines = [
        f"Model `{meta['model_id']}`; data `{data_name(meta)}` "
        f"v{meta['data']['version']} ({meta['config']['form'] or 'every form'}); grammar "
        f"{meta['grammar_version']}; seed {meta['seed']}; {meta['config']['reruns']} reruns; "
        f"{results['counts']['samples']} samples.",
        "",
    ]

    def table(title: str, metrics: list[tuple[str, str]]) -> None:
        lines.append(f"### {title}\n")
        header = ["variant"] + [f"{label} @ {k} shots" for k in shots for _, label in metrics]
        lines.append("| " + " | ".join(header) + " |")
        lines.append("|" + "---|" * len(header))
        for v in variants:
            cells = [_cell(cell[(v, k)][m]) if (v, k) in cell else "-"
                     for k in shots for m, _ in metrics]
            lines.append(f"| {v} | " + " | ".join(cells) + " |")
        lines.append("")

    table("Table I: validity (%)", [("validity", "validity")])
    table("Table II: accuracy and containment (%), on pairs valid under every variant",
          [("accuracy", "accuracy"), ("containment", "containment")])
    table("Latency (ms per formula)", [("latency_ms", "ms")])
    if results["overhead"]:
        lines.append("Constrained / unconstrained latency: " + ", ".join(
            f"{k}: {v:.2f}x" for k, v in results["overhead"].items()))
        lines.append("")
    return "\n".join(lines)


def plot_results(results: Results, path: Path) -> None:
    """Grouped bars of validity and accuracy per variant and shot count, std as error bars."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = results["results"]
    groups = sorted({(r["shots"], r["variant"]) for r in rows},
                    key=lambda g: (g[0], len(g[1]), g[1]))
    by = {(r["shots"], r["variant"]): r for r in rows}
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), sharey=True)
    for ax, metric in zip(axes, ("validity", "accuracy"), strict=True):
        labels = [f"{v}\n{k} shots" for k, v in groups]
        means = [by[g][metric]["mean"] for g in groups]
        stds = [by[g][metric]["std"] for g in groups]
        ax.bar(range(len(groups)), means, yerr=stds, capsize=3, color="#4a7ab5")
        ax.set_xticks(range(len(groups)), labels, fontsize=8)
        ax.set_title(f"{metric} (%)")
        ax.set_ylim(0, 105)
        ax.grid(axis="y", alpha=0.3)
    fig.suptitle(f"{results['meta']['model_id']} on {data_name(results['meta'])}",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
