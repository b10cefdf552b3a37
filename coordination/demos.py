"""The paper's three demonstrations as runnable scenarios.

- ``pallet``: a robot finds a pallet in the aisle and asks the forklifts for help;
  each one translates the request, plans, and bids; the cheapest bid wins.
- ``kitting``: one instruction with unordered goals (collect three parts in any
  order, then deliver the kit); the planner picks the order.
- ``tool``: a strict sequence through nested U (key from the cabinet, then the tool
  from the locker, then the workbench).

Each prints the messages, the STL (the translator's when ``--model`` names a model, the
reference formula otherwise), the plan, and writes a PNG of the paths.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ara.coordination.events import UnsupportedSpec, Vocabulary
from ara.coordination.planner_dp import Job, plan_jobs
from ara.coordination.planner_milp import plan_spec
from ara.coordination.protocol import Helper, HelpRequest, request_text, run_round
from ara.coordination.specs import job_names, jobs_vocabulary
from ara.coordination.world import Cell, GridWorld
from ara.data.help_requests import help_props, pick_ap, place_ap, says_template
from ara.errors import ConfigError
from ara.grammars import parse

DEMOS = ("pallet", "kitting", "tool")


@dataclass(frozen=True)
class Errand:
    """One robot, one NL instruction over named places."""

    nl: str
    start: Cell
    places: dict[str, Cell]
    reference: str  # the formula the instruction means, for --model none


ERRANDS = {
    "kitting": Errand(
        "Collect the screws, the bolts and the washers in any order, and only then bring "
        "the kit to the station.",
        (0, 0), {"screws": (7, 0), "bolts": (0, 7), "washers": (3, 4), "station": (7, 7)},
        "F(screws) & F(bolts) & F(washers) & (!station U screws) & (!station U bolts) & "
        "(!station U washers) & F(station)"),
    "tool": Errand(
        "Get the key from the cabinet first, then take the tool from the locker, and "
        "then bring it to the workbench.",
        (3, 0), {"cabinet": (0, 6), "locker": (7, 2), "workbench": (3, 7)},
        "!locker U (cabinet & (!workbench U (locker & F(workbench))))"),
}


def run_demo(name: str, out: str | Path, translator=None, echo=print) -> dict:
    """Run demo ``name``; writes ``<out>/<name>.png`` and ``<out>/<name>.json``."""
    if name not in DEMOS:
        raise ConfigError(f"unknown demo {name!r}; choose one of {', '.join(DEMOS)}")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    world = GridWorld.paper()
    result = _pallet(world, translator, echo) if name == "pallet" else \
        _errand(world, ERRANDS[name], translator, echo)
    import json

    (out / f"{name}.json").write_text(json.dumps(result, indent=2, default=list) + "\n")
    draw(world, result["paths"], out / f"{name}.png", result["title"], result.get("marks"))
    echo(f"wrote {out / (name + '.png')} and {out / (name + '.json')}")
    return result


def _pallet(world: GridWorld, translator, echo) -> dict:
    site, requester = (3, 4), (3, 2)
    helpers = [Helper(0, (0, 0), (Job((0, 2), (7, 2), name="j0"),)),
               Helper(1, (7, 6), (Job((7, 4), (0, 4), name="j1"), Job((3, 7), (7, 7), name="j2"))),
               Helper(2, (0, 7), (Job((0, 6), (3, 6), name="j3"),))]
    caps = ("navigate", "report conflicts")
    request = HelpRequest("requester", site, caps, request_text(site, caps))
    echo(f"[requester at {requester}] {request.text}")
    rnd = run_round(world, request, helpers, planner="milp", translator=translator)
    paths = {"requester": [requester]}
    drop = world.nearest_free_neighbour(site)
    for o in rnd.offers:
        verdict = ""
        if translator is not None:  # without one, every helper plans the template itself
            same = bool(o.stl) and says_template(o.stl, site, drop, timeout_s=10)
            said = {True: "equivalent", False: "differs", None: "Spot cannot tell"}[same]
            verdict = f"  (pick-before-place template: {said})"
        echo(f"[forklift {o.helper}] STL: {o.stl or '-'}{verdict}")
        echo(f"[forklift {o.helper}] {o.text}")
    for d in rnd.decisions:
        echo(f"[requester -> forklift {d.helper}] {d.text}")
    for h, offer in zip(helpers, rnd.offers, strict=True):  # offers come in helper order
        cells = {**jobs_vocabulary(world, list(h.jobs)).events,
                 **dict(zip(help_props(site, drop), (site, drop), strict=True))}
        order = offer.plan if h.index == rnd.chosen else _own_order(world, h)
        paths[f"forklift {h.index}"] = _trace(world, h.start, [cells[e] for e in order])
    return {"title": f"pallet at {site}: forklift {rnd.chosen} helps", **rnd.to_dict(),
            "paths": paths, "marks": {"pallet": site}}


def _own_order(world: GridWorld, h: Helper) -> list[str]:
    """The events of a helper that keeps its own plan, in order."""
    plan = plan_jobs(world, h.start, list(h.jobs))
    names = job_names(h.jobs)
    return [e for i in plan.order for e in (pick_ap(names[i]), place_ap(names[i]))]


def _errand(world: GridWorld, errand: Errand, translator, echo) -> dict:
    aps = tuple(errand.places)
    echo(f"[instruction] {errand.nl}")
    warnings, probability = [], None
    if translator is None:
        stl, source = errand.reference, "reference"
    else:
        from ara.eval.translate.answering import answer, notes

        # Answered and checked as `ara translate` does, so the demo shows what a user gets
        answered = answer(translator, errand.nl, aps)
        stl, source = answered.stl, f"translated by {answered.model}"
        warnings, probability = notes(answered, errand.nl), answered.confidence
    echo(f"[STL, {source}] {stl}")
    for warning in warnings:
        echo(warning)
    said = {"stl": stl, "source": source, "confidence": probability}
    vocab = Vocabulary(errand.places)
    try:
        plan = plan_spec(world, errand.start, {"task": parse(stl)}, vocab, "makespan")
    except UnsupportedSpec as err:
        echo(f"[planner] cannot plan: {err}")
        return {"title": "no plan", **said, "status": "unsupported", "reason": str(err),
                "paths": {}}
    if not plan.feasible:
        echo(f"[planner] no plan: {plan.status}")
        return {"title": "no plan", **said, "status": plan.status, "paths": {}}
    echo("[plan] " + " -> ".join(f"{e}@t={plan.times[e]}" for e in plan.order)
         + f"  (makespan {plan.makespan}, solved in {plan.solve_s * 1000:.1f} ms)")
    return {"title": f"{' -> '.join(plan.order)} (makespan {plan.makespan})", **said,
            "status": plan.status, "order": plan.order, "times": plan.times,
            "makespan": plan.makespan,
            "paths": {"robot": _trace(world, errand.start,
                                      [errand.places[e] for e in plan.order])},
            "marks": errand.places}


def _trace(world: GridWorld, start: Cell, stops: list[Cell]) -> list[Cell]:
    path = [start]
    for cell in stops:
        path += world.path(path[-1], cell)[1:]
    return path


def draw(world: GridWorld, paths: dict[str, list[Cell]], target: Path, title: str,
         marks: dict[str, Cell] | None = None) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 5))
    for r, c in world.obstacles:
        ax.add_patch(plt.Rectangle((c - 0.5, r - 0.5), 1, 1, color="0.3"))
    for k, (name, path) in enumerate(paths.items()):
        if not path:
            continue
        off = 0.08 * (k - len(paths) / 2)
        xs, ys = [c + off for _, c in path], [r + off for r, _ in path]
        ax.plot(xs, ys, "-o", ms=3, label=name)
        ax.annotate("start", (xs[0], ys[0]), fontsize=7)
    for label, (r, c) in (marks or {}).items():
        ax.plot([c], [r], "kX", ms=12)
        ax.annotate(label, (c + 0.15, r - 0.15), fontsize=8, weight="bold")
    ax.set_xlim(-0.5, world.cols - 0.5)
    ax.set_ylim(world.rows - 0.5, -0.5)
    ax.set_xticks(range(world.cols))
    ax.set_yticks(range(world.rows))
    ax.grid(True, lw=0.3)
    ax.set_title(title, fontsize=9)
    if any(paths.values()):  # a request with no plan draws the world alone
        ax.legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    fig.savefig(target, dpi=110)
    plt.close(fig)

