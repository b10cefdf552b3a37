"""How often helpers read a help request right: every wording of the pallet request
(the paper's and ten rewordings) at several sites, translated by one model with the
protocol's worked examples and repaired as a helper repairs it (as `ara translate`
does), each formula judged by Spot against the template's pick-before-place spec.

    .venv/bin/python bench/help_request_wordings.py [--model finetuned] [--sites 5]
        [--out runs/bench/help-request-wordings.json]
"""

from __future__ import annotations

import argparse
import json
import platform
import random
from datetime import date
from pathlib import Path

from tqdm import tqdm

from ara.coordination.protocol import REQUEST_WORDINGS, request_shots, request_text
from ara.coordination.world import GridWorld
from ara.data.help_requests import help_props, says_template
from ara.eval.translate.models import make_backend
from ara.eval.translate.repair import translate_repaired
from ara.eval.translate.translator import Translator

CAPS = ("navigate", "report conflicts")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", default="finetuned")
    parser.add_argument("--sites", type=int, default=5, help="Free cells drawn (seed 0).")
    parser.add_argument("--out", type=Path, default=Path("runs/bench/help-request-wordings.json"))
    args = parser.parse_args()
    world = GridWorld.paper()
    free = list(world.free_cells)
    shot_sites = {(5, 2), (0, 6)}  # the worked examples' own sites stay out
    sites = random.Random(0).sample([s for s in free if s not in shot_sites], args.sites)
    translator = Translator(make_backend(args.model))
    rows = []
    jobs = [(w, s) for w in range(len(REQUEST_WORDINGS)) for s in sites]
    for wording, site in tqdm(jobs, desc="requests", unit="request"):
        drop = world.nearest_free_neighbour(site)
        text = request_text(site, CAPS, wording=wording)
        vote = translate_repaired(translator, text, help_props(site, drop),
                                  request_shots())  # repaired as a helper reads it
        result = vote.result
        same = says_template(result.stl, site, drop)
        rows.append({"wording": wording, "site": list(site), "stl": result.stl,
                     "equivalent": same, "ms": round(vote.ms, 1),
                     "answers_weighed": len(vote.results)})
    print("| wording | equivalent to the template | of |\n|---:|---:|---:|")
    for w in range(len(REQUEST_WORDINGS)):
        mine = [r for r in rows if r["wording"] == w]
        print(f"| {w} | {sum(bool(r['equivalent']) for r in mine)} | {len(mine)} |")
    total = sum(bool(r["equivalent"]) for r in rows)
    print(f"\nall wordings: {total}/{len(rows)} ({100 * total / len(rows):.1f}%), "
          f"model {translator.backend.model_id}")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps({
        "date": date.today().isoformat(), "machine": platform.platform(),
        "model": translator.backend.model_id, "sites": [list(s) for s in sites],
        "equivalent": total, "requests": len(rows), "rows": rows}, indent=2) + "\n")


if __name__ == "__main__":
    main()
