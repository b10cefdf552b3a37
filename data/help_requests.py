"""Help requests and the spec they ask for: a stuck robot asks for a pallet to be moved,
in words composed from parts, answered with the template's pick-before-place spec.

A pick-and-place job ``j`` is the paper's App. A.2 conjunction over its two action
propositions ``pick_j`` and ``place_j`` (:func:`pnp_spec`)::

    phi1 = (!place_j) U pick_j              # nothing is placed before it is picked
    phi2 = G(pick_j -> (!others) U place_j)  # carrying j, touch nothing else first
    phi3 = F place_j                        # and it is placed

The help job's spec (:func:`template_help_spec`) is that conjunction over propositions
named after the request's cells. The helpers of :mod:`ara.coordination` translate a
request with the shipped translator and plan with these specs; the auction is only right
when the formula is the template's. The wordings used to measure that
(:data:`ara.coordination.protocol.REQUEST_WORDINGS`, the paper's among them) are never
produced here, so the bench measures wordings training never saw.
"""

from __future__ import annotations

import random
from collections.abc import Sequence

from ara.data.normalize import Record, UidMaker, make_record
from ara.grammars import Always, And, Atom, Eventually, Formula, Implies, Not, Or, Until
from ara.grammars.ast import rename_atoms

#: A grid cell, (row, column).
Cell = tuple[int, int]

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


def help_request_text(rng: random.Random, site: Cell) -> str:
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


def pick_ap(name: str) -> str:
    return f"pick_{name}"


def place_ap(name: str) -> str:
    return f"place_{name}"


def pnp_spec(name: str, others: Sequence[str] = ()) -> Formula:
    """phi1 & phi2 & phi3 for job ``name``; ``others`` are the other jobs' propositions."""
    pick, place = Atom(pick_ap(name)), Atom(place_ap(name))
    return And((Until(Not(place), pick), carry_alone(pick.name, place.name, others),
                Eventually(place)))


def carry_alone(pick: str, place: str, others: Sequence[str]) -> Formula:
    """phi2: once ``pick`` happens, none of ``others`` before ``place`` (one pallet at a
    time); ``G(pick -> F place)`` when there are no others."""
    carry: Formula = Eventually(Atom(place))  # true U place
    if others:
        blocked = Atom(others[0]) if len(others) == 1 else Or(tuple(Atom(o) for o in others))
        carry = Until(Not(blocked), Atom(place))
    return Always(Implies(Atom(pick), carry))


def help_props(site: Cell, drop: Cell) -> tuple[str, str]:
    """A helper's propositions for the help job: named after their cells, since that
    is what the request says."""
    return (pick_ap(f"r{site[0]}c{site[1]}"), place_ap(f"r{drop[0]}c{drop[1]}"))


def template_help_spec(site: Cell, drop: Cell, others: Sequence[str]) -> Formula:
    """The help job's PNP spec, written from the request's fields (no LLM).

    Its conjunctions nest two at a time, ``(phi1 & phi2) & phi3``, so the decoding
    grammar (at most two arguments per ``&``) can write it."""
    pick, place = help_props(site, drop)
    spec = rename_atoms(pnp_spec("h", others), {pick_ap("h"): pick, place_ap("h"): place})
    first, second, third = spec.args
    return And((And((first, second)), third))


def says_template(stl: str, site: Cell, drop: Cell, timeout_s: float = 30) -> bool | None:
    """Whether a helper's translation means :func:`template_help_spec` (Spot); None where
    Spot cannot tell within ``timeout_s`` or the formula's bounds are too large for it, so
    a trial or a demo records it as unknown instead of stopping."""
    from ara.grammars import to_text
    from ara.grammars.spot_bridge import same_meaning

    return same_meaning(stl, to_text(template_help_spec(site, drop, ())), timeout_s)
