"""The compositional split: the training mixture of the shipped fine-tune, and a test
side of formula shapes and phrasings that training never sees.

Train, by source (each deduplicated, so no sentence is learned by repetition):

* ``navi``: the lifted rows on the train side of the paper split (same seed), so the
  paper split's test side stays as held out as it was, each sentence once (the file
  has only 522 distinct ones). Its grounded rows are left out: they read a bare
  command as "holds now" ("pick up pear and when possible get apple" is
  ``pick_up_pear & F(get_apple)``) and "whenever x" as "at some point x", which
  contradicts what a user means by "pick up the pear" or "whenever the alarm rings";
  the synthetic grounded rows teach the user's reading;
* ``nl2tl_timed_train``: NL2TL's lifted timed training file (``lifted_stl_dev`` stays
  out: it is the timed evaluation set);
* ``synthetic``: :func:`ara.data.synthetic.synthetic_records`, train side;
* ``help_request``: :func:`ara.data.help_requests.help_request_records`, a stuck
  robot's request answered with the coordination template's spec (the wordings the
  coordination bench measures are never among them).

NL2TL's timed file is labelled by :func:`ara.data.normalize.lifted_from_grounded`,
which makes it agree with navi on every sentence they share.

Test: synthetic rows whose shapes are held out, worded with held-out phrasings where
a construct has them. Records of any source with a held-out shape stay out of train,
and so do records whose sentence is one of the hand-written suites' (the generator
says short ones such as "at no time ( prop_1 )" on its own).
"""

from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path

from ara.data.handwritten import SUITES, suite_records
from ara.data.help_requests import HELP_REQUEST_ROWS, help_request_records
from ara.data.normalize import (
    TIMED_LABELS_VERSION,
    Record,
    RejectedRow,
    normalize_navi,
    normalize_timed,
    read_raw,
)
from ara.data.splits import paper_split
from ara.data.synthetic import (
    SYNTHETIC_VERSION,
    SynthSettings,
    is_held_out,
    synthetic_records,
)

#: Rows of each part; a change here is a new version of the split.
SYNTHETIC_TRAIN_ROWS = 4700
SYNTHETIC_TEST_ROWS = 400


def _dedup(records: list[Record]) -> list[Record]:
    seen: set[tuple[str, str, str]] = set()
    out = []
    for r in records:
        key = (r.form, r.nl, r.stl)
        if key not in seen:
            seen.add(key)
            out.append(r)
    return out


def sentence_key(nl: str) -> str:
    """A sentence up to case, spacing and a final full stop."""
    return " ".join(nl.lower().rstrip(". ").split())


def compositional_split(raw_dir: Path, seed: int
                        ) -> tuple[dict[str, list[Record]], list[RejectedRow], dict]:
    """The mixture and its held-out test side (see the module doc).

    Returns:
        ``(parts, rejected, sources)`` as :func:`ara.data.store.build_split` does.
    """
    navi_rows, navi_hash = read_raw(raw_dir, "navi.jsonl")
    navi, rejected = normalize_navi(navi_rows)
    navi_train = paper_split(navi, len(navi_rows), seed)["train"]
    lifted = _dedup([r for r in navi_train if r.form == "lifted"])
    timed_rows, timed_hash = read_raw(raw_dir, "lifted_stl_train.jsonl")
    timed, rejected_timed = normalize_timed(timed_rows, "nl2tl_timed_train")
    settings = SynthSettings()
    # A held-out shape stays out of training whatever the source wrote it.
    nl2tl = [r for r in lifted + _dedup(timed)
             if not is_held_out(r.formula, settings)]
    train = (nl2tl + synthetic_records(SYNTHETIC_TRAIN_ROWS, seed, held_out=False,
                                       settings=settings)
             + help_request_records(HELP_REQUEST_ROWS, seed))
    suite = {sentence_key(r.nl) for split in SUITES for r in suite_records(split)}
    train = [r for r in train if sentence_key(r.nl) not in suite]
    test = synthetic_records(SYNTHETIC_TEST_ROWS, seed, held_out=True, settings=settings)
    sources = {"navi.jsonl": navi_hash, "lifted_stl_train.jsonl": timed_hash}
    sources["timed_labels"] = TIMED_LABELS_VERSION
    sources["synthetic"] = json.dumps({"version": SYNTHETIC_VERSION, **asdict(settings),
                                       "train_rows": SYNTHETIC_TRAIN_ROWS,
                                       "test_rows": SYNTHETIC_TEST_ROWS,
                                       "help_requests": HELP_REQUEST_ROWS}, sort_keys=True)
    return {"train": train, "test": test}, rejected + rejected_timed, sources
