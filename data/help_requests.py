"""Help requests for training: a stuck robot asks for a pallet to be moved, in words
composed from parts, answered with the template's pick-before-place spec.

The helpers of :mod:`ara.coordination` translate such a request with the shipped
translator, and the auction is only right when the formula is the template's
(:func:`ara.coordination.protocol.template_help_spec`). The wordings used to
measure that (:data:`ara.coordination.protocol.REQUEST_WORDINGS`, the paper's among
them) are never produced here, so the bench measures wordings training never saw.
"""

from __future__ import annotations

import random

from ara.data.normalize import Record, UidMaker, make_record

#: Rows in the training mixture; a change here is a new version of the split.
HELP_REQUEST_ROWS = 400

_CONTEXT = (
    "A pallet is in the way at ({r}, {c}) and blocks {what}.",
    "There's a pallet at cell ({r}, {c}) sitting in {what}.",
    "Pallet at ({r},{c}) obstructs {what}.",
    "I can't get through {what}: a pallet is at ({r}, {c}).",
    "Blocked: a pallet stands at position ({r}, {c}) in {what}.",
    "I cannot get past a pallet at ({r}, {c}); it blocks {what}.",
    "Location ({r}, {c}) has a pallet on it, right in {what}.",
    "Somebody left a pallet at ({r}, {c}) in {what}.",
)
_ASK = ("Could you", "Can someone", "Please", "I need a robot to", "Would a forklift",
        "Requesting help to", "Someone needs to", "I would like help to")
_PICK = ("pick the pallet up", "lift it", "take the pallet", "pick it up", "load the pallet",
         "grab that pallet", "collect it", "remove the pallet from there")
_THEN = (", then", " and then", " and after that", ", and afterwards", ", and once it is loaded,",
         " and subsequently", " first, and then", "; after picking it up,")
_DROP = ("put it down at the closest free drop zone", "leave it in the nearest empty drop zone",
         "unload it at a free drop zone close by", "drop it in the nearest free spot",
         "set it down at the closest open drop area", "place it at the nearest free drop point",
         "bring it to the closest free drop zone", "deposit it at an empty drop zone nearby")
_CAPS = ("I can only {caps}.", "My only capability is to {caps}.", "All I can do is {caps}.",
         "I am limited to: {caps}.", "(I can {caps}, nothing else.)", "")
_WHAT = ("the aisle", "my path", "the corridor", "the loading lane", "the passage",
         "the shelf row", "the exit", "the dock entrance")
_CAPABILITIES = ("navigate", "navigate, turn", "move and turn", "drive", "navigate, scan",
                 "move forward")
_NEIGHBOURS = ((-1, 0), (1, 0), (0, -1), (0, 1))


def help_request_text(rng: random.Random, site: tuple[int, int]) -> str:
    """One request for ``site``, its parts drawn from ``rng``."""
    r, c = site
    context = rng.choice(_CONTEXT).format(r=r, c=c, what=rng.choice(_WHAT))
    task = f"{rng.choice(_ASK)} {rng.choice(_PICK)}{rng.choice(_THEN)} {rng.choice(_DROP)}"
    if task.startswith(("Could you", "Can someone", "Would a forklift")):
        task += "?"
    else:
        task += "."
    caps = rng.choice(_CAPS).format(caps=rng.choice(_CAPABILITIES))
    parts = [context, task, caps] if rng.random() < 0.7 else [task, context, caps]
    return " ".join(p for p in parts if p)


def help_request_records(rows: int, seed: int) -> list[Record]:
    """``rows`` grounded records: a request and the template spec for its site and a
    drop cell beside it (the helper's own choice, named by the proposition)."""
    from ara.coordination.protocol import template_help_spec

    rng = random.Random(f"{seed}:help-requests")
    uid = UidMaker()
    records = []
    for row in range(rows):
        site = (rng.randrange(10), rng.randrange(10))
        dr, dc = rng.choice(_NEIGHBOURS)
        drop = (abs(site[0] + dr), abs(site[1] + dc))
        spec = template_help_spec(site, drop, ())
        records.append(make_record(uid, "help_request", "grounded", row,
                               help_request_text(rng, site), spec))
    return records
